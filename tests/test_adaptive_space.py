"""The adaptive-space experiment (ch. 9.4.5): its measures against closed forms and its smoke
battery on the robot."""

import contextlib
import io
import json
import pathlib
import shutil
import tempfile
import types
import unittest

import numpy as np
from test_figures import FigureTest

from mobee_drake.experiments import adaptive_space, adaptive_space_command
from mobee_drake.experiments.adaptive_space_figures import Figure
from mobee_drake.experiments.arms import (
    Arms,
    ReachTargets,
    RoadmapSpace,
    TargetGaps,
    ValidConfigurations,
)
from mobee_drake.experiments.doc_tables import GeneratedBlocks
from mobee_drake.planning.state_space import Lattice
from mobee_drake.reaching.targets import LoadTargetGrid


class TestMeasures(unittest.TestCase):
    def test_the_distance_to_the_nearest_configuration_an_action_ended_in(self):
        """Actions ended at (0.25, 0.25) and (0.25, 0.75): the valid configurations' distances
        are to those, not to any state's centre; with no action, none is near."""
        settled = np.array([[0.25, 0.25], [0.25, 0.75]])
        valid = np.array([[0.25, 0.25], [0.3, 0.3], [0.75, 0.75]])
        np.testing.assert_allclose(
            adaptive_space.Nearest(settled, valid), [0.0, 0.05 * np.sqrt(2), 0.5]
        )
        self.assertTrue(np.all(np.isinf(adaptive_space.Nearest(np.zeros((0, 2)), valid))))

    def test_the_valid_configurations_keep_the_constraints_and_the_obstacles(self):
        """The iCub's sample keeps some draws and drops others (the shoulder's cable
        constraints cut the corners of the range); the Katana has no constraint clauses, but
        its scenario's obstacles drop some draws too. All within [0, 1]."""
        arms = Arms()
        for name in ("icub", "katana"):
            with self.subTest(robot=name):
                valid = ValidConfigurations(arms[name], 200, seed=1)
                self.assertTrue(20 < len(valid) < 200)
                self.assertTrue(np.all((valid >= 0) & (valid <= 1)))


class TestTheBatterysOrder(unittest.TestCase):
    def test_the_reach_runs_go_seed_by_seed(self):
        """Every setting's seed 0 before any seed 1: a battery of days stopped early reports on
        every robot and space alike."""
        from mobee_drake.experiments.adaptive_space_reaching import Stages
        from mobee_drake.planning.space_maintenance import MaintenanceConfig

        args = adaptive_space_command._Parser().parse_args(
            ["--part", "reaching", "--robots", "icub", "katana", "--seeds", "2"]
        )
        stages = Stages(args, MaintenanceConfig())
        self.assertEqual([d for d, _ in stages][-1], "adaptive reaching")
        seeds = [job.kwargs["seed"] for job in stages[-1][1]]
        settings = 2 * 2 * 3 * 2  # robots x spaces x strategies x conditions
        self.assertEqual(seeds, [0] * settings + [1] * settings)

    def test_the_closest_cell_gives_the_worst_of_the_runs(self):
        """The closest the robot came to itself over the runs (those whose own pairs came within
        a field) and the deepest penetration, in mm; "far" if none came near; "-" with a run
        from before they were kept."""
        from mobee_drake.experiments.adaptive_space_reaching import _ClosestCell

        def Run(closest, deepest):
            return types.SimpleNamespace(closest_to_itself=closest, deepest_penetration=deepest)

        self.assertEqual(_ClosestCell([Run(-0.04, 0.0633), Run(None, 0.01)]), "-40.0 / 63.3")
        self.assertEqual(_ClosestCell([Run(0.012, 0.0), Run(0.02, 0.005)]), "+12.0 / 5.0")
        self.assertEqual(_ClosestCell([Run(None, 0.0)]), "far / 0.0")
        self.assertEqual(_ClosestCell([Run(-0.04, 0.0633), Run(None, None)]), "-")

    def test_the_report_names_the_runs_without_a_result(self):
        """Of a two-seed battery on both robots, the results of all but the Katana's roadmap
        run with intrinsic, maintained, seed 1 and the iCub's lattice random fixed seeds 0 and
        1: the report names those three runs by setting, and no other."""
        from mobee_drake.experiments.adaptive_space_reaching import MissingRuns, Report, Stages
        from mobee_drake.planning.space_maintenance import MaintenanceConfig

        args = adaptive_space_command._Parser().parse_args(
            ["--part", "reaching", "--robots", "icub", "katana", "--seeds", "2"]
        )
        jobs = Stages(args, MaintenanceConfig())[-1][1]
        left_out = {
            "reach_katana_trm_intrinsic_maintained_seed1",
            "reach_random_fixed_seed0",
            "reach_random_fixed_seed1",
        }
        results = {job.name: {} for job in jobs if job.name not in left_out}
        missing = MissingRuns(jobs, results)
        self.assertEqual(
            missing,
            {
                ("katana", "trm", "intrinsic", "maintained"): [1],
                ("icub", "rank3", "random", "fixed"): [0, 1],
            },
        )
        self.assertIn(
            "Runs without a result (3: failed, or not finished; the comparisons leave out the "
            "pairs they belong to): icub rank3 random fixed seeds 0, 1; katana trm intrinsic "
            "maintained seed 1.",
            Report([], "test", missing=missing),
        )
        self.assertNotIn("Runs without a result", Report([], "test", missing={}))


