"""Projects workspace point forces into joint space by the Jacobian transpose (eq. 5.4, 5.10)."""

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import Frame, JacobianWrtVariable


def ProjectPointForces(plant: MultibodyPlant, plant_context, frame_B: Frame, p_BP: np.ndarray,
                       f_W: np.ndarray) -> np.ndarray:
    """Returns ``sum_i J_i^T f_W[i]`` for forces at points ``p_BP[i]`` fixed in ``frame_B``.

    ``J_i`` is the translational Jacobian of point i (world frame, with respect to all of the
    plant's velocities). All points of one frame share one Jacobian computation.

    Args:
        p_BP: (k, 3) points in frame B.
        f_W: (k, 3) forces in world.
    """
    world = plant.world_frame()
    J = plant.CalcJacobianTranslationalVelocity(
        plant_context, JacobianWrtVariable.kV, frame_B, p_BP.T, world, world)
    return f_W.ravel() @ J
