"""Tries, as a new user would, the bad inputs and misuses of issue 18 on the command line, and
the malformed robot (MoBeE XML), overlay and scenario files of issue 5, and prints what each ends
in (exit code and the last line it printed), as a markdown table.

Run: ``python scripts/try_bad_inputs.py [FOLDER]`` (FOLDER: where to make the trials' files; a
temporary folder by default). About two minutes: each trial starts the command afresh.
"""

import pathlib
import subprocess
import sys
import tempfile


def _Tree(body: str) -> str:
    """A MoBeE XML robot file (bodypart 'arm') around ``body``."""
    return (
        '<?xml version="1.0"?>\n<ZeroPositionKinematicTree version="1.0" robotName="r">\n'
        f'<bodypart name="arm">\n{body}\n</bodypart>\n</ZeroPositionKinematicTree>\n'
    )


def _Joint(attributes: str = "", inside: str = "") -> str:
    return (
        f'<motor minPos="0" maxPos="10"><joint z="1" minPos="0" maxPos="10" {attributes}>'
        f"{inside}</joint></motor>"
    )


# A valid arm for the scenario 'katana' (which draws the trail of the marker 'wrist').
ARM = '<link x="1" radius="0.05"><marker name="wrist"/>{}</link>'


# Malformed robot files (issue 5, part 4): what each is, its content.
ROBOT_FILES = {
    'z="1 0"': _Tree('<link z="1 0"/>'),
    'z="0_19"': _Tree('<link z="0_19"/>'),
    "an unknown element in <constraint>": _Tree(
        _Joint() + '<constraintList><constraint a="1" q="0" b="1"><foo/></constraint>'
        "</constraintList>"
    ),
    "a <link> in a <box>": _Tree(
        '<link z="1"><box width="1" height="1" depth="1"><link z="1"/></box></link>'
    ),
    "ISO-8859-1, undeclared": _Tree("<!-- caf\u00e9 -->").encode("latin-1"),
    "no joints (valid XML)": _Tree('<link z="1" radius="0.05"/>'),
    "ISO-8859-1, declared (valid)": _Tree("<!-- caf\u00e9 -->" + _Joint("", ARM.format("")))
    .replace('<?xml version="1.0"?>', '<?xml version="1.0" encoding="ISO-8859-1"?>')
    .encode("latin-1"),
    "nesting 1000 deep": _Tree('<link z="1">' * 1000 + "</link>" * 1000),
    'a joint named "a<b"': _Tree(_Joint('name="a&lt;b"')),
    'a joint named "a::b"': _Tree(_Joint('name="a::b"')),
    'a joint named ""': _Tree(_Joint('name=""')),
    'a joint named "base"': _Tree(_Joint('name="base"')),
    "an axis of 1e308": _Tree(_Joint().replace('z="1"', 'z="1e308"')),
    "limits of +-1e308": _Tree(
        _Joint().replace('minPos="0" maxPos="10" ', 'minPos="-1e308" maxPos="1e308" ', 1)
    ),
    'version="2.0"': _Tree("").replace('version="1.0" r', 'version="2.0" r'),
    "20,000 markers (valid)": _Tree(
        _Joint("", ARM.format("".join(f'<marker name="m{i}"/>' for i in range(20000))))
    ),
}


def _Bomb(key: str) -> str:
    """A 'billion laughs' YAML file (9^8 nodes) under ``key``."""
    lines = ['_l0: &l0 ["x", "x", "x", "x", "x", "x", "x", "x", "x"]']
    lines += [f"_l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * 9) + "]" for i in range(1, 8)]
    return "\n".join([*lines, f"{key}: [" + ", ".join(["*l7"] * 9) + "]"]) + "\n"


