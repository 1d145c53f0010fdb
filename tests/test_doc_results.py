"""The tables of docs/ that a report writes from a battery kept in docs/results are what the
report gives from the kept result files now: a table edited by hand, or left behind by runs
added to its folder since, fails (docs/results/README.md)."""

import json
import pathlib
import re
import unittest

import numpy as np

from mobee_drake.atomic_files import CurrentGeneration
from mobee_drake.experiments.adaptive_space import AdaptiveSpaceRun
from mobee_drake.experiments.adaptive_space_command import KeptReport, SpaceHistories
from mobee_drake.experiments.arms import Arms, ReachTargets
from mobee_drake.experiments.ch8_claims import ClaimsTables
from mobee_drake.experiments.ch8_reaching import StoredResults
from mobee_drake.experiments.doc_tables import GeneratedBlocks

ROOT = pathlib.Path(__file__).parents[1]

# The command of a block written by the ch. 8 report of a kept battery.
_CH8_KEPT = re.compile(r"^mobee-drake experiment ch8 --report-only --output (docs/results/\S+) ")
# The command of a block written by the adaptive-space report of a battery kept here.
_ADAPTIVE_KEPT = re.compile(
    r"^mobee-drake experiment adaptive-space (?=.*--report-only)(?=.*--output docs/results/\S)"
)
# A ratio with its interval, as the prose quotes one: "1.43 [1.40, 1.46]".
_RATIO = re.compile(r"(\d+\.\d+) \[(\d+\.\d+), (\d+\.\d+)\]")
# A difference with its interval, signed: "-0.01 [-0.12, +0.11]".
_DIFFERENCE = re.compile(r"[+-]\d+\.\d+ \[[+-]\d+\.\d+, [+-]\d+\.\d+\]")


def _Folded(text: str) -> str:
    return " ".join(text.split())


def _ProseAndBlocks(doc: pathlib.Path) -> tuple[str, str]:
    """``doc``'s text without its generated blocks, and the blocks' (each folded to one
    line, joined)."""
    prose, tables = doc.read_text(), []
    for _, _, table in GeneratedBlocks(doc):
        prose = prose.replace(table, "")
        tables.append(_Folded(table))
    return _Folded(prose), " ".join(tables)