class TestReachTargets(unittest.TestCase):
    def test_the_icub_has_the_sources_grid_and_the_katana_one_in_front_of_it(self):
        """The iCub's targets are its file's; the Katana's are a 3 x 3 x 3 grid of increasing
        levels, all in front of it (+x, beyond 10 cm), none in its base's column."""
        arms = Arms()
        self.assertEqual(ReachTargets(arms["icub"]), LoadTargetGrid())
        grid = ReachTargets(arms["katana"])
        self.assertEqual(grid.Centres().shape, (27, 3))
        for axis in "xyz":
            self.assertTrue(np.all(np.diff(getattr(grid, axis)) > 0), axis)
        self.assertGreater(min(grid.x), 0.1)

    def test_the_hand_that_may_touch_the_target_is_the_markers_body_and_beyond(self):
        """The iCub's hand is its palm's body alone; the Katana's wrist carries its two
        fingers, which may touch the target with it (so the wrist can come near)."""
        from mobee_drake.experiments.ch8_reaching import ReachRobot

        for robot, bodies in (
            ("icub", {"r_hand"}),
            ("katana", {f"arm_{i}_link" for i in (4, 5, 6)}),
        ):
            with self.subTest(robot=robot):
                reach = ReachRobot(Lattice([0.25, 0.5, 0.75], 4), 0.05, robot=robot)
                plant, frames = reach.station.plant, reach.station.robot.geometry_frames
                hand = {plant.get_frame(frames[g]).body().name() for g in reach._hand}
                self.assertEqual(hand, bodies)


class TestConfigurationRoadmap(unittest.TestCase):
    def test_every_vertex_is_a_valid_configuration_in_fractions(self):
        """A roadmap of 12 vertices over the right arm's shoulder and elbow: every vertex keeps
        the limits and the constraints and collides with nothing, its task point is its
        configuration in fractions of range, and no two are nearer than half the spacing."""
        from mobee_drake.ngik.kinematic_model import KinematicModel
        from mobee_drake.trm.configuration import BuildConfigurationRoadmap

        arm = Arms()["icub"]
        robot = arm.robot
        roadmap = BuildConfigurationRoadmap(robot, list(arm.joints), 0.6, 12)
        self.assertEqual(len(roadmap.q), 12)
        model = KinematicModel(robot)
        for q, y in zip(roadmap.q, roadmap.y):
            self.assertTrue(model.IsValid(q))
            self.assertFalse(model.Evaluate(q).collision_pairs)
            np.testing.assert_allclose(y, (q - model.lower) / (model.upper - model.lower))
        gaps = np.linalg.norm(roadmap.y[:, None] - roadmap.y[None], axis=2)
        self.assertGreaterEqual(gaps[np.triu_indices(12, 1)].min(), 0.3)


class TestSpaceHistory(unittest.TestCase):
    def test_the_history_follows_the_changes_in_order(self):
        """Three states; a state grown at 100 actions, the second initial state pruned at 200,
        another grown at 200, the first grown one pruned at 300 (a drop changes no state): two
        initial states kept, two removed (one of them grown first), one added, each where the
        palm is at its centre; a pruned state that is not there is refused."""
        from mobee_drake.experiments.adaptive_space_figures import (
            History,
            _Counts,
            _MarkerPositions,
        )

        arm = Arms()["icub"]
        initial = np.array([[0.25] * 4, [0.5] * 4, [0.75] * 4])
        grown = [[0.375] * 4, [0.625] * 4]
        changes = [
            dict(actions_done=100, rule="grow", states=[3, 0], centre=grown[0]),
            dict(actions_done=200, rule="prune", states=[1], centre=[0.5] * 4),
            dict(actions_done=200, rule="drop", states=[0, 2], centre=[]),
            dict(actions_done=200, rule="grow", states=[3, 2], centre=grown[1]),
            dict(actions_done=300, rule="prune", states=[2], centre=grown[0]),
        ]
        history = History("icub, test", arm, initial, changes)
        np.testing.assert_array_equal(history.added_at, [0, 0, 0, 100, 200])
        np.testing.assert_array_equal(history.pruned_at, [np.inf, 200, np.inf, 300, np.inf])
        palms = _MarkerPositions(arm, [*initial, *grown])
        np.testing.assert_array_equal(history.kept, palms[[0, 2]])
        np.testing.assert_array_equal(history.removed, palms[[1, 3]])
        self.assertEqual(history.added_then_removed, 1)
        np.testing.assert_array_equal(history.added, palms[[4]])
        self.assertEqual(_Counts(history), "2 kept, 2 removed (1 of them added first), 1 added")
        with self.assertRaisesRegex(ValueError, r"icub, test: pruned state \[0\.1"):
            History("icub, test", arm, initial, [dict(changes[1], centre=[0.1] * 4)])


