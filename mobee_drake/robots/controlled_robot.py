"""One robot of a plant as its controllers see it: the joints they control (where those sit in
the plant's position and velocity vectors, their limits and home angles) and the robot's markers
with their bodies. MoBeE (:class:`~mobee_drake.mobee.system.Mobee`) and the NGIK kinematic model
(:class:`~mobee_drake.ngik.kinematic_model.KinematicModel`) both look the robot up through it.

A joint that follows a controlled one (:mod:`mobee_drake.robots.couplings`) is not a degree of
freedom of its own: the maps below carry the controlled joints' (q, v) into the plant's with the
followers set, and the plant's generalized forces back onto the controlled joints (the chain
rule: a follower's force acts on its leader times the ratio)."""

import dataclasses as dc

import numpy as np
from pydrake.multibody.plant import MultibodyPlant

from mobee_drake.robots.couplings import CoupledPositions, Followers, JointCoupling
from mobee_drake.robots.overlay import BodyMarker, RobotOverlay


@dc.dataclass(frozen=True)
class ControlledRobot:
    """The controlled joints (in this order in every n-vector) and the markers of one robot."""

    joints: tuple[str, ...]
    # Where each joint's position and velocity is in the plant's vectors.
    q_index: np.ndarray
    v_index: np.ndarray
    # Each joint's position limits and its home angle (the plant's default position), rad.
    lower: np.ndarray
    upper: np.ndarray
    home: np.ndarray
    markers: tuple[BodyMarker, ...]
    # The plant body each marker is fixed to.
    marker_bodies: tuple
    # Who reports an error ("MoBeE", "kinematic model").
    source: str
    # The joints that follow controlled ones, and where all of them sit in the plant's vectors.
    followers: tuple[JointCoupling, ...]
    coupled: CoupledPositions
    # v_plant = velocity_map @ v (nv x n): each controlled joint's column is 1 at its own velocity
    # and the ratio at its followers'; its transpose carries generalized forces onto the joints.
    velocity_map: np.ndarray

    @staticmethod
    def Of(
        plant: MultibodyPlant, robot: RobotOverlay, joints: list[str], source: str
    ) -> "ControlledRobot":
        """The controlled ``joints`` of ``robot`` in the finalized ``plant``.

        Raises:
            ValueError: naming ``source`` and the first joint the robot does not have.
        """
        found = []
        for name in joints:
            if not plant.HasJointNamed(name, robot.instance):
                movable = [
                    plant.get_joint(j).name()
                    for j in plant.GetJointIndices(robot.instance)
                    if plant.get_joint(j).num_positions() == 1
                ]
                raise ValueError(
                    f"{source}: unknown joint '{name}'; the robot's joints are: "
                    + ", ".join(movable)
                )
            found.append(plant.GetJointByName(name, robot.instance))
        q_index = np.array([j.position_start() for j in found], dtype=int)
        followers = Followers(robot.couplings, joints, source)
        coupled = CoupledPositions.Of(plant, robot.instance, joints, followers)
        velocity_map = coupled.VelocityMap(plant.num_velocities())
        return ControlledRobot(
            joints=tuple(joints),
            q_index=q_index,
            v_index=np.array([j.velocity_start() for j in found], dtype=int),
            lower=np.array([j.position_lower_limits()[0] for j in found]),
            upper=np.array([j.position_upper_limits()[0] for j in found]),
            home=plant.GetPositions(plant.CreateDefaultContext())[q_index],
            markers=tuple(robot.markers),
            marker_bodies=tuple(
                plant.GetBodyByName(m.body_name, robot.instance) for m in robot.markers
            ),
            source=source,
            followers=tuple(followers),
            coupled=coupled,
            velocity_map=velocity_map,
        )

    def PlantPositions(self, q: np.ndarray, positions: np.ndarray) -> np.ndarray:
        """``positions`` (the plant's, modified) with the controlled joints at ``q`` and their
        followers where they follow."""
        coupled = self.coupled
        positions[coupled.rows] = coupled.P @ q + coupled.p0
        return positions

    def PlantStateMap(self, num_positions: int) -> tuple[np.ndarray, np.ndarray]:
        """(S, s0) with ``x_plant = S [q; v] + s0`` for the robot's entries of the plant's
        state (every other entry zero): the controlled joints and their followers."""
        nv, n = self.velocity_map.shape
        P, p0 = self.coupled.PositionMap(num_positions)
        S = np.zeros((num_positions + nv, 2 * n))
        S[:num_positions, :n] = P
        S[num_positions:, n:] = self.velocity_map
        return S, np.concatenate([p0, np.zeros(nv)])

    @property
    def marker_names(self) -> list[str]:
        return [m.name for m in self.markers]

    def JointIndex(self, name: str) -> int:
        """The index of joint ``name`` in the n-vectors."""
        if name not in self.joints:
            raise ValueError(
                f"{self.source}: unknown joint '{name}'; controlled joints are: "
                + ", ".join(self.joints)
            )
        return self.joints.index(name)

    def MarkerIndex(self, name: str) -> int:
        """The index of marker ``name`` (its 3-vector is ``3i:3i+3`` of the marker ports)."""
        names = self.marker_names
        if name not in names:
            raise ValueError(
                f"{self.source}: unknown marker '{name}'; markers are: " + ", ".join(names)
            )
        return names.index(name)
