"""Targets that appear inside the robot, and the penetrations that follow them.

Ch. 8's targets are drawn without regard to where the arm rests, so a new problem's target may
appear inside the hand or the forearm; MoBeE then pushes the arm out of it, and the station's
safety monitor counts the periods the two solids overlap as penetrating. Those periods are the
draw's, not a failure of MoBeE's safety: a run's penetrating periods are only a safety measure
once they are split into the problems whose target appeared inside the robot and the rest.

A problem's periods are set aside as the draw's only when its target's pairs alone penetrate
when it appears, and none but its target's when it ends: a robot already inside itself or an
object when a target appears, or left so at the problem's end (a push out of a target that
drove the arm into itself), counts among the rest. (Before, any penetration at the target's
appearance set the whole problem aside: a Katana wedged inside itself for most of a run counted
as targets appearing inside it, docs/adaptive_space.md.)
"""

import dataclasses as dc

import numpy as np

from mobee_drake.reaching.targets import TARGET_NAME
from mobee_drake.station.safety import PenetratingPairs


@dc.dataclass
class AppearanceCounts:
    """What an :class:`AppearanceWatch` has seen so far (and where its current problem began)."""

    # Problems whose target appeared inside the robot, nothing else penetrating.
    appeared_inside: int = 0
    # Penetrating control periods of the other problems (and of those that ended with something
    # but their target penetrating).
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
        if c.current_inside is False or (c.current_inside and self._Pairs()[1]):
            c.other_penetrating_steps += self._Penetrating() - c.current_start
        c.current_inside = None

    def SetProblem(self, target: np.ndarray) -> None:
        self.Close()
        self.robot.SetProblem(target)
        c = self.counts
        target, others = self._Pairs()
        c.current_inside = target and not others
        c.current_start = self._Penetrating()
        c.appeared_inside += c.current_inside
