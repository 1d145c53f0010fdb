"""Tests of the watch for targets that appear inside the robot (reaching/appearance.py), on a
stand-in robot whose penetrations the test sets (test_reach_learning runs it on the iCub), and
of the reports' cell of its split."""

import dataclasses as dc
import types
import unittest
from unittest import mock

from mobee_drake.reaching import appearance
from mobee_drake.reaching.appearance import AppearanceCounts, AppearanceWatch
from mobee_drake.reaching.targets import TARGET_NAME


class _Robot:
    """Counts penetrating periods as the test says; a target is inside iff it is "inside", and
    the arm is inside itself while ``wedged``."""

    def __init__(self):
        self.penetrating, self.target, self.wedged = 0, None, False
        self.station, self.context = types.SimpleNamespace(diagram=None), None

    def Safety(self):
        return types.SimpleNamespace(penetrating_steps=self.penetrating)

    def SetProblem(self, target) -> None:
        self.target = target

    def State(self) -> int:
        return 7


def _Pairs(robot: _Robot):
    return lambda diagram, context: (
        [(-0.01, "the robot", "r_hand", TARGET_NAME)] * (robot.target == "inside")
        + [(-0.04, "the robot", "r_forearm", "r_upper_arm")] * robot.wedged
    )


class AppearanceWatchTest(unittest.TestCase):
    def test_penetrations_split_by_where_the_target_appeared(self):
        robot = _Robot()
        with mock.patch.object(appearance, "PenetratingPairs", _Pairs(robot)):
            watched = AppearanceWatch(robot)
            watched.SetProblem("inside")
            robot.penetrating += 3  # (the arm pushed out of the target: the draw's)
            robot.target = None  # (its reach ended the problem: the target is gone)
            watched.SetProblem("outside")
            robot.penetrating += 5
            # A checkpoint's counts resume the watch in a new process.
            watched = AppearanceWatch(robot, AppearanceCounts(**dc.asdict(watched.counts)))
            robot.penetrating += 2
            watched.SetProblem("inside")
            robot.penetrating += 4
            robot.target = None
            watched.SetProblem("outside")
            robot.penetrating += 1
            watched.Close()
            watched.Close()  # (closing twice counts once)
        self.assertEqual(watched.counts.appeared_inside, 2)
        self.assertEqual(watched.counts.other_penetrating_steps, 5 + 2 + 1)
        self.assertEqual(robot.target, "outside")
        # (a target left inside the arm when its problem is closed: not the draw's)
        robot = _Robot()
        with mock.patch.object(appearance, "PenetratingPairs", _Pairs(robot)):
            watched = AppearanceWatch(robot)
            watched.SetProblem("inside")
            robot.penetrating += 6
            watched.Close()
        self.assertEqual(
            [watched.counts.appeared_inside, watched.counts.other_penetrating_steps], [0, 6]
        )
        self.assertEqual(watched.State(), 7)  # (the rest of the robot, unwatched)
        watched.space = "reshaped"  # (a space keeper sets the robot's space through the watch)
        self.assertEqual(robot.space, "reshaped")
        self.assertNotIn("space", vars(watched))

    def test_a_robot_inside_itself_is_not_set_aside_as_the_draws(self):
        """A target that appears while the arm is wedged inside itself is not counted as one
        that appeared inside; nor is one that appeared inside, alone, but whose problem was
        closed with the arm inside itself: both problems' periods count among the others; a
        target alone inside when it appeared, nothing inside when its problem was closed, is
        the draw's."""
        robot = _Robot()
        with mock.patch.object(appearance, "PenetratingPairs", _Pairs(robot)):
            watched = AppearanceWatch(robot)
            watched.SetProblem("inside")
            robot.penetrating += 3  # (pushed out, cleanly: the draw's)
            robot.target = "gone"
            watched.SetProblem("inside")
            robot.penetrating, robot.wedged = robot.penetrating + 20, True  # (into itself)
            watched.SetProblem("inside")  # (appears while the arm is inside itself)
            robot.penetrating += 40
            watched.Close()
        self.assertEqual(watched.counts.appeared_inside, 1)
        self.assertEqual(watched.counts.other_penetrating_steps, 20 + 40)

    def test_a_reports_cell_sums_the_split_or_says_it_is_unknown(self):
        """Two runs' periods summed: all / the other problems' (problems whose target appeared
        inside); a run from before the count makes the split unknown."""
        from mobee_drake.experiments.ch8_measures import PenetrationCell

        def Run(total, other, inside):
            return types.SimpleNamespace(
                penetrating_steps=total, other_penetrating_steps=other, appeared_inside=inside
            )

        self.assertEqual(PenetrationCell([Run(10, 2, 3), Run(5, 0, 1)]), "15 / 2 (4)")
        self.assertEqual(PenetrationCell([Run(10, 2, 3), Run(5, None, None)]), "15 / - (-)")


if __name__ == "__main__":
    unittest.main()
