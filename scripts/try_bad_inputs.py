"""Tries bad inputs as a new user would, and tallies what each ends in.

The bad inputs and misuses of issues 18 and 31 on the command line, and the malformed robot
(MoBeE XML), overlay and scenario files of issue 5: it prints what each ends in (exit code and
the last line it printed) as a markdown table, then the tally:

- *clear*: a bad input refused with one line beginning ``error:`` (or the parser's
  ``...: error:``) and a non-zero exit code;
- *unclear*: refused otherwise (several lines, no ``error:``, a line of more than
  :data:`MAX_LINE` characters);
- *traceback*: a Python traceback;
- *silent*: a bad input that ran and exited 0;
- *hang*: no end within two minutes;
- *valid*: a legitimate use (:data:`VALID`) that ran (exit 0).

Run: ``python scripts/try_bad_inputs.py [--folder FOLDER] [--doc docs/durability.md]`` (FOLDER:
where to make the trials' files, a temporary folder by default; ``--doc`` rewrites the doc's
generated table and tally). A few minutes: each trial starts the command afresh.
"""

import argparse
import collections
import os
import pathlib
import subprocess
import sys
import tempfile

from mobee_drake.experiments.doc_tables import WriteGeneratedTable


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
        *_Issue31Trials(folder, thesis_folder),
    ]  # fmt: skip


def _Issue31Trials(folder: pathlib.Path, thesis_folder: pathlib.Path) -> list:
    """The reproductions of issue 31 (each was a traceback, silent or a hang)."""
    objects = "".join(
        f"  - {{name: b{i}, shape: !Sphere {{radius: 0.01}}, position: [-2, 0, {i * 0.03:.2f}]}}\n"
        for i in range(2001)
    )
    (folder / "many_objects.yaml").write_text("objects:\n" + objects)
    os.mkfifo(folder / "fifo.yaml")
    (folder / "huge.yaml").write_text("duration: " + "x" * 10_000_000 + "\n")
    (folder / "bell.yaml").write_text("duration: 1\x07\n")
    run = ["run", "reach_around_ball", "--no-meshcat", "--no-log", "--duration", "0.1", "--set"]
    agent = "{{attractor: !ExploreAttractor {{agents: [{{name: a, joints: [r_elbow], {}}}]}}}}"
    return [
        ("an agent named '../../x'", [*run, "{attractor: !ExploreAttractor {agents: [{name: ../../x, joints: [r_elbow]}]}}"]),
        ("levels: [0.5]", [*run, agent.format("levels: [0.5]")]),
        ("levels: [0.5, 0.5]", [*run, agent.format("levels: [0.5, 0.5]")]),
        ("nearest: 1000", [*run, agent.format("nearest: 1000")]),
        ("explorer delta: -1", [*run, agent.format("explorer: {delta: -1}")]),
        ("explorer delta: .nan", [*run, agent.format("explorer: {delta: .nan}")]),
        ("controlled_joints: []", [*run, "{robot: {controlled_joints: []}}"]),
        ("an unknown contact_model", [*run, "{mover: !Dynamic {plant_config: {contact_model: bogus}}}"]),
        ("an unknown integration_scheme", [*run, "{simulator_config: {integration_scheme: bogus}}"]),
        ("time_step: 1e-9", [*run, "{time_step: 1e-9}"]),
        ("target_realtime_rate: 1e-6", [*run, "{simulator_config: {target_realtime_rate: 1e-6}}"]),
        ("a key given twice", [*run, "{duration: 1, duration: 2}"]),
        ("an object at 1e300 m", [*run, "{objects: [{name: b, shape: !Sphere {radius: 0.1}, position: [1e300, 0, 0]}]}"]),
        ("max_step_size: -1", [*run, "{simulator_config: {max_step_size: -1}}"]),
        ("--set ''", [*run, ""]),
        ("--record ''", ["run", "reach_around_ball", "--record", ""]),
        ("--checkpoint ''", ["run", "reach_around_ball", "--checkpoint", ""]),
        ("bench forces --amplitude 5", ["bench", "forces", "--amplitude", "5"]),
        ("bench forces --plot into a file", ["bench", "forces", "--plot", str(folder / "notes.txt" / "x.png")]),
        ("ch8 --stages 2 2", ["experiment", "ch8", "--stages", "2", "2"]),
        ("ch8 --report-only on a missing folder", ["experiment", "ch8", "--report-only", "--output", str(folder / "missing")]),
        ("trm into a user's folder", ["experiment", "trm", "--output", str(thesis_folder)]),
        ("saggriac --analyse-only into a user's folder", ["experiment", "saggriac", "--analyse-only", "--output", str(thesis_folder)]),
        ("ch8-discounting --gamma 1.5", ["experiment", "ch8-discounting", "--model", "m", "--gamma", "1.5"]),
        ("ch8-discounting --units 0", ["experiment", "ch8-discounting", "--model", "m", "--units", "0"]),
        ("ch8-discounting --misses 0.3 0.1", ["experiment", "ch8-discounting", "--model", "m", "--misses", "0.3", "0.1"]),
        ("ch8-discounting --runs of a missing file", ["experiment", "ch8-discounting", "--model", "m", "--runs", str(folder / "no.json")]),
        ("bench simulation --seconds 0.5", ["bench", "simulation", "--seconds", "0.5"]),
        ("bench simulation --scenario nonexistent", ["bench", "simulation", "--scenario", "nonexistent"]),
        ("bench simulation --controls bogus", ["bench", "simulation", "--controls", "bogus"]),
        ("2,001 objects", ["run", str(folder / "many_objects.yaml")]),
        ("--ray with an address nobody answers", ["experiment", "saggriac", "--smoke", "--output", str(folder / "ray"), "--ray", "127.0.0.1:1"]),
        ("--ray with no address format", ["experiment", "saggriac", "--smoke", "--output", str(folder / "ray"), "--ray", "bogus"]),
        ("saggriac --smoke --budget-exp1 700 (the flag's budget)", ["experiment", "saggriac", "--smoke", "--experiments", "1", "--budget-exp1", "700", "--output", str(folder / "s1")]),
        ("saggriac --checkpoints beyond the budget", ["experiment", "saggriac", "--experiments", "1", "--budget-exp1", "100", "--checkpoints", "500", "--output", str(folder / "s2")]),
        ("ch8 --reach-force 1e300", ["experiment", "ch8", "--reach-force", "1e300", "--output", str(folder / "c1")]),
        ("ch8 --distance-unit 1e-300", ["experiment", "ch8", "--distance-unit", "1e-300", "--output", str(folder / "c2")]),
        ("ch8 --output a file", ["experiment", "ch8", "--output", str(folder / "notes.txt")]),
        ("ch7 --output a file", ["experiment", "ch7", "--experiment", "7.1", "--output", str(folder / "notes.txt")]),
        ("an unknown controlled joint", [*run, "{robot: {controlled_joints: [nope]}}"]),
        ("a folder as the scenario", ["run", str(thesis_folder)]),
        ("a FIFO as the scenario", ["run", str(folder / "fifo.yaml")]),
        ("a 10 MB value in a scenario file", ["run", str(folder / "huge.yaml")]),
        ("a control character in a scenario file", ["run", str(folder / "bell.yaml")]),
    ]  # fmt: skip


