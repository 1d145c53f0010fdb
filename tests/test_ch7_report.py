"""The ch. 7 reports against numbers computed from constructed runs (issue 32: a report's
numbers are its runs' own)."""

import pathlib
import tempfile
import unittest

import numpy as np

from mobee_drake.experiments.ch7_model_learning import MovingBoxResult, PlanningRun
from mobee_drake.experiments.ch7_report import REPORTS
from mobee_drake.experiments.exploration import ExplorationRun
from mobee_drake.planning.state_space import Lattice


def _Run(**fields) -> ExplorationRun:
    defaults = dict(
        agents=["right_arm"], tries=[], values=[], misses=[], goals=[], actions=[0],
        snapshots={}, coverage=[], simulated_seconds=0.0, wall_seconds=0.0, penetrating_steps=0,
    )  # fmt: skip
    return ExplorationRun(**(defaults | fields))


def _Cells(line: str) -> list[str]:
    return [cell.strip() for cell in line.strip().strip("|").split("|")]


class TestCh7Reports(unittest.TestCase):
    def setUp(self):
        self.output = pathlib.Path(tempfile.mkdtemp())

    def test_hypercube_row_is_its_runs_tries_values_and_time(self):
        # Two runs at gamma 0.9: tries (4, 6) and (5, 9) per state-action, values 0.1-0.4.
        runs = [
            _Run(
                labels=dict(gamma=0.9, run=k),
                snapshots={320: dict(tries=tries, values=values)},
                wall_seconds=wall,
            )
            for k, (tries, values, wall) in enumerate(
                [([4, 6], [0.1, 0.2], 10.0), ([5, 9], [0.3, 0.4], 20.0)]
            )
        ]
        lines = REPORTS["7.1"](self.output, runs)
        # Mean tries 6, spread: the mean of std(4, 6) = 1 and std(5, 9) = 2, mean value 0.25,
        # times 1 - gamma: 0.025.
        self.assertEqual(
            _Cells(lines[2]), ["0.9", "2", "6.00", "1.50", "0.2500", "0.02500", "15.0"]
        )
        self.assertTrue((self.output / "7.1_hypercube.png").is_file())

    def test_coverage_counts_censored_runs_and_marks_the_ratio(self):
        from mobee_drake.experiments.ch7_figures import COVERAGE_STATE_ACTIONS as ALL

        def Run(strategy: str, run: int, covered_at: int | None, cap: int = 4000):
            end = covered_at or cap
            coverage = [[n, min(ALL, ALL * n // end) if covered_at else ALL - 5] for n in
                        range(500, end + 1, 500)]  # fmt: skip
            return _Run(labels=dict(strategy=strategy, run=run, cap=cap), coverage=coverage)

        runs = [Run("curious", k, n) for k, n in enumerate((1000, 1500, 1000))]
        runs += [Run("least_tried", k, n) for k, n in enumerate((2500, 2500, 2000))]
        lines = REPORTS["7.2"](self.output, runs)
        self.assertEqual(_Cells(lines[2]), ["curious", "0", "1000", str(ALL), "1000"])
        # Means 1166.7 and 2333.3: a ratio of 0.50, every run finished.
        self.assertRegex(lines[-1], r"least-tried.*: 0\.50 \[.*\(3 and 3 runs\).*\*\*reproduced")
        runs[-1] = Run("least_tried", 2, None)  # stopped by the cap at 4000
        lines = REPORTS["7.2"](self.output, runs)
        self.assertIn("| least_tried | 2 | 4000 | " + str(ALL - 5) + " | > 4000 |", lines[7])
        self.assertIn("an upper bound: 1 run(s) stopped by the cap", lines[-1])
        self.assertIn("**not reproduced**", lines[-1])

    def test_controls_compare_the_arms_correlation_with_and_without_the_table(self):
        rng = np.random.default_rng(0)
        shared = rng.poisson(5, 300)

        def Arms(noise: float) -> list:
            return [(shared + rng.poisson(noise, 300)).tolist() for _ in range(2)]

        runs = [
            _Run(labels={}, tries=Arms(0.5)),  # 7.4: the arms alike
            _Run(labels=dict(control="no_table"), tries=Arms(20.0)),  # unlike without it
            _Run(labels=dict(control="right_alone"), tries=Arms(0.5)[:1]),
            _Run(labels=dict(control="left_alone"), tries=Arms(0.5)[:1]),
        ]
        lines = REPORTS["7.4c"](self.output, runs)
        table, no_table = (np.corrcoef(r.tries[0], r.tries[1])[0, 1] for r in runs[:2])
        self.assertEqual(_Cells(lines[2])[2], f"{table:.3f}")
        self.assertEqual(_Cells(lines[3])[2], f"{no_table:.3f}")
        self.assertIn("the table makes the arms more alike", lines[-1])
        runs[1] = _Run(labels=dict(control="no_table"), tries=Arms(0.5))
        self.assertIn("the table adds no similarity", REPORTS["7.4c"](self.output, runs)[-1])

    def test_initialization_lists_the_state_actions_that_miss_their_goal(self):
        tries = np.full(8, 4)
        misses = np.zeros(8)
        misses[3] = 0.5  # 2 of 4 tries missed
        misses[5] = 0.05  # under 10 %: reliable
        runs = [
            _Run(
                labels=dict(initialization=initialization, gamma=0.5, run=0),
                tries=[tries.tolist()],
                values=[np.zeros(8).tolist()],
                misses=[misses.tolist()],
                actions=[32],
            )
            for initialization in ("50-50", "60-40")
        ]
        lines = REPORTS["7.2i"](self.output, runs)
        space = Lattice([0.25, 0.5, 0.75], 4)
        expected = f"{space.action_state[3]}->{space.action_goal[3]}: 2/4"
        self.assertEqual(_Cells(lines[2]), ["50-50", "0.5", "0", "32", expected])
        self.assertEqual(_Cells(lines[3]), ["60-40", "0.5", "0", "32", expected])

    def test_moving_box_counts_risky_plans_and_failed_transitions(self):
        # State-action 0 (0 -> 1) is risky; one plan crosses it, the other does not.
        planners = dict(
            moving_box=PlanningRun(
                reliability=[0.5, 1.0],
                plans=[[0, 1, 2], [0, 3, 2]],
                episodes=[
                    dict(start=0, goal=2, actions=2, failed=1, tried=[0]),
                    dict(start=0, goal=2, actions=4, failed=0, tried=[1]),
                ],
                penetrating_steps=3,
            ),
            no_box=PlanningRun(reliability=[1.0, 1.0], plans=[[0, 1, 2], [0, 1, 2]]),
        )
        result = MovingBoxResult(
            unreliable=[0], problems=[(0, 2)], action_state=[0, 1], action_goal=[1, 2],
            planners=planners,
        )  # fmt: skip
        lines = REPORTS["7.4.1"](self.output, result)
        rows = {_Cells(line)[0]: _Cells(line) for line in lines if line.startswith("| ")}
        self.assertEqual(rows["moving_box"][1:], ["1 of 2", "2", "3.00", "0.50", "50%", "3"])
        self.assertEqual(rows["no_box"][1:], ["2 of 2", "0", "0.00", "0.00", "0%", "0"])

    def test_a_result_of_an_earlier_version_reads_its_labels(self):
        # Before ExplorationRun, a job's labels (gamma, run) sat beside its data.
        data = _Run(labels={}).ToJson()
        del data["labels"]
        data |= dict(gamma=0.5, run=2, snapshots={"320": dict(tries=[1], values=[0.0])})
        run = ExplorationRun.FromJson(data)
        self.assertEqual(run.labels, dict(gamma=0.5, run=2))
        self.assertEqual(list(run.snapshots), [320])


if __name__ == "__main__":
    unittest.main()
