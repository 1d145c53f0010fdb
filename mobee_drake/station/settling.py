"""When an action on the robot ends: the one settling test of every agent (ch. 6.1, ch. 8.2).

An action ends when the robot has settled (the watched joints slower than ``settle_speed`` for
``settle_time``, and at least ``min_duration`` after the start) or after ``timeout``. The curious
explorer watches its own joints, the state-action executor all of MoBeE's joints; both poll the
same two functions below with their joints' velocities.
"""

import dataclasses as dc

import numpy as np


@dc.dataclass
class ActionTiming:
    """When an action ends (ch. 6.1; the original MoBeE learner's values, in radians)."""

    settle_speed: float = np.radians(2.0)  # rad/s, every watched joint
    settle_time: float = 0.5  # s the robot must stay that slow
    min_duration: float = 0.5  # s before an action may end
    timeout: float = 20.0  # s

    def Validate(self) -> None:
        """Raises ValueError naming the first value out of range."""
        for name, value, low in (
            ("settle_speed", self.settle_speed, 0.0),
            ("timeout", self.timeout, 0.0),
        ):
            if not (np.isfinite(value) and value > low):
                raise ValueError(f"timing: {name} must be finite and > 0, got {value}")
        for name, value in (("settle_time", self.settle_time), ("min_duration", self.min_duration)):
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f"timing: {name} must be finite and >= 0, got {value}")

    def SlowSince(self, slow_since: float, now: float, v: np.ndarray) -> float:
        """Since when the joints with velocities ``v`` have been slow, given ``slow_since`` at
        the previous poll (inf: not slow now)."""
        slow = np.max(np.abs(v), initial=0.0) < self.settle_speed
        return min(slow_since, now) if slow else np.inf

    def Ended(self, now: float, started: float, slow_since: float) -> bool:
        """Whether an action started at ``started`` has ended: settled, or timed out."""
        elapsed = now - started
        settled = elapsed >= self.min_duration and now - slow_since >= self.settle_time
        return settled or elapsed >= self.timeout