# The trials that are legitimate uses (they should run, exit 0); every other one is a mistake.
VALID = {
    "a run to 3 s with a checkpoint",
    "the same run again (finished)",
    "resume with the same configuration, longer",
    "saggriac smoke battery",
    "robot file: ISO-8859-1, declared (valid)",
    "robot file: 20,000 markers (valid)",
    "saggriac --smoke --budget-exp1 700 (the flag's budget)",
}
HANG_SECONDS = 120
# An error line longer than this is unclear (nobody reads a 10 MB line).
MAX_LINE = 2000


def Verdict(what: str, code: int | None, output: str) -> str:
    """What a trial ended in (the module's tally: clear, unclear, traceback, silent, hang,
    valid); ``code`` None: it did not end."""
    lines = output.strip().splitlines()
    if code is None:
        return "hang"
    if "Traceback" in output:
        return "traceback"
    if what in VALID:
        return "valid" if code == 0 else "unclear"
    if code == 0:
        return "silent"
    one_line = len([line for line in lines if "error:" in line]) == 1
    last = lines[-1] if lines else ""
    return "clear" if one_line and "error:" in last and len(last) <= MAX_LINE else "unclear"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--folder", help="where to make the trials' files")
    parser.add_argument("--doc", help="rewrite this doc's generated bad-input table and tally")
    args = parser.parse_args()
    folder = pathlib.Path(args.folder or tempfile.mkdtemp())
    folder.mkdir(parents=True, exist_ok=True)
    rows = ["| tried | exit code | verdict | last line |", "|---|---:|---|---|"]
    print("\n".join(rows))
    tally = collections.Counter()
    for what, args_ in Trials(folder):
        try:
            done = subprocess.run(
                [sys.executable, "-m", "mobee_drake.cli", *args_],
                capture_output=True,
                text=True,
                timeout=HANG_SECONDS,
            )
            code, output = done.returncode, done.stdout + done.stderr
        except subprocess.TimeoutExpired:
            code, output = None, ""
        verdict = Verdict(what, code, output)
        tally[verdict] += 1
        lines = output.strip().splitlines()
        last = (lines[-1] if lines else "").replace("|", "/")[:150]
        rows.append(f"| {what} | {code if code is not None else '-'} | {verdict} | {last} |")
        print(rows[-1], flush=True)
    kinds = ("clear", "unclear", "traceback", "silent", "hang", "valid")
    summary = (
        "| "
        + " | ".join(kinds)
        + " |\n|"
        + "---:|" * len(kinds)
        + "\n| "
        + " | ".join(str(tally[k]) for k in kinds)
        + " |\n"
    )
    print("\n" + summary)
    if args.doc:
        command = "python scripts/try_bad_inputs.py --doc " + args.doc
        WriteGeneratedTable(args.doc, "bad-input tally", command, summary)
        WriteGeneratedTable(args.doc, "bad inputs", command, "\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