def _KeptReport(report: str) -> str:
    """What :func:`adaptive_space_command.KeptReport` gives for the command ``report`` names."""
    command = report.split("Command: `")[1].split("`")[0]
    return adaptive_space_command.KeptReport(command, pathlib.Path("/"))


class TestSmokeBattery(FigureTest):
    def setUp(self):
        self.output = pathlib.Path(tempfile.mkdtemp()) / "adaptive"
        self.addCleanup(shutil.rmtree, self.output.parent)

    def _AssertRefused(self, arguments: list[str], message: str) -> None:
        """The command refuses ``arguments`` in one line with exit code 2, before it makes its
        folder."""
        stderr = io.StringIO()
        with contextlib.redirect_stderr(stderr), self.assertRaises(SystemExit) as exit:
            adaptive_space_command.main([*arguments, "--report-only", "--output", str(self.output)])
        self.assertEqual(exit.exception.code, 2)
        self.assertIn(f"error: {message}", stderr.getvalue())
        self.assertFalse(self.output.exists())

    def test_the_exploration_part_refuses_develop(self):
        """Its agent favours no states: ``develop`` would do nothing."""
        self._AssertRefused(
            ["--rules", "prune", "develop"], "--rules develop: the exploration part's agent"
        )

    def test_a_join_within_below_the_actions_ends_is_refused(self):
        self._AssertRefused(["--join-within", "0.4"], "maintenance: join_within must be >= 0.5")

    def test_a_doc_table_without_a_doc_is_refused(self):
        self._AssertRefused(["--doc-table", "other"], "--doc-table: no --doc to write it in")

    def test_the_smoke_battery(self):
        """2 seeds x 30 actions on the rank-4 lattice and on a roadmap of 12 states, on both
        arms, fixed and maintained every 5 actions (a state pruned after one try into it), no
        round at the end: every run reports; on the lattice only the maintained ones change
        their space, and its size in the report is what the runs ended with; no penetration."""
        arguments = ["--seeds", "2", "--actions", "30", "--tests", "3", "--every", "5",
                     "--prune-after", "1", "--spaces", "rank4", "trm", "--trm-spacing", "0.6",
                     "--trm-states", "12", "--robots", "icub", "katana", "--output",
                     str(self.output)]  # fmt: skip
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            adaptive_space_command.main([*arguments, "--workers", "2"])
        runs = [
            adaptive_space.AdaptiveSpaceRun(**json.loads(path.read_text()))
            for path in self.output.glob("runs/*_seed*/result.json")
        ]
        self.assertEqual(len(runs), 16)
        katana, runs = (
            [r for r in runs if r.robot == "katana"],
            [r for r in runs if r.robot == "icub"],
        )
        for run in katana:  # (among its scenario's obstacles)
            with self.subTest(robot="katana", space=run.space, condition=run.condition):
                self.assertTrue(30 <= run.actions <= 35)
                self.assertEqual(run.penetrating_steps, 0)
                self.assertTrue(0 < run.coverage < 1)
        roadmap = json.loads((self.output / "runs" / "icub_roadmap" / "result.json").read_text())
        self.assertEqual(roadmap["vertices"], 12)
        unchanged = [r for r in runs if r.space == "trm" and not sum(r.changes.values())]
        self.assertTrue(unchanged and all(r.states == 12 for r in unchanged))
        everything, runs = runs, [r for r in runs if r.space == "rank4"]
        for run in runs:
            with self.subTest(condition=run.condition, seed=run.seed):
                self.assertTrue(30 <= run.actions <= 35)  # (it stops at a chunk's end)
                self.assertGreater(run.tests, 0)
                self.assertEqual(run.penetrating_steps, 0)
                self.assertTrue(0 < run.coverage < 1)
                maintained = run.condition == "maintained"
                self.assertEqual(sum(run.changes.values()) > 0, maintained)
                self.assertEqual(run.states != 256, maintained)
                if maintained:  # (rounds at 5, 10, ... 25, none at the run's end: 30)
                    folder = self.output / "runs" / f"icub_rank4_maintained_seed{run.seed}"
                    changes = adaptive_space_command.SpaceChanges(folder / "model", "right_arm")
                    self.assertLessEqual({c["actions_done"] for c in changes}, {5, 10, 15, 20, 25})
        report = (self.output / "report.md").read_text()
        self.assertEqual(_KeptReport(report), report.split("\n\nFigures (")[0])
        # How near the lattice's states lie to the arm's valid configurations.
        valid = ValidConfigurations(Arms()["icub"])
        lattice = Lattice(adaptive_space.LATTICES["rank4"], 4).centres
        roadmap = RoadmapSpace(Arms()["icub"], self.output / "runs" / "icub_roadmap" / "roadmap")
        near = [np.mean(adaptive_space.Nearest(c, valid)) for c in (lattice, roadmap.centres)]
        self.assertIn(
            "configurations (the mean distance from them to the nearest state, fractions of "
            f"range): icub, rank4 {near[0]:.3f}, trm {near[1]:.3f};",
            report,
        )
        maintained = [r for r in runs if r.condition == "maintained"]
        states = np.mean([r.states for r in maintained])
        self.assertRegex(
            report, rf"\| icub \| rank4 \| maintained \| 2 \| 3\d \| .* \| {states:.0f} \|"
        )
        self.assertIn(
            "icub rank4, maintained minus fixed, prediction error (percentage points)", report
        )
        # The roadmap against the lattice, both fixed: the mean of the paired differences.
        fixed = {(r.space, r.seed): r.coverage for r in everything if r.condition == "fixed"}
        difference = 100 * np.mean([fixed["trm", k] - fixed["rank4", k] for k in (0, 1)])
        self.assertIn(
            "icub, trm minus rank4 (both fixed), coverage (percentage points): "
            f"{difference:+.2f} [",
            report,
        )
        self.assertIn("icub rank4, maintained minus fixed, robot s per action", report)
        self.assertIn("The trm spaces: icub, 12 states and", report)
        # The figures of the first seed's maintained runs: each state of the final space is kept
        # or added, and one is removed per prune.
        histories = adaptive_space_command.SpaceHistories(everything, self.output)["icub"]
        self.assertEqual([h.title for h in histories], ["icub, rank4", "icub, trm"])
        rank4 = [r for r in runs if r.condition == "maintained" and r.seed == 0][0]
        self.assertEqual(len(histories[0].removed), rank4.changes["prune"])
        self.assertEqual(len(histories[0].kept) + len(histories[0].added), rank4.states)
        self.assertReadable(Figure(histories), "adaptive space")
        for name in ("adaptive_space.png", "adaptive_space_icub.html"):
            self.assertTrue((self.output / name).is_file(), name)
        self.assertIn("Figures (the first seed's maintained runs)", report)
        # --doc-table: the report into another block of a doc, the part's own left alone.
        doc = self.output.parent / "doc.md"
        doc.write_text("".join(f"<!-- generated: {name}, by x -->\n<!-- end generated: {name} -->\n"
                               for name in ("adaptive-space", "other")))  # fmt: skip
        with contextlib.redirect_stdout(io.StringIO()):
            adaptive_space_command.main(
                [*arguments, "--report-only", "--doc", str(doc), "--doc-table", "other"]
            )
        blocks = {name: text for name, _, text in GeneratedBlocks(doc)}
        self.assertEqual(blocks["adaptive-space"], "")
        self.assertIn("--doc-table other`.", blocks["other"])
        self.assertEqual(blocks["other"], (self.output / "report.md").read_text())


