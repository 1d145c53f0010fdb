"""The parameters of MoBeE 2.0's dynamical system (dissertation eq. 5.7-5.17).

Units: joint positions in radians, lengths in metres, time in seconds. With the default unit mass,
every force is a joint acceleration in rad/s^2 (and the collision gain is in (rad/s^2) per metre of
field penetration per metre of lever arm).

Two presets (docs/mobee.md, "Presets"):

- :class:`MobeeParams`, the defaults, chosen by measurement against Drake's differential IK
  (docs/reactive.md). Far from the attractor the spring is squashed to its maximum ``m_s`` and
  the damping ``C`` caps a joint's speed at ``m_s / C``; near it the spring is linear (slope
  ``k K``) and eq. 5.7 is ``q'' = -C q' - k K (q - q*)``, critically damped when ``C^2 = 4 k K``,
  with time constant ``1 / sqrt(k K)``. We take ``C = 20/s`` and ``K = 100/s^2`` (k = 1): critical
  damping, a 0.1 s time constant and a 1 rad/s (57 deg/s) speed cap from the attractor alone.
  The maxima keep the order the text asks for (ch. 5.2.1-5.2.2): each client force (20) can beat
  the spring (20), and the forces that keep the robot safe (limits, constraints, collisions: 80)
  beat the spring and both client forces together (60). The obstacle-aware flow is on.
- :class:`Dissertation`, the constants of the dissertation's experiments: the 2014 MoBeE used unit
  mass, damping 50, an attractor spring of slope 50 squashed to 1000 deg/s^2 (17.5 rad/s^2),
  joint limits with a 10-degree spring and 1000 deg/s^2 at the limit, constraint forces of 1500
  deg/s^2, and collision forces squashed to 1200 deg/s^2 (docs/mobee.md). It keeps mass, damping,
  stiffness and the 10-degree springs, with maxima in the same order (client 20, spring 20,
  safety 40): an overdamped approach (slow pole 1.02/s, so a 1 s time constant) capped at 0.4
  rad/s (23 deg/s), the source's slow and careful motion. No flow. The experiments of ch. 7 and 8
  and the scenarios that reproduce them use it.
"""

import dataclasses as dc
import math

import numpy as np

from mobee_drake.mobee.barrier import BarrierParams
from mobee_drake.mobee.flow import FlowParams


@dc.dataclass
class SquashParams:
    """One sigmoid ``L`` of eq. 5.8: its maximum value ``m`` and its maximum slope ``k``."""

    m: float = 20.0
    k: float = 1.0


@dc.dataclass
class JointParams:
    """One joint's own values of MoBeE's per-joint constants; None keeps the robot-wide value.

    Eq. 5.7's M, C, K, eq. 5.8's maximum ``m_i`` and slope ``k_i`` of each sigmoid, and eq.
    5.12's spring length ``delta_i`` and force ``f_max,i`` of the joint's limits are all per
    dimension in the text.
    """

    mass: float | None = None
    damping: float | None = None
    stiffness: float | None = None
    spring_squash: SquashParams | None = None
    config_squash: SquashParams | None = None
    work_squash: SquashParams | None = None
    collision_squash: SquashParams | None = None
    limit_delta: float | None = None
    limit_force: float | None = None


SQUASHES = ("spring", "config", "work", "collision")


@dc.dataclass(frozen=True)
class PerJointValues:
    """Every per-joint constant as an array over the controlled joints (in their order)."""

    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    limit_delta: np.ndarray
    limit_force: np.ndarray
    # The sigmoids of eq. 5.8 by name (SQUASHES): (m, k), each an array.
    squash: dict[str, tuple[np.ndarray, np.ndarray]]


