"""The parameters of MoBeE 2.0's dynamical system (dissertation eq. 5.7-5.17).

Units: joint positions in radians, lengths in metres, time in seconds. With the default unit mass,
every force is a joint acceleration in rad/s^2 (and the collision gain is in (rad/s^2) per metre of
field penetration per metre of lever arm).

Where the defaults come from: the 2014 MoBeE of the dissertation used unit mass, damping 50,
an attractor spring of slope 50 squashed to 1000 deg/s^2 (17.5 rad/s^2), joint limits with a
10-degree spring and 1000 deg/s^2 at the limit, constraint forces of 1500 deg/s^2, and collision
forces squashed to 1200 deg/s^2 (docs/mobee.md). We keep mass, damping, stiffness and the
10-degree springs, and choose the maxima in a fixed order that the text asks for (ch. 5.2.1-5.2.2):
the client's forces (20 rad/s^2) must be able to beat the attractor spring (20) but never the
constraint forces (limits, constraints and collisions: 40).
"""

import dataclasses as dc
import math


@dc.dataclass
class SquashParams:
    """One sigmoid ``L`` of eq. 5.8: its maximum value ``m`` and its maximum slope ``k``."""

    m: float = 20.0
    k: float = 1.0


@dc.dataclass
class JointDynamics:
    """Per-joint overrides of the mass, damping and spring constants of eq. 5.7."""

    mass: float = 1.0
    damping: float = 50.0
    stiffness: float = 50.0


@dc.dataclass
class MobeeParams:
    """The constants of MoBeE 2.0 (eq. 5.7-5.17)."""

    # M, C, K of eq. 5.7 for every controlled joint ...
    mass: float = 1.0
    damping: float = 50.0
    stiffness: float = 50.0
    # ... unless overridden here, by joint name.
    joint_overrides: dict[str, JointDynamics] = dc.field(default_factory=dict)

    # L of the attractor spring -L(K(q - q*)) (eq. 5.7).
    spring_squash: SquashParams = dc.field(default_factory=lambda: SquashParams(20.0, 1.0))
    # L of the client's configuration-space force (eq. 5.9).
    config_squash: SquashParams = dc.field(default_factory=lambda: SquashParams(20.0, 1.0))
    # L of the projected workspace forces on markers (eq. 5.10).
    work_squash: SquashParams = dc.field(default_factory=lambda: SquashParams(20.0, 1.0))
    # L of the projected collision forces (eq. 5.11).
    collision_squash: SquashParams = dc.field(default_factory=lambda: SquashParams(40.0, 1.0))
    # Workspace force per metre of field penetration, before projection (eq. 5.11).
    collision_gain: float = 1.0e4

    # Joint limits (eq. 5.12): spring length delta (rad) and force f_max at the limit.
    limit_delta: float = math.radians(10.0)
    limit_force: float = 40.0
    # Linear constraints (eq. 5.15): spring length delta (rad of joint space) and f_max.
    constraint_delta: float = math.radians(10.0)
    constraint_force: float = 40.0

    def Validate(self, joints: list[str]) -> None:
        """Raises ValueError naming the parameter (and joint) whose value is out of range."""
        positive = {
            "mass": self.mass,
            "stiffness": self.stiffness,
            "collision_gain": self.collision_gain,
            "limit_delta": self.limit_delta,
            "limit_force": self.limit_force,
            "constraint_delta": self.constraint_delta,
            "constraint_force": self.constraint_force,
        }
        for name in ("spring", "config", "work", "collision"):
            squash = getattr(self, f"{name}_squash")
            positive[f"{name}_squash.m"] = squash.m
            positive[f"{name}_squash.k"] = squash.k
        for name, override in self.joint_overrides.items():
            if name not in joints:
                raise ValueError(
                    f"MoBeE parameters: joint_overrides names unknown joint '{name}'; "
                    "controlled joints are: " + ", ".join(joints)
                )
            positive[f"joint_overrides[{name}].mass"] = override.mass
            positive[f"joint_overrides[{name}].stiffness"] = override.stiffness
            if not (math.isfinite(override.damping) and override.damping >= 0):
                raise ValueError(
                    f"MoBeE parameters: joint_overrides[{name}].damping must be >= 0, "
                    f"got {override.damping}"
                )
        for name, value in positive.items():
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"MoBeE parameters: {name} must be > 0, got {value}")
        if not (math.isfinite(self.damping) and self.damping >= 0):
            raise ValueError(f"MoBeE parameters: damping must be >= 0, got {self.damping}")

    def PerJoint(self, joints: list[str]) -> tuple[list[float], list[float], list[float]]:
        """The mass, damping and stiffness of each joint, in the order of ``joints``."""
        default = JointDynamics(self.mass, self.damping, self.stiffness)
        rows = [self.joint_overrides.get(name, default) for name in joints]
        return ([r.mass for r in rows], [r.damping for r in rows], [r.stiffness for r in rows])