class TestKeptBatteries(unittest.TestCase):
    def test_every_ch8_claims_table_is_what_its_kept_runs_give(self):
        blocks = [
            (doc, name, ROOT / kept[1], table)
            for doc in sorted((ROOT / "docs").glob("*.md"))
            for name, command, table in GeneratedBlocks(doc)
            if (kept := _CH8_KEPT.match(command))
        ]
        self.assertLessEqual({"ch8-stage100", "ch8-sweep400"}, {name for _, name, _, _ in blocks})
        for doc, name, folder, table in blocks:
            with self.subTest(doc=doc.name, block=name):
                results = StoredResults(folder)
                self.assertTrue(results, f"{folder}: no finished runs")
                self.assertEqual(table.rstrip(), "\n".join(ClaimsTables(results)).rstrip())

    def test_every_adaptive_space_report_is_what_its_kept_runs_give(self):
        """docs/adaptive_space.md's blocks (its two batteries' and any other): each, once
        written by a battery's ``--report-only`` from a folder kept here, is what that command
        gives now (its figures' line aside); until then it says it has not been run."""
        blocks = GeneratedBlocks(ROOT / "docs" / "adaptive_space.md")
        names = {"adaptive-space", "adaptive-space-reaching"}
        self.assertEqual({name for name, _, _ in blocks} & names, names)
        for name, command, text in blocks:
            with self.subTest(block=name):
                if command == "(not yet run)":
                    self.assertEqual(text, "")
                    continue
                self.assertRegex(command, _ADAPTIVE_KEPT)
                self.assertEqual(text.split("\n\nFigures (")[0].rstrip(), KeptReport(command, ROOT))

    def _AssertTheBatterysRunsButForWallTime(
        self, side: str, battery: str, count: int, parted: dict | None = None
    ) -> None:
        """The ``count`` runs kept in ``side`` are ``battery``'s runs of the same names,
        measure for measure, but for their wall time, and for the measures ``parted`` names
        for a run (name: the measures in which it differs)."""
        results = ROOT / "docs" / "results"
        runs = sorted((results / side).glob("runs/*_seed*"))
        self.assertEqual(len(runs), count)
        for run in runs:
            with self.subTest(run=run.name):
                kept, made = (
                    json.loads((folder / run.name / "result.json").read_text())
                    for folder in (run.parent, results / battery / "runs")
                )
                differ = {
                    key for key in kept.keys() | made.keys() if kept.get(key) != made.get(key)
                }
                self.assertEqual(differ, {"wall_seconds", *(parted or {}).get(run.name, ())})

    def test_the_one_blas_thread_runs_are_the_batterys_but_for_their_wall_time(self):
        """docs/adaptive_space.md says the runs made with one BLAS thread a worker are the
        exploration battery's runs of the same names, measure for measure, but for their wall
        time."""
        self._AssertTheBatterysRunsButForWallTime(
            "adaptive_space_one_blas_thread", "adaptive_space", 16
        )

    def test_the_dense_t_runs_are_the_batterys_but_for_their_wall_time(self):
        """docs/adaptive_space.md says the reaching battery's first 32 runs, made while the
        reach learner held T dense, are the battery's runs of the same names (made with T
        sparse), measure for measure, but for their wall time; but for one, whose log parts
        where a transition's two values compared the other way (its robot time and
        penetrations differ, not what it learned)."""
        parted = {
            "reach_trm_random_maintained_seed0": (
                "robot_hours",
                "exploring_hours",
                "penetrating_steps",
                "appeared_inside",
            )
        }
        self._AssertTheBatterysRunsButForWallTime(
            "adaptive_space_reaching_dense_t", "adaptive_space_reaching_303aba8", 32, parted
        )

    def test_the_side_batterys_code_makes_the_batterys_runs(self):
        """docs/adaptive_space.md says a maintained roadmap run of the reaching battery, made
        again with 30c7f3e's code (its sparse ``ObservedOutcomes``), is the battery's run, of
        the same arguments, measure for measure, but for its wall time."""
        results = ROOT / "docs" / "results"
        self._AssertTheBatterysRunsButForWallTime(
            "adaptive_space_reaching_again", "adaptive_space_reaching_303aba8", 1
        )
        (run,) = (results / "adaptive_space_reaching_again").glob("runs/*")
        made = results / "adaptive_space_reaching_303aba8" / "runs" / run.name
        self.assertEqual((run / "job.json").read_text(), (made / "job.json").read_text())
        sittings = (results / "adaptive_space_reaching_again" / "sessions.jsonl").read_text()
        self.assertEqual(
            {(s["commit"][:7], s["changed"]) for s in map(json.loads, sittings.splitlines())},
            {("30c7f3e", False)},
        )
        # (made beside other work: more than twice the battery's wall time, as the doc says)
        again, battery = (
            json.loads((folder / "result.json").read_text())["wall_seconds"]
            for folder in (run, made)
        )
        self.assertGreater(again, 2 * battery)

    def test_the_wedged_katanas_probe_is_the_batterys_run_and_the_docs_figures(self):
        """docs/adaptive_space.md's account of the Katana's run wedged inside itself is its
        probe's (scripts/probe_penetrations.py): the battery's run but for its wall time and
        the split (the probe's watch is adf6900's); the problems that ended with the arm inside
        itself, from the first on every one, their periods, the first's start, the joint
        farthest beyond its limits at its end and the forces there, the later problems'
        lengths."""
        results = ROOT / "docs" / "results"
        name = "reach_katana_random_maintained_seed1"
        probe = json.loads((results / "adaptive_space_reaching_probe" / f"{name}.json").read_text())
        made = json.loads(
            (results / "adaptive_space_reaching_303aba8/runs" / name / "result.json").read_text()
        )
        kept, split = probe["result"], {"appeared_inside", "other_penetrating_steps"}
        differ = {k for k in made if kept[k] != made[k]}  # (the probe's code keeps more)
        self.assertEqual(differ, {"wall_seconds", *split})
        self.assertLess(kept["closest_to_itself"], 0.0)
        problems = probe["problems"]
        self.assertEqual(len(problems), made["appeared_inside"])  # (the old watch's count)

        def Wedged(moment: dict) -> bool:
            return any("'reach_target'" not in pair for pair in moment["pairs"])

        wedged = [i for i, p in enumerate(problems) if Wedged(p["at_end"])]
        self.assertEqual(wedged, list(range(wedged[0], len(problems))))
        periods = sum(problems[i]["periods"] for i in wedged)
        self.assertEqual(kept["other_penetrating_steps"], periods)  # (the new watch's split)
        first, later = problems[wedged[0]], problems[wedged[0] + 1 :]
        self.assertFalse(Wedged(first["at_start"]))
        self.assertTrue(all(Wedged(p["at_start"]) for p in later))
        lengths = " or ".join(str(n) for n in sorted({p["periods"] for p in later}))
        lower, upper = (np.array(probe["limits"][side]) for side in ("lower", "upper"))
        q = np.array(first["at_end"]["q"])
        outside = np.maximum(lower - q, q - upper)
        joint = int(np.argmax(outside))
        others = [ORDINALS[j] for j in np.flatnonzero(outside > 0) if j != joint]
        beyond = " and the ".join(others)
        pushed = int(np.argmax(np.abs(first["at_start"]["f_barrier"])))
        # (the last evaluation: its tries of every target, after the exploration)
        job = json.loads(
            (results / "adaptive_space_reaching_303aba8/runs" / name / "job.json").read_text()
        )
        evaluated = job["evaluations"] * len(ReachTargets(Arms()["katana"]).Centres())
        self.assertLessEqual(len(wedged), evaluated)
        for p in later:  # (the arm did not move again)
            np.testing.assert_allclose(p["at_end"]["q"], q, atol=0.01)
        doc = _Folded((ROOT / "docs" / "adaptive_space.md").read_text())
        for text in (
            f"counts {made['penetrating_steps']:,} penetrating periods, all among the "
            f"{len(problems)} problems",
            f"{len(wedged)} of its {len(problems)} problems were closed with the arm's own solids",
            f"({first['at_end']['pairs'][0].removeprefix('the robot: ')},",
            f"those hold {periods:,} of its {made['penetrating_steps']:,} penetrating periods",
            f"the {wedged[0] + 1}th such problem",
            f"({first['at_start']['pairs'][0].removeprefix('the robot: ')})",
            f"{ORDINALS[joint]} of MoBeE's joints stood at {q[joint]:.2f} rad, its limits "
            f"[{lower[joint]:.2f}, {upper[joint]:.2f}] (the {beyond} stood beyond theirs too)",
            f"All {len(wedged)} fell in the run's last evaluation",
            f"{len(wedged)} of the {evaluated} problems whose summed reward",
            f"pushed the {ORDINALS[pushed]} joint with "
            f"{first['at_start']['f_barrier'][pushed]:.0f}",
            f"force ({first['at_end']['f_lim'][joint]:.0f}) and the barrier's "
            f"({first['at_end']['f_barrier'][joint]:.0f})",
            f"counted {lengths} penetrating periods until the next was closed",
            f"with {probe['commit'][:7]}'s code",
            f"the same run counts {kept['appeared_inside']} problems whose target appeared "
            f"inside and {periods:,} periods among the others",
        ):
            with self.subTest(text=text):
                self.assertIn(text, doc)
        self.assertEqual(made["other_penetrating_steps"], 0)
        depth = first["at_start"]["pairs"][0].split("' ")[1].split(" mm")[0]
        mobee = _Folded((ROOT / "docs" / "mobee.md").read_text())
        self.assertIn(f"appeared {depth} mm inside the Katana's forearm", mobee)
        self.assertIn(f"a joint stood at {q[joint]:.2f} rad", mobee)

    def test_the_runs_whose_arm_came_inside_itself_are_the_docs(self):
        """docs/adaptive_space.md counts the reaching battery's finished runs whose robot came
        inside itself (its last checkpoint's safety monitor: the closest approach of the robot's
        own solids below zero), by robot and condition."""
        runs = ROOT / "docs" / "results" / "adaptive_space_reaching_303aba8" / "runs"
        inside, finished = [], sorted(runs.glob("reach_*/result.json"))
        for result in finished:
            last = CurrentGeneration(result.parent / "checkpoint")
            with np.load(last / "simulation" / "simulation.npz") as saved:
                # (the monitor's state: per object, "(self)", "(other objects)", then the
                # penetrating periods, the deepest penetration and the barrier's periods)
                monitor = saved["safety_monitor/0"]
            if monitor[-5] < 0:
                inside.append(json.loads(result.read_text()))
        robots = {r.get("robot", "icub") for r in inside}
        maintained = sum(r["condition"] == "maintained" for r in inside)
        self.assertEqual(robots, {"katana"})
        katana = [json.loads(f.read_text()) for f in finished if "katana" in f.parent.name]
        by_space = {
            space: (
                sum(r.get("space", "rank3") == space for r in inside),
                sum(r.get("space", "rank3") == space for r in katana),
            )
            for space in ("trm", "rank3")
        }
        doc = _Folded((ROOT / "docs" / "adaptive_space.md").read_text())
        self.assertIn(
            f"In {len(inside)} of its {len(finished)} finished runs, all the Katana's "
            f"({maintained} maintained, {len(inside) - maintained} fixed)",
            doc,
        )
        self.assertIn(
            f"{by_space['trm'][0]} of the Katana's {by_space['trm'][1]} finished roadmap runs and "
            f"{by_space['rank3'][0]} of its {by_space['rank3'][1]} lattice runs",
            doc,
        )

    def _CheckQuotedDifferences(self, prose: str, tables: str) -> None:
        self.assertTrue(_DIFFERENCE.findall(prose))  # (a change of format would check nothing)
        for difference in _DIFFERENCE.findall(prose):
            with self.subTest(difference=difference):
                self.assertIn(difference, tables)

    def test_the_ratios_the_prose_quotes_are_its_generated_blocks(self):
        """docs/reaching.md's prose quotes random's robot time over the others' from its
        generated blocks (R times [low, high]), and any difference with its interval; a block
        written again from new runs fails the prose that still quotes the old figures."""
        prose, tables = _ProseAndBlocks(ROOT / "docs" / "reaching.md")
        quoted = _RATIO.findall(prose)
        self.assertTrue(quoted)
        for ratio, low, high in quoted:
            with self.subTest(ratio=ratio):
                self.assertIn(f"{ratio} times [{low}, {high}]", tables)
        self._CheckQuotedDifferences(prose, tables)  # (ch. 8.5's among them)

    def test_the_differences_adaptive_space_quotes_are_its_blocks(self):
        """docs/adaptive_space.md's verdict quotes differences with their intervals from its
        generated blocks ("+1.23 [+0.45, +2.01]"): each must be in a block."""
        self._CheckQuotedDifferences(*_ProseAndBlocks(ROOT / "docs" / "adaptive_space.md"))