@dc.dataclass
class MobeeParams:
    """The constants of MoBeE 2.0 (eq. 5.7-5.17)."""

    # M, C, K of eq. 5.7 for every controlled joint ...
    mass: float = 1.0
    damping: float = 20.0
    stiffness: float = 100.0
    # ... and every other per-joint constant below, unless a joint has its own value here.
    joint_overrides: dict[str, JointParams] = dc.field(default_factory=dict)

    # L of the attractor spring -L(K(q - q*)) (eq. 5.7).
    spring_squash: SquashParams = dc.field(default_factory=lambda: SquashParams(20.0, 1.0))
    # L of the client's configuration-space force (eq. 5.9).
    config_squash: SquashParams = dc.field(default_factory=lambda: SquashParams(20.0, 1.0))
    # L of the projected workspace forces on markers (eq. 5.10).
    work_squash: SquashParams = dc.field(default_factory=lambda: SquashParams(20.0, 1.0))
    # L of the projected collision forces (eq. 5.11).
    collision_squash: SquashParams = dc.field(default_factory=lambda: SquashParams(80.0, 1.0))
    # Workspace force per metre of field penetration, before projection (eq. 5.11).
    collision_gain: float = 1.0e4

    # Joint limits (eq. 5.12): spring length delta (rad) and force f_max at the limit.
    limit_delta: float = math.radians(10.0)
    limit_force: float = 80.0
    # Linear constraints (eq. 5.15): spring length delta (rad of joint space) and f_max.
    constraint_delta: float = math.radians(10.0)
    constraint_force: float = 80.0
    # The safety barrier (ours): no force, a client's or MoBeE's, closes a gap between solids
    # faster than this (see mobee_drake/mobee/barrier.py).
    barrier: BarrierParams = dc.field(default_factory=BarrierParams)
    # The obstacle-aware flow (ours): the goal-directed forces bent around the fields they push
    # into (see mobee_drake/mobee/flow.py).
    flow: FlowParams = dc.field(default_factory=FlowParams)

    def _Values(self, override: JointParams | None = None) -> dict[str, float]:
        """Every per-joint constant by name (``spring_squash.m``, ...), robot-wide or, where
        ``override`` gives one, the joint's own."""
        override = override or JointParams()
        values = {}
        for name in ("mass", "damping", "stiffness", "limit_delta", "limit_force"):
            own = getattr(override, name)
            values[name] = getattr(self, name) if own is None else own
        for squash in SQUASHES:
            own = getattr(override, f"{squash}_squash")
            chosen = getattr(self, f"{squash}_squash") if own is None else own
            values[f"{squash}_squash.m"], values[f"{squash}_squash.k"] = chosen.m, chosen.k
        return values

    def Validate(self, joints: list[str]) -> None:
        """Raises ValueError naming the parameter (and joint) whose value is out of range."""
        for name in self.joint_overrides:
            if name not in joints:
                raise ValueError(
                    f"MoBeE parameters: joint_overrides names unknown joint '{name}'; "
                    "controlled joints are: " + ", ".join(joints)
                )
        robot_wide = {
            "collision_gain": self.collision_gain,
            "constraint_delta": self.constraint_delta,
            "constraint_force": self.constraint_force,
        }
        scopes = [("", {**self._Values(), **robot_wide})] + [
            (f"joint_overrides[{joint}].", self._Values(override))
            for joint, override in self.joint_overrides.items()
        ]
        for prefix, values in scopes:
            for name, value in values.items():
                low_ok = value >= 0 if name == "damping" else value > 0
                if not (math.isfinite(value) and low_ok):
                    bound = ">= 0" if name == "damping" else "> 0"
                    raise ValueError(
                        f"MoBeE parameters: {prefix}{name} must be {bound}, got {value}"
                    )
            # The barrier's condition: bounded speeds (docs/mobee.md, "The safety guarantee").
            if self.barrier.enabled and values["damping"] <= 0:
                raise ValueError(
                    f"MoBeE parameters: {prefix}damping must be > 0 while the safety barrier is "
                    "on (without damping speeds are unbounded and a solid may cross its field "
                    f"in one period), got {values['damping']}"
                )
        for error in self.barrier.Errors():
            raise ValueError(f"MoBeE parameters: {error}")

    def PerJoint(self, joints: list[str]) -> PerJointValues:
        """Every per-joint constant for ``joints``, in their order."""
        rows = [self._Values(self.joint_overrides.get(joint)) for joint in joints]

        def Column(name: str) -> np.ndarray:
            return np.array([row[name] for row in rows], dtype=float)

        return PerJointValues(
            mass=Column("mass"),
            damping=Column("damping"),
            stiffness=Column("stiffness"),
            limit_delta=Column("limit_delta"),
            limit_force=Column("limit_force"),
            squash={
                squash: (Column(f"{squash}_squash.m"), Column(f"{squash}_squash.k"))
                for squash in SQUASHES
            },
        )


@dc.dataclass
class Dissertation(MobeeParams):
    """MoBeE 2.0 with the constants of the dissertation's experiments (see the module): in a
    scenario, ``mobee: !Dissertation {}``."""

    damping: float = 50.0
    stiffness: float = 50.0
    collision_squash: SquashParams = dc.field(default_factory=lambda: SquashParams(40.0, 1.0))
    limit_force: float = 40.0
    constraint_force: float = 40.0
    flow: FlowParams = dc.field(default_factory=lambda: FlowParams(enabled=False))