class TestTheReachLearnersSpace(unittest.TestCase):
    def setUp(self):
        self.output = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, self.output)

    @staticmethod
    def _Reaching(output: pathlib.Path, seeds: int, tries: int, *arguments: str) -> None:
        """The reaching part, greedy, with the MDP learned with the reaches and ``develop`` (a
        target recorded enough) a round at half the run, quietly."""
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            adaptive_space_command.main(
                ["--part", "reaching", "--mdp", "simultaneous", "--strategies", "greedy",
                 "--seeds", str(seeds), "--problem-tries", str(tries), "--stages", str(tries),
                 "--evaluations", "1", "--every", str(tries // 2), "--rules", "develop",
                 "--develop-min-targets", "1", "--output", str(output), *arguments]
            )  # fmt: skip

    def test_the_reaching_smoke_battery(self):
        """The reaching part on both arms: greedy, 2 seeds x 8 problem-tries, fixed and
        developed every 4: every run reports at its last stage; only the maintained ones grow,
        by develop."""
        from mobee_drake.experiments.adaptive_space_reaching import AdaptiveReachRun

        output = self.output / "reaching"
        arms = ["--robots", "icub", "katana", "--reach-spaces", "rank3"]
        self._Reaching(output, 2, 8, *arms, "--workers", "2")
        runs = [
            AdaptiveReachRun(**json.loads(path.read_text()))
            for path in output.glob("runs/reach_*/result.json")
        ]
        self.assertEqual(sorted(r.robot for r in runs), ["icub"] * 4 + ["katana"] * 4)
        for run in runs:
            with self.subTest(condition=run.condition, seed=run.seed):
                self.assertEqual(run.stage, 8)
                self.assertTrue(0 < run.exploring_hours < run.robot_hours)
                self.assertEqual(run.states > 81, run.condition == "maintained")
                self.assertEqual(sum(run.changes.values()) > 0, run.condition == "maintained")
                self.assertGreaterEqual(run.deepest_penetration, 0.0)  # (the safety monitor's)
        # (some arm's own solids came within their fields: the closest approach was kept)
        self.assertTrue(any(r.closest_to_itself is not None for r in runs))
        report = (output / "report.md").read_text()
        from mobee_drake.experiments.adaptive_space_reaching import _ClosestCell as ClosestCell

        for robot in ("icub", "katana"):
            self.assertIn(f"| {robot} | rank3 | greedy | maintained | 2 | 8 |", report)
            for condition in ("fixed", "maintained"):
                rs = [r for r in runs if (r.robot, r.condition) == (robot, condition)]
                start = f"| {robot} | rank3 | greedy | {condition} |"
                (row,) = [line for line in report.splitlines() if line.startswith(start)]
                self.assertIn(f"| {ClosestCell(rs)} |", row)
            self.assertIn(f"{robot} rank3 greedy, maintained minus fixed, summed reward:", report)
            self.assertRegex(
                report,
                rf"{robot}: targets of radius .* rank3, a median \d+\.\d cm \(at most "
                r"\d+\.\d cm\), and on the spaces the maintained runs ended with, the median of "
                r"the runs' medians greedy \d+\.\d cm \(2 runs\) \(at most \d+\.\d cm\)\.",
            )
            # (the spaces the maintained runs ended with, each grown beyond the lattice)
            (ended,) = adaptive_space_command.EndedSpaces(runs, output, robot, "rank3").values()
            maintained = sorted(
                (r for r in runs if (r.robot, r.condition) == (robot, "maintained")),
                key=lambda r: r.seed,
            )
            self.assertEqual([len(c) for c in ended], [r.states for r in maintained])
            lattice = Lattice(adaptive_space.LATTICES["rank3"], 4).centres
            valid = ValidConfigurations(Arms()[robot])
            near = np.mean(adaptive_space.Nearest(lattice, valid))
            self.assertRegex(report, rf"valid configurations .*\b{robot}, rank3 {near:.3f}\b")
            gaps = [TargetGaps(Arms()[robot], c) for c in ended]
            median = 100 * np.median([np.median(g) for g in gaps])
            self.assertIn(f"the runs' medians greedy {median:.1f} cm (2 runs)", report)
        # The figures: the first seed's maintained space as it grew, with the arm's targets.
        histories = adaptive_space_command.ReachSpaceHistories(runs, output)
        for robot in ("icub", "katana"):
            (history,) = histories[robot]
            self.assertEqual(history.title, f"{robot}, rank3, greedy, seed 0")
            (first,) = [
                r for r in runs if (r.robot, r.condition, r.seed) == (robot, "maintained", 0)
            ]
            self.assertEqual(len(history.kept) + len(history.added), first.states)
            self.assertEqual(
                len(history.kept), 81 - len(history.removed) + history.added_then_removed
            )
            self.assertEqual(len(history.removed), first.changes["prune"])
            self.assertEqual(len(history.targets), 27)
            self.assertTrue((output / f"adaptive_space_reaching_{robot}.html").is_file())
        # (a seed 0 without a result: the first finished seed is drawn, and named)
        later = [r for r in runs if (r.robot, r.condition, r.seed) != ("icub", "maintained", 0)]
        (history,) = adaptive_space_command.ReachSpaceHistories(later, output)["icub"]
        self.assertEqual(history.title, "icub, rank3, greedy, seed 1")
        self.assertIn("adaptive_space_reaching.png", report)
        self.assertEqual(_KeptReport(report), report.split("\n\nFigures (")[0])
        # The report of the finished runs alone, a third seed's runs not started (and named).
        self._Reaching(output, 3, 8, *arms, "--report-only")
        self.assertFalse(list(output.glob("runs/*seed2")))
        table = (output / "report.md").read_text()
        missing = (
            "\n\nRuns without a result (4: failed, or not finished; the comparisons leave out the "
            "pairs they belong to): icub rank3 greedy fixed seed 2; icub rank3 greedy "
            "maintained seed 2; katana rank3 greedy fixed seed 2; katana rank3 greedy "
            "maintained seed 2."
        )
        self.assertIn(missing, table)
        self.assertEqual(
            table.replace(missing, "").split("Command:")[0], report.split("Command:")[0]
        )
        self._AssertFixedRunsShared(output, report)

    def _AssertFixedRunsShared(self, first: pathlib.Path, report: str) -> None:
        """A battery of another ``join_within`` reads its fixed runs from ``first`` (a smoke
        battery's folder, its ``report``) and makes only its maintained runs; its report says
        where the fixed runs came from and does not compare wall time, and the kept report
        reads the folder under its root. A folder of runs of other arguments, of none of the
        fixed runs, or this battery's own, and the exploration part, are refused before
        anything runs."""
        from mobee_drake.experiments.battery import BatteryRefused

        output, icub = self.output / "join_half", ["--robots", "icub", "--reach-spaces", "rank3"]
        self._Reaching(output, 2, 8, *icub, "--join-within", "0.5", "--fixed-from", str(first))
        self.assertEqual(
            sorted(p.name for p in output.glob("runs/reach_*")),
            ["reach_greedy_maintained_seed0", "reach_greedy_maintained_seed1"],
        )
        job = json.loads((output / "runs/reach_greedy_maintained_seed0/job.json").read_text())
        self.assertEqual(job["maintenance"]["MaintenanceConfig"]["join_within"], 0.5)
        shared = (output / "report.md").read_text()
        (fixed,) = [
            line for line in report.splitlines() if "| icub | rank3 | greedy | fixed |" in line
        ]
        self.assertIn(fixed, shared)
        self.assertIn("icub rank3 greedy, maintained minus fixed, summed reward:", shared)
        self.assertIn(f"The fixed runs are read from {first}, not made again", shared)
        for text in (report, shared):  # (wall time in the table, not compared)
            self.assertNotIn("wall s per run", text.split("paired by seed")[-1])
            self.assertIn("Wall time is in the table but not compared", text)
        # (the kept report: the paths under its root)
        command = shared.split("Command: `")[1].split("`")[0].replace(f"{self.output}/", "")
        kept = adaptive_space_command.KeptReport(command, self.output)
        relative = shared.split("\n\nFigures (")[0].replace(f"{self.output}/", "")
        self.assertEqual(kept, relative)
        other = self.output / "other"
        with self.assertRaisesRegex(BatteryRefused, r"reach_greedy_fixed_seed0: evaluations"):
            self._Reaching(other, 2, 8, *icub, "--evaluations", "2", "--fixed-from", str(first))
        with self.assertRaisesRegex(BatteryRefused, "none of the 2 fixed runs is finished there"):
            self._Reaching(other, 2, 8, *icub, "--fixed-from", str(output))
        self.assertFalse(other.exists())
        for arguments, message in (
            (["--part", "reaching", "--fixed-from", str(other)], "no battery's runs in"),
            (["--fixed-from", str(first)], "only with --part reaching"),
            (
                ["--part", "reaching", "--fixed-from", str(first), "--output", str(first)],
                "is this battery's own folder",
            ),
        ):
            stderr = io.StringIO()
            with contextlib.redirect_stderr(stderr), self.assertRaises(SystemExit) as exit:
                adaptive_space_command.main(arguments)
            self.assertEqual(exit.exception.code, 2)
            self.assertIn("error: --fixed-from: ", stderr.getvalue())
            self.assertIn(message, stderr.getvalue())

    def test_the_reach_learner_on_a_roadmap(self):
        """The reaching part on the iCub's roadmap space (spacing 1.0: a few states), greedy, one
        seed: the roadmap is built before the runs; a fixed run keeps its states, a developed one
        grows; the report gives the space's rows and how near its states come to the targets."""
        from mobee_drake.experiments.adaptive_space_reaching import AdaptiveReachRun

        output = self.output / "reaching"
        self._Reaching(
            output, 1, 6, "--reach-spaces", "trm", "--reach-trm-spacing", "1.0", "--workers", "2"
        )
        roadmap = json.loads((output / "runs/icub_roadmap/result.json").read_text())
        runs = [
            AdaptiveReachRun(**json.loads(path.read_text()))
            for path in output.glob("runs/reach_trm_*/result.json")
        ]
        self.assertEqual(len(runs), 2)
        for run in runs:
            with self.subTest(condition=run.condition, seed=run.seed):
                self.assertEqual(run.space, "trm")
                maintained = run.condition == "maintained"
                self.assertEqual(run.states > roadmap["vertices"], maintained)
                self.assertEqual(run.states == roadmap["vertices"], not maintained)
        report = (output / "report.md").read_text()
        self.assertIn("| icub | trm | greedy | fixed | 1 | 6 |", report)
        self.assertIn(f"The trm spaces: icub, {roadmap['vertices']} states and", report)
        self.assertRegex(report, r"icub: targets of .* trm, a median \d+\.\d cm")
        self.assertNotIn("rank3:", report)

    def test_an_mdp_learned_on_a_roadmap_has_its_space(self):
        """A roadmap of spacing 1.5 (a few states) and the MDP learned on it until every
        state-action was tried once: the model's states are the roadmap's vertices, its
        transitions the roadmap's edges both ways."""
        from mobee_drake.experiments.arms import RoadmapJob
        from mobee_drake.experiments.battery import RunFolder
        from mobee_drake.experiments.ch8_reaching import AGENT, MdpJob, MdpName
        from mobee_drake.planning.explorers import ExplorerConfig, LoadAgentModel

        for name in ("icub_roadmap", "mdp"):
            (self.output / name).mkdir()
        built = RoadmapJob(
            RunFolder(self.output / "icub_roadmap"), robot="icub", spacing=1.5, max_vertices=81
        )
        learned = MdpJob(RunFolder(self.output / "mdp"), 1, space="trm")
        self.assertEqual(learned["min_tries"], 1)
        model = LoadAgentModel(str(self.output / "mdp" / "model"), AGENT, ExplorerConfig())
        space = RoadmapSpace(Arms()["icub"], self.output / "icub_roadmap" / "roadmap")
        self.assertEqual(len(space.centres), built["vertices"])
        np.testing.assert_array_equal(model.space.centres, space.centres)
        self.assertEqual(len(model.space.action_goal), 2 * built["edges"])
        self.assertEqual(MdpName(5, robot="katana", space="trm"), "katana_mdp_tries5_trm")

    def test_the_report_compares_the_roadmap_with_the_lattice(self):
        """Constructed runs: trm's fixed runs reach 1.5 more than the lattice's, seed by seed
        (0.5 apart from seed to seed), and take 0.25 robot hours less exploring (their
        evaluations 0.3 h more than the lattice's, so 0.05 h more in all); trm's maintained
        runs reach 2.5 more than the fixed lattice's (1.0 more than fixed trm's). What was
        learned and what it cost are two families."""
        from mobee_drake.experiments.adaptive_space_reaching import AdaptiveReachRun, Report

        evaluating = {"rank3": 0.5, "trm": 0.8}  # (robot hours)

        def Run(space, seed, reward, hours, condition="fixed"):
            return AdaptiveReachRun(
                strategy="greedy", condition=condition, seed=seed, stage=8, reward=reward,
                reward_without_penalties=reward, robot_hours=hours + evaluating[space], states=81,
                transitions=351, changes={}, penetrating_steps=0, wall_seconds=1.0, space=space,
                exploring_hours=hours,
            )  # fmt: skip

        runs = [Run("rank3", k, 20.0 + 0.5 * k, 2.0 + 0.1 * k) for k in range(4)]
        runs += [Run("trm", k, 21.5 + 0.5 * k + 0.01 * k * k, 1.75 + 0.101 * k) for k in range(4)]
        report = Report(runs, "test")
        (reward,) = [line for line in report.splitlines() if "trm minus rank3" in line
                     and "summed reward:" in line]  # fmt: skip
        (hours,) = [line for line in report.splitlines() if "trm minus rank3" in line
                    and "robot hours" in line]  # fmt: skip
        self.assertIn("icub greedy, trm minus rank3 (both fixed), summed reward: +1.5", reward)
        self.assertIn("robot hours exploring: -0.25", hours)
        # (the sum without the -10s the same as with them in every run: not tested again; wall
        # time not compared)
        self.assertIn("what was learned, paired by seed (Holm over the 1)", report)
        self.assertIn(
            "not tested again: icub greedy, trm minus rank3 (both fixed), without the -10s (as "
            "summed reward)",
            report,
        )
        self.assertIn("what it cost, paired by seed (Holm over the 1)", report)
        self.assertNotIn("wall s per run", report.split("paired by seed")[-1])
        self.assertNotIn("trm maintained minus", report)
        self.assertNotIn("The MDPs learned first", report)
        mdps = {"icub rank3": dict(min_tries=5, actions=2160), "icub trm": dict(actions=1900)}
        self.assertIn(
            "The MDPs learned first (5 tries of every state-action): icub rank3, 2160 actions; "
            "icub trm, 1900 actions.",
            Report(runs, "test", mdps=mdps),
        )
        runs += [Run("trm", k, 22.5 + 0.5 * k + 0.02 * k * k, 1.75, "maintained") for k in range(4)]
        report = Report(runs, "test")
        (reward,) = [line for line in report.splitlines() if "summed reward:" in line
                     and "trm maintained minus rank3 fixed" in line]  # fmt: skip
        gain = np.mean([2.5 + 0.02 * k * k for k in range(4)])
        self.assertIn(
            f"icub greedy, trm maintained minus rank3 fixed, summed reward: {gain:+.2f}", reward
        )
        # (three comparisons of the summed reward; without the -10s it is the same in every run)
        self.assertIn("what was learned, paired by seed (Holm over the 3)", report)
        self.assertIn("what it cost, paired by seed (Holm over the 3)", report)

    def test_a_stage_is_evaluated_before_its_round(self):
        """A round due every 4 problem-tries, stages at 4 and 8 (the last): each stage's
        evaluation sees the space the learner explored, so the round at 4 follows its
        evaluation, and there is none at 8."""
        from unittest import mock

        from mobee_drake.experiments.ch8_reaching import RunOne, RunSettings
        from mobee_drake.planning.space_maintenance import MaintenanceConfig
        from mobee_drake.reaching import reshaping
        from mobee_drake.reaching.learner import ReachLearner

        calls, maintain = [], reshaping.MaintainReachSpace

        def Evaluating(learner, robot, seed, targets=None):
            calls.append(("evaluation", int(learner.problem_tries.sum())))
            return []  # (what is evaluated does not matter here: when)

        def Maintaining(learner, maintenance, state, done):
            calls.append(("round", done))
            return maintain(learner, maintenance, state, done)

        settings = RunSettings(
            strategy="greedy", seed=0, problem_tries=8, stages=[4, 8], evaluations=1,
            checkpoint_every=3, mdp="simultaneous",
        )  # fmt: skip
        maintenance = MaintenanceConfig(every=4, rules=["develop"], develop_min_targets=1)
        with (
            mock.patch.object(ReachLearner, "Evaluate", Evaluating),
            mock.patch.object(reshaping, "MaintainReachSpace", Maintaining),
        ):
            RunOne(self.output / "run", self.output, settings, maintenance=maintenance)
        self.assertEqual(calls, [("evaluation", 4), ("round", 4), ("evaluation", 8)])

    def test_a_reshaping_run_resumes_exactly(self):
        """A random run whose space is maintained every 2 problem-tries by all five rules (set
        to act on a try or a record), killed after 7 tries (checkpoint at 6, after the rounds at
        2 and 4 dropped logged state-actions, before the round due at 6, which the resumed run
        makes) and run again, ends as the run never killed: the same log, space and robot
        time."""
        from unittest import mock

        from mobee_drake.experiments.ch8_reaching import RunOne, RunSettings
        from mobee_drake.planning.space_maintenance import RULES, MaintenanceConfig
        from mobee_drake.reaching.learner import ReachLearner

        settings = RunSettings(
            strategy="random", seed=0, problem_tries=10, stages=[], evaluations=1,
            checkpoint_every=3, mdp="simultaneous",
        )  # fmt: skip
        maintenance = MaintenanceConfig(
            every=2, rules=list(RULES), prune_after=1, drop_after=1, drop_miss_share=0.5,
            shortcut_after=1, develop_min_targets=1,
        )  # fmt: skip
        whole = RunOne(self.output / "whole", self.output, settings, maintenance=maintenance)
        explore, calls = ReachLearner.Explore, []

        def Dying(learner, robot):
            calls.append(1)
            if len(calls) == 8:
                raise KeyboardInterrupt
            return explore(learner, robot)

        checkpoints = []
        with mock.patch.object(ReachLearner, "Explore", Dying):
            with self.assertRaises(KeyboardInterrupt):
                RunOne(
                    self.output / "killed", self.output, settings,
                    progress=checkpoints.append, maintenance=maintenance,
                )  # fmt: skip
        self.assertEqual(checkpoints[-1], 6)
        # (A copy whose checkpoint predates the count of targets appearing inside the robot and
        # the evaluations' timing.)
        shutil.copytree(self.output / "killed", self.output / "older")
        (saved,) = (self.output / "older").glob("checkpoint/g*/learner.json")
        data = json.loads(saved.read_text()) | dict(appearance=None)
        del data["evaluation_seconds"]
        saved.write_text(json.dumps(data))
        resumed = RunOne(self.output / "killed", self.output, settings, maintenance=maintenance)
        self.assertTrue(all(whole["space"]["changes"][rule] > 0 for rule in RULES))
        # The checkpoint's log has entries its rounds dropped (-1): they stay dropped through
        # the rounds after it, in the run resumed from it and in the run never killed.
        dropped = [
            i for i, row in enumerate(np.load(saved.with_suffix(".npz"))["log"]) if row[2] == -1
        ]
        self.assertTrue(dropped)
        for run in (whole, resumed):
            self.assertEqual({run["log"][i][2] for i in dropped}, {-1})
        self.assertEqual(resumed["space"], whole["space"])
        self.assertEqual(resumed["log"], whole["log"])
        self.assertAlmostEqual(resumed["simulated_seconds"], whole["simulated_seconds"])
        self.assertEqual(
            [resumed["appeared_inside"], resumed["other_penetrating_steps"]],
            [whole["appeared_inside"], whole["other_penetrating_steps"]],
        )
        self.assertGreater(whole["appeared_inside"], 0)  # (so the counts' resumption is tested)
        older = RunOne(self.output / "older", self.output, settings, maintenance=maintenance)
        self.assertEqual(older["log"], whole["log"])
        self.assertEqual([older["appeared_inside"], older["other_penetrating_steps"]], [None] * 2)
        self.assertEqual([whole["evaluation_seconds"], resumed["evaluation_seconds"]], [0.0] * 2)
        self.assertIsNone(older["evaluation_seconds"])
