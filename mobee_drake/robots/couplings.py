"""Joints that move together: the joints one motor drives, as the Katana's gripper motor drives
both fingers (dissertation App. B). MoBeE sees the motor as one degree of freedom, its *leader*
joint; every other joint of the motor *follows*: ``q_follower = ratio q_leader + offset``."""

import dataclasses as dc

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import ModelInstanceIndex
from pydrake.systems.framework import LeafSystem
from pydrake.systems.primitives import AffineSystem, MatrixGain


@dc.dataclass(frozen=True)
class JointCoupling:
    """``follower`` moves as ``ratio`` times ``leader`` plus ``offset`` (radians)."""

    follower: str
    leader: str
    ratio: float
    offset: float


def Followers(
    couplings: tuple[JointCoupling, ...], joints: list[str], source: str
) -> list[JointCoupling]:
    """The couplings whose leader is among the controlled ``joints`` (the follower of a joint
    held still is held too).

    Raises:
        ValueError: naming ``source``, for a follower listed among the controlled joints.
    """
    for coupling in couplings:
        if coupling.follower in joints:
            raise ValueError(
                f"{source}: joint '{coupling.follower}' follows '{coupling.leader}' (one motor "
                f"drives both); control '{coupling.leader}' alone"
            )
    return [c for c in couplings if c.leader in joints]


@dc.dataclass(frozen=True)
class CoupledPositions:
    """Where the controlled joints and their followers sit in the plant's positions and
    velocities, and the map from the controlled joints' q: ``q_plant[rows] = P q + p0`` (and
    ``v_plant[velocity_rows] = P v``)."""

    rows: np.ndarray
    velocity_rows: np.ndarray
    P: np.ndarray
    p0: np.ndarray

    def PositionMap(self, num_positions: int) -> tuple[np.ndarray, np.ndarray]:
        """(P, p0) over all of the plant's positions: ``q_plant = P q + p0`` on this robot's
        entries, zero elsewhere."""
        P, p0 = np.zeros((num_positions, self.P.shape[1])), np.zeros(num_positions)
        P[self.rows], p0[self.rows] = self.P, self.p0
        return P, p0

    def VelocityMap(self, num_velocities: int) -> np.ndarray:
        """``v_plant = V v`` on this robot's entries, zero elsewhere."""
        V = np.zeros((num_velocities, self.P.shape[1]))
        V[self.velocity_rows] = self.P
        return V

    @staticmethod
    def Of(
        plant: MultibodyPlant,
        instance: ModelInstanceIndex,
        joints: list[str],
        followers: list[JointCoupling],
    ) -> "CoupledPositions":
        moved = [plant.GetJointByName(name, instance) for name in joints] + [
            plant.GetJointByName(c.follower, instance) for c in followers
        ]
        n = len(joints)
        P = np.vstack([np.eye(n), np.zeros((len(followers), n))])
        p0 = np.zeros(len(moved))
        for k, coupling in enumerate(followers, start=n):
            P[k, joints.index(coupling.leader)] = coupling.ratio
            p0[k] = coupling.offset
        return CoupledPositions(
            rows=np.array([j.position_start() for j in moved], dtype=int),
            velocity_rows=np.array([j.velocity_start() for j in moved], dtype=int),
            P=P,
            p0=p0,
        )


def LinearMapSystem(S: np.ndarray, s0: np.ndarray) -> LeafSystem:
    """The system ``y = S u + s0``: a gain, or an affine map when followers have offsets."""
    return MatrixGain(S) if not np.any(s0) else AffineSystem(D=S, y0=s0)