ORDINALS = ("first", "second", "third", "fourth", "fifth", "sixth")


def _Rows(table: str) -> dict[str, list[str]]:
    """The rows of the first markdown table in a generated block: the first cell, then the
    others."""
    rows = {}
    for line in table.split("\n\n|", 1)[-1].split("\n\n")[0].splitlines():
        if not line.startswith("|---"):
            cells = [c.strip() for c in line.strip("|").split("|")]
            rows[cells[0]] = cells[1:]
    return rows


class TestAdaptiveSpaceCounts(unittest.TestCase):
    """The counts docs/adaptive_space.md's exploration verdict takes from the battery's kept runs
    (their checkpoints' changes), not from its blocks."""

    def test_the_pruned_states_grown_first_and_the_roadmaps_one_shortcut(self):
        output = ROOT / "docs" / "results" / "adaptive_space"
        runs = output / "runs"
        kept = [
            AdaptiveSpaceRun(**json.loads(r.read_text()))
            for r in sorted(runs.glob("icub_rank4_*/result.json"))
        ]
        (history,) = SpaceHistories(kept, output)["icub"]  # (the figure's: the first seed's)
        doc = _Folded((ROOT / "docs" / "adaptive_space.md").read_text())
        self.assertIn(
            f"in the first seed's run {history.added_then_removed} of its "
            f"{len(history.removed)}, the figure above",
            doc,
        )
        shortcuts = {
            robot: [
                json.loads(r.read_text())["changes"]
                for r in sorted(runs.glob(f"{robot}_trm_maintained_seed*/result.json"))
            ]
            for robot in ("icub", "katana")
        }
        self.assertEqual(len(shortcuts["icub"]), 10)
        self.assertFalse(any(any(c.values()) for c in shortcuts["icub"]))  # (nothing changed)
        katana = [c for c in shortcuts["katana"] if any(c.values())]
        self.assertEqual(katana, [dict.fromkeys(katana[0], 0) | {"shortcut": 1}])
        self.assertIn("on the Katana made one shortcut in one run", doc)


