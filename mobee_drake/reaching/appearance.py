"""Targets that appear inside the robot, and the penetrations that follow them.

Ch. 8's targets are drawn without regard to where the arm rests, so a new problem's target may
appear inside the hand or the forearm; MoBeE then pushes the arm out of it, and the station's
safety monitor counts the periods the two solids overlap as penetrating. Those periods are the
draw's, not a failure of MoBeE's safety: a run's penetrating periods are only a safety measure
once they are split into the problems whose target appeared inside the robot and the rest.

A problem is set aside as one whose target appeared inside the robot only when its target's
pairs alone penetrate when it appears, and nothing does when it is closed (at the next
problem's appearance: its target gone, the next evaluation's walk done): a robot already inside
itself or an object when a target appears, or left so, counts among the rest. A problem that
went inside itself and got out again before it was closed is still set aside; the run's closest
approach of the robot to itself (the safety monitor's) shows that. (Before, any penetration at
a target's appearance set the problem aside: a Katana wedged inside itself for the rest of its
run counted as targets appearing inside it, docs/adaptive_space.md.)
"""

import dataclasses as dc

import numpy as np

from mobee_drake.reaching.targets import TARGET_NAME
from mobee_drake.station.safety import PenetratingPairs


@dc.dataclass
class AppearanceCounts:
    """What an :class:`AppearanceWatch` has seen so far (and where its current problem began)."""

    # Problems set aside: their target alone appeared inside the robot, and nothing penetrated
    # when they were closed.
    appeared_inside: int = 0
    # Penetrating control periods of the other problems.
    other_penetrating_steps: int = 0
    # The open problem: whether its target appeared inside (None: none is open), and the
    # robot's penetrating periods when it appeared (its own are the difference at its end).
    current_inside: bool | None = None
    current_start: int = 0


class AppearanceWatch:
    """A reach learner's robot (``SimulatedRobot``), watched for targets that appear inside it:
    every ``SetProblem`` ends the last problem's count and checks the new target. ``counts``
    resumes a watch (its ``counts`` as saved with a checkpoint, from which the robot's safety
    monitor resumes too)."""

    def __init__(self, robot, counts: AppearanceCounts | None = None):
        self.robot = robot
        self.counts = AppearanceCounts() if counts is None else counts

    def __getattr__(self, name):  # (the rest of the Robot protocol, unwatched)
        return getattr(self.robot, name)

    def __setattr__(self, name, value):  # (the robot's own are set on it: a reshaped space)
        if name in ("robot", "counts"):
            object.__setattr__(self, name, value)
        else:
            setattr(self.robot, name, value)

    def _Penetrating(self) -> int:
        return self.robot.Safety().penetrating_steps

    def _Pairs(self) -> tuple[bool, bool]:
        """Whether a pair with the target penetrates, and whether a pair without it does."""
        pairs = PenetratingPairs(self.robot.station.diagram, self.robot.context)
        targets = [TARGET_NAME in (a, b) for _, _, a, b in pairs]
        return any(targets), not all(targets)

    def Close(self) -> None:
        """Ends the current problem's count (call once after the last problem)."""
        c = self.counts
        if c.current_inside and any(self._Pairs()):  # (left inside something: not the draw's)
            c.current_inside, c.appeared_inside = False, c.appeared_inside - 1
        if c.current_inside is False:
            c.other_penetrating_steps += self._Penetrating() - c.current_start
        c.current_inside = None

    def SetProblem(self, target: np.ndarray) -> None:
        self.Close()
        self.robot.SetProblem(target)
        c = self.counts
        target_inside, others_inside = self._Pairs()
        c.current_inside = target_inside and not others_inside
        c.current_start = self._Penetrating()
        c.appeared_inside += c.current_inside
