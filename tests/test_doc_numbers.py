"""The numbers the README, the tutorial and docs/simulation.md quote from the main job are what
a fresh run gives: each is read from the text and compared with the run at the text's own
precision."""

import pathlib
import re
import tempfile
import unittest

import numpy as np
import pandas as pd

from mobee_drake.scenario import LoadScenario, RunScenario

ROOT = pathlib.Path(__file__).parents[1]
DOCS = ROOT / "docs"


def _Text(name: str) -> str:
    """A doc (under docs/, or the README) with its line breaks and indentation folded into
    single spaces."""
    return " ".join((ROOT / name if name == "README.md" else DOCS / name).read_text().split())


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

    def test_the_readme(self):
        text = _Text("README.md")
        ball = self.main.safety.closest_approach["ball"]
        printed, cm, short = _Quoted(
            text, r"\(`ball ([+-][0-9.]+)`: ([0-9.]+) cm\) and the palm (\d+) cm short of its goal"
        )
        self.assertEqual(printed, f"{ball:+.4f}")
        self.assertEqual(cm, f"{100 * ball:.1f}")
        self.assertEqual(int(short), round(100 * self.Palm(self.main)))
        _Quoted(text, r"`penetrations of solid geometry: 0 control periods`")
        self.assertEqual(self.main.safety.penetrating_steps, 0)
        (title,) = _Quoted(text, r"the ball holds the palm (\d+) cm short of its goal")
        self.assertEqual(int(title), round(100 * self.Palm(self.main)))
        # The palm's goal, as the README's plot and the scenario's comment give it.
        goal = np.array(_Quoted(text, r"goal = np.array\(\[([-0-9.]+), ([-0-9.]+), ([-0-9.]+)\]\)"))
        comment = (ROOT / "diagrams" / "reach_around_ball.yaml").read_text()
        stated = _Quoted(comment, r"this attractor at \(([-0-9.]+), ([-0-9.]+), ([-0-9.]+)\)")
        palm = self.log[["marker.r_palm.x", "marker.r_palm.y", "marker.r_palm.z"]].to_numpy()
        end = np.linalg.norm(palm[-1] - goal.astype(float))
        self.assertAlmostEqual(end, self.Palm(self.main), delta=1e-3)  # rounded to 1 mm
        self.assertEqual(stated, tuple(goal))

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