class TestReactiveQuotes(unittest.TestCase):
    """The figures docs/reactive.md and docs/mobee.md quote from `bench reactive` are its
    generated tables' (median time to reach: column 3; worst clearance to obstacles: 5)."""

    def test_the_quoted_times_and_clearances_are_the_tables(self):
        blocks = {
            name: _Rows(table) for name, _, table in GeneratedBlocks(ROOT / "docs/reactive.md")
        }
        main, no_flow = blocks["reactive"], blocks["reactive-no-flow"]
        palm, fast = main["MoBeE (defaults), palm goal"], main["DiffIK, 1 cm, 1 rad/s"]
        slow = [main["DiffIK, 1 cm"][2], main["DiffIK, 3 cm (MoBeE's field)"][2]]
        unflowed = no_flow["MoBeE (defaults_no_flow), palm goal"]
        reactive = _Folded((ROOT / "docs/reactive.md").read_text())
        self.assertIn(
            f"median time to reach: {palm[2]} s against {slow[0]} and {slow[1]} s", reactive
        )
        self.assertIn(f"(median {fast[2]} against {palm[2]} s)", reactive)
        mobee = _Folded((ROOT / "docs/mobee.md").read_text())
        self.assertIn(
            f"worst clearance from {unflowed[4].lstrip('+')} to {palm[4].lstrip('+')} cm and "
            f"shortened their median time from {unflowed[2]} to {palm[2]} s",
            mobee,
        )
