"""Projects workspace point forces into joint space by the Jacobian transpose (eq. 5.4, 5.10)."""

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import Frame, JacobianWrtVariable


class PointForceProjector:
    """``J^T f`` for a force ``f`` (world frame) at a point fixed in a frame of ``plant``.

    ``J`` is the point's translational Jacobian in world with respect to all of the plant's
    velocities; the result is a generalized force over the plant's velocities.
    """

    def __init__(self, plant: MultibodyPlant):
        self._world = plant.world_frame()
        self._jacobian = plant.CalcJacobianTranslationalVelocity

    def __call__(
        self, plant_context, frame_F: Frame, p_FP: np.ndarray, f_W: np.ndarray
    ) -> np.ndarray:
        J = self._jacobian(
            plant_context, JacobianWrtVariable.kV, frame_F, p_FP, self._world, self._world
        )
        return f_W @ J
