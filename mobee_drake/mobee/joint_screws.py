"""Every point Jacobian MoBeE needs, from a few of Drake's: the joints' screws in world.

A velocity v_j of the plant moves each body downstream of its joint with one twist: angular
velocity ``w_j`` and, at the world origin, linear velocity ``u_j`` per unit of v_j (the column j of
any such body's spatial Jacobian shifted to the origin; for a revolute joint, the Plücker
coordinates of its axis line). A point P of body b therefore moves at

    dp_WP/dv_j = mask[b, j] (w_j x P + u_j),        mask[b, j] = "v_j moves body b",

so the translational Jacobian of any point of any body is one vectorised expression, and the
projection of a direction n onto the joints (MoBeE's ``J^T f``, eq. 5.4, 5.10, 5.11) is

    n . dp_WP/dv_j = mask[b, j] ((P x n) . w_j + n . u_j).

The screws of all of the robot's velocities come from one spatial Jacobian per chain end (a
*leaf*: the iCub's hands and head, three calls; the Katana's arm and finger, two) per
configuration, however many points are projected. The columns are then carried onto the
controlled joints by the robot's velocity map (followers included: robots/couplings.py).
"""

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import BodyIndex, JacobianWrtVariable

# The Levi-Civita symbol: (a x b)_i = eps_ijk a_j b_k (einsum with it is ~6x faster than np.cross
# on these small arrays).
_EPS = np.zeros((3, 3, 3))
_EPS[0, 1, 2] = _EPS[1, 2, 0] = _EPS[2, 0, 1] = 1.0
_EPS[0, 2, 1] = _EPS[2, 1, 0] = _EPS[1, 0, 2] = -1.0
_ORIGIN = np.zeros(3)


class JointScrews:
    """The screws of the plant velocities a robot's controlled joints drive.

    Args:
        plant: the finalized plant.
        velocity_map: (nv, n), ``v_plant = velocity_map @ v`` (ControlledRobot.velocity_map).
    """

    def __init__(self, plant: MultibodyPlant, velocity_map: np.ndarray):
        self._plant = plant
        self._world = plant.world_frame()
        # The velocities the controlled joints drive, and the map from them onto the joints.
        self._velocities = np.flatnonzero(np.any(velocity_map != 0.0, axis=1))
        self._to_joints = velocity_map[self._velocities]
        column = {int(v): c for c, v in enumerate(self._velocities)}
        # moves[b, c]: velocity c moves body b.
        self._moves = np.zeros((plant.num_bodies(), len(self._velocities)), dtype=bool)
        for joint in (plant.get_joint(j) for j in plant.GetJointIndices()):
            start = joint.velocity_start()
            for v in range(start, start + joint.num_velocities()):
                if v in column:
                    bodies = plant.GetBodiesKinematicallyAffectedBy([joint.index()])
                    self._moves[[int(b) for b in bodies], column[v]] = True
        # Leaves: bodies that, together, are moved by every one of the velocities; each column
        # is read from the Jacobian of the first leaf moved by it.
        uncovered = np.ones(len(self._velocities), dtype=bool)
        self._leaf_frames, self._gather = [], np.zeros(len(self._velocities), dtype=int)
        while uncovered.any():
            body = int(np.argmax((self._moves & uncovered).sum(axis=1)))
            columns = np.flatnonzero(self._moves[body] & uncovered)
            offset = len(self._leaf_frames) * plant.num_velocities()
            self._gather[columns] = offset + self._velocities[columns]
            self._leaf_frames.append(plant.get_body(BodyIndex(body)).body_frame())
            uncovered[columns] = False

    @property
    def velocities(self) -> np.ndarray:
        """(r,): the plant velocities the controlled joints drive, in the screws' order."""
        return self._velocities

    @property
    def to_joints(self) -> np.ndarray:
        """(r, n): ``v_driven = to_joints @ v`` of the controlled joints."""
        return self._to_joints

    def Calc(self, plant_context) -> np.ndarray:
        """(6, r): the screws of the r driven velocities, column by column: ``w`` in rows 0-2,
        ``u`` in rows 3-5.

        Read off the Jacobian of the world frame's spatial velocity measured in each leaf
        (at the world origin, expressed in world), which is minus the leaf's own shifted to the
        world origin: no pose of the leaf is needed.
        """
        jacobians = [
            self._plant.CalcJacobianSpatialVelocity(
                plant_context, JacobianWrtVariable.kV, self._world, _ORIGIN, leaf, self._world
            )
            for leaf in self._leaf_frames
        ]
        return -np.concatenate(jacobians, axis=1)[:, self._gather]

    def Moves(self, bodies: np.ndarray) -> np.ndarray:
        """(k, r) float: which of the driven velocities move each of ``bodies`` (plant body
        indices), for :meth:`Project`."""
        return self._moves[bodies].astype(float)

    def Project(
        self, screws: np.ndarray, moves: np.ndarray, points: np.ndarray, directions: np.ndarray
    ) -> np.ndarray:
        """(k, n): each direction n_i (world) at point P_i (world) projected onto the controlled
        joints, ``n_i . dp_WP_i/dq``, for a point of a body moved by the velocities ``moves[i]``
        (rows of :meth:`Moves`; a difference of two rows gives the relative motion of two bodies
        along n_i, for two points on one line along n_i)."""
        w, u = screws[:3], screws[3:]
        p_x_n = np.einsum("ijk,aj,ak->ai", _EPS, points, directions)
        return ((p_x_n @ w + directions @ u) * moves) @ self._to_joints

    def Jacobians(self, screws: np.ndarray, moves: np.ndarray, points: np.ndarray) -> np.ndarray:
        """(k, 3, n): the translational Jacobian ``dp_WP_i/dq`` of each point (world) of a body
        moved by the velocities ``moves[i]`` (rows of :meth:`Moves`), over the controlled joints."""
        w, u = screws[:3], screws[3:]
        J = u[None] + np.einsum("ijk,jr,ak->air", _EPS, w, points)  # u_j + w_j x P
        return (J * moves[:, None, :]) @ self._to_joints
