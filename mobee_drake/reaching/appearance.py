"""Targets that appear inside the robot, and the penetrations that follow them.

Ch. 8's targets are drawn without regard to where the arm rests, so a new problem's target may
appear inside the hand or the forearm; MoBeE then pushes the arm out of it, and the station's
safety monitor counts the periods the two solids overlap as penetrating. Those periods are the
draw's, not a failure of MoBeE's safety: a run's penetrating periods are only a safety measure
once they are split into the problems whose target appeared inside the robot and the rest.
"""

import dataclasses as dc

import numpy as np

from mobee_drake.station.safety import Penetrations


@dc.dataclass
class AppearanceCounts:
    """What an :class:`AppearanceWatch` has seen so far (and where its current problem began)."""

    # Problems whose target appeared inside the robot.
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

    def Close(self) -> None:
        """Ends the current problem's count (call once after the last problem)."""
        c = self.counts
        if c.current_inside is False:
            c.other_penetrating_steps += self._Penetrating() - c.current_start
        c.current_inside = None

    def SetProblem(self, target: np.ndarray) -> None:
        self.Close()
        self.robot.SetProblem(target)
        c = self.counts
        c.current_inside = bool(Penetrations(self.robot.station.diagram, self.robot.context))
        c.current_start = self._Penetrating()
        c.appeared_inside += c.current_inside