def Trials(folder: pathlib.Path) -> list[tuple[str, list[str]]]:
    """(what is tried, the command's arguments) in order; files are made here as they are needed."""
    thesis_folder = folder / "thesis"
    thesis_folder.mkdir()
    (thesis_folder / "thesis.tex").write_text("chapter 1")
    a_file = folder / "notes.txt"
    a_file.write_text("mine")
    for name, data in (
        ("binary.yaml", b"\x00\x01"),
        ("latin1.yaml", b"\xff\xfe duration: 3"),
        ("empty.yaml", b""),
        ("bomb_scenario.yaml", _Bomb("objects").encode()),
        ("bomb_overlay.yaml", _Bomb("exclude").encode()),
        ("deep_scenario.yaml", ("duration: " + "[" * 5000 + "]" * 5000).encode()),
    ):
        (folder / name).write_bytes(data)
    robot_trials = []
    for i, (what, data) in enumerate(ROBOT_FILES.items()):
        path = folder / f"robot_{i}.xml"
        path.write_bytes(data if isinstance(data, bytes) else data.encode())
        robot_trials.append((
            f"robot file: {what}",
            ["run", "katana", "--duration", "0.1", "--no-meshcat", "--no-log",
             "--set", f"{{robot: !ZeroPositionConfig {{file: {path}}}}}"],
        ))  # fmt: skip
    run = ["run", "explore_hypercube", "--no-meshcat"]
    checkpoint = str(folder / "run")
    return [
        ("checkpoint: a user's folder", [*run, "--duration", "1", "--checkpoint", str(thesis_folder)]),
        ("checkpoint: a file", [*run, "--duration", "1", "--checkpoint", str(a_file)]),
        ("a run to 3 s with a checkpoint", [*run, "--duration", "3", "--checkpoint", checkpoint]),
        ("the same run again (finished)", [*run, "--duration", "3", "--checkpoint", checkpoint]),
        ("the checkpoint later than --duration", [*run, "--duration", "1", "--checkpoint", checkpoint]),
        ("an unknown model in info", ["info", "--model", "iCubMars"]),
        ("a trail marker that does not exist", ["run", "reach_around_ball", "--duration", "0.1", "--set", "{visualization: {trail_marker: nose}}"]),
        ("resume with another seed", [*run, "--duration", "4", "--checkpoint", checkpoint, "--set", "{random_seed: 5}"]),
        ("resume with another time step", [*run, "--duration", "4", "--checkpoint", checkpoint, "--set", "{time_step: 0.01}"]),
        ("resume with another strategy", [*run, "--duration", "4", "--checkpoint", checkpoint, "--set", "{attractor: !ExploreAttractor {agents: [{name: right_arm, joints: [r_shoulder_pitch, r_shoulder_roll, r_shoulder_yaw, r_elbow], explorer: {strategy: random}}]}}"]),
        ("resume with the same configuration, longer", [*run, "--duration", "4", "--checkpoint", checkpoint]),
        ("recording into a file's folder", ["run", "reach_around_ball", "--duration", "0.1", "--record", str(a_file / "x.html")]),
        ("time_step: .inf", ["run", "reach_around_ball", "--set", "{time_step: .inf}"]),
        ("time_step: 1e6", ["run", "reach_around_ball", "--set", "{time_step: 1e6}"]),
        ("--duration 0", ["run", "reach_around_ball", "--duration", "0"]),
        ("--duration inf", ["run", "reach_around_ball", "--duration", "inf"]),
        ("--duration 1e308", ["run", "reach_around_ball", "--duration", "1e308"]),
        ("--duration -1", ["run", "reach_around_ball", "--duration", "-1"]),
        ("--duration nan", ["run", "reach_around_ball", "--duration", "nan"]),
        ("invalid YAML in --set", ["run", "reach_around_ball", "--set", "{duration: ["]),
        ("nearest: -3", ["run", "explore_hypercube", "--set", "{attractor: !ExploreAttractor {agents: [{name: a, joints: [r_elbow], nearest: -3}]}}"]),
        ("empty levels", ["run", "explore_hypercube", "--set", "{attractor: !ExploreAttractor {agents: [{name: a, joints: [r_elbow], levels: []}]}}"]),
        ("empty joints", ["run", "explore_hypercube", "--set", "{attractor: !ExploreAttractor {agents: [{name: a, joints: []}]}}"]),
        ("duplicate agent names", ["run", "explore_hypercube", "--set", "{attractor: !ExploreAttractor {agents: [{name: a, joints: [r_elbow]}, {name: a, joints: [l_elbow]}]}}"]),
        ("a negative sphere radius", ["run", "reach_around_ball", "--set", "{objects: [{name: b, shape: !Sphere {radius: -0.1}}]}"]),
        ("a binary scenario file", ["run", str(folder / "binary.yaml")]),
        ("a non-UTF-8 scenario file", ["run", str(folder / "latin1.yaml")]),
        ("an empty scenario file", ["run", str(folder / "empty.yaml")]),
        ("ch7 --transitions -5", ["experiment", "ch7", "--experiment", "7.2", "--transitions", "-5"]),
        ("ch8 --workers 0", ["experiment", "ch8", "--workers", "0"]),
        ("ch8 --checkpoint-every 0", ["experiment", "ch8", "--checkpoint-every", "0"]),
        ("ch8 --seeds 0", ["experiment", "ch8", "--seeds", "0"]),
        ("ch8 --problem-tries 0", ["experiment", "ch8", "--problem-tries", "0"]),
        ("ch8 --reach-force -3", ["experiment", "ch8", "--reach-force", "-3"]),
        ("saggriac into a user's folder", ["experiment", "saggriac", "--smoke", "--experiments", "1", "--output", str(thesis_folder)]),
        ("saggriac smoke battery", ["experiment", "saggriac", "--smoke", "--experiments", "1", "--seeds", "1", "--output", str(folder / "sagg")]),
        ("the same battery, its runs with other settings", ["experiment", "saggriac", "--experiments", "1", "--seeds", "1", "--budget-exp1", "600", "--checkpoints", "3", "--output", str(folder / "sagg")]),
        *robot_trials,
        ("a 'billion laughs' scenario file", ["run", str(folder / "bomb_scenario.yaml")]),
        ("a scenario file nested 5000 deep", ["run", str(folder / "deep_scenario.yaml")]),
        ("a 'billion laughs' overlay file", ["run", "reach_around_ball", "--duration", "0.1", "--no-meshcat", "--no-log", "--set", f"{{robot: {{overlay: {folder / 'bomb_overlay.yaml'}}}}}"]),
    ]  # fmt: skip


def main() -> None:
    folder = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp())
    folder.mkdir(parents=True, exist_ok=True)
    print("| tried | exit code | last line |")
    print("|---|---:|---|")
    for what, args in Trials(folder):
        done = subprocess.run(
            [sys.executable, "-m", "mobee_drake.cli", *args],
            capture_output=True,
            text=True,
            timeout=600,
        )
        lines = (done.stdout + done.stderr).strip().splitlines()
        last = lines[-1] if lines else ""
        if "Traceback" in done.stderr:
            last = "TRACEBACK: " + last
        print(f"| {what} | {done.returncode} | {last.replace('|', '/')[:150]} |", flush=True)


if __name__ == "__main__":
    main()
