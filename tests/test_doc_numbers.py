"""The numbers the tutorial and docs/simulation.md quote from the main job are what a fresh run
gives: each is read from the text and compared with the run at the text's own precision."""

import pathlib
import re
import tempfile
import unittest

import numpy as np
import pandas as pd

from mobee_drake.scenario import LoadScenario, RunScenario

DOCS = pathlib.Path(__file__).parents[1] / "docs"


def _Text(name: str) -> str:
    """A doc with its line breaks and indentation folded into single spaces."""
    return " ".join((DOCS / name).read_text().split())


def _Quoted(text: str, pattern: str) -> tuple[str, ...]:
    found = re.search(pattern, text)
    if found is None:
        raise AssertionError(f"the docs no longer say: {pattern}")
    return found.groups()


class TestQuotedNumbers(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        folder = pathlib.Path(tempfile.mkdtemp())
        log = folder / "main.parquet"
        cls.main = RunScenario(LoadScenario("reach_around_ball"), data_log=str(log))
        cls.log = pd.read_parquet(log)
        cls.free = RunScenario(
            LoadScenario("reach_around_ball", ["{objects: []}", "{duration: 12}"])
        )

    def Palm(self, summary) -> float:
        return summary.outcome["attractor"]["marker_distance_to_goal_m"]["r_palm"]

    def test_the_tutorial(self):
        text = _Text("tutorial.md")
        ball = self.main.safety.closest_approach["ball"]
        printed, cm = _Quoted(text, r'\("ball ([+-][0-9.]+)": the hand came within ([0-9.]+) cm')
        self.assertEqual(printed, f"{ball:+.4f}")
        self.assertEqual(cm, f"{100 * ball:.1f}")
        (short,) = _Quoted(text, r"the palm stays (\d+) cm short")
        self.assertEqual(int(short), round(100 * self.Palm(self.main)))
        _Quoted(text, r"it arrives, to within rounding \(about 1e-16 m\)")
        self.assertLess(self.Palm(self.free), 1e-15)
        (closest,) = _Quoted(text, r"the summary's ([0-9.]+) cm is the closest")
        self.assertEqual(closest, f"{100 * ball:.1f}")
        t, f_coll = self.log["time"].to_numpy(), self.log["force.f_coll"].to_numpy()
        spring = self.log["force.spring"].to_numpy()
        enters, peak = _Quoted(text, r"enters the ball's field at ([0-9.]+) s, peaks at (\d+)")
        self.assertEqual(enters, f"{t[np.argmax(f_coll > 0)]:.2f}")
        self.assertEqual(int(peak), round(f_coll.max()))
        (start,) = _Quoted(text, r"the spring's pull falls from (\d+)")
        self.assertEqual(int(start), round(spring.max()))
        pull, push = _Quoted(text, r"\(([0-9.]+) against ([0-9.]+) at 15 s\)")
        self.assertEqual((pull, push), (f"{spring[-1]:.2f}", f"{f_coll[-1]:.2f}"))

    def test_the_simulation_doc(self):
        text = _Text("simulation.md")
        rows, columns = _Quoted(text, r"`reach_around_ball` \((\d+) rows, (\d+) columns\)")
        self.assertEqual((int(rows), int(columns)), self.log.shape)
        palm, closest = _Quoted(
            text, r"right palm ([0-9.]+) cm from its goal \(the ball is in the way, closest "
            r"approach ([0-9.]+) cm\)",
        )  # fmt: skip
        self.assertEqual(palm, f"{100 * self.Palm(self.main):.1f}")
        self.assertEqual(closest, f"{100 * self.main.safety.closest_approach['ball']:.1f}")
        _Quoted(text, r"--duration 12` at it, to within rounding \(about 1e-16 m\)")
        self.assertLess(self.Palm(self.free), 1e-15)


if __name__ == "__main__":
    unittest.main()
