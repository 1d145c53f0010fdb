"""MoBeE's virtual dynamics (eq. 5.7) integrated in discrete time: the kinematic robot's motion."""

import numpy as np
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import LinearSystem

from mobee_drake.mobee.system import FORCE_TERMS


class VirtualDynamics(Diagram):
    """Integrates ``M q'' = total`` with period ``h`` from the forces of MoBeE.

    .. pydrake_system::

        name: VirtualDynamics
        input_ports:
        - forces
        output_ports:
        - state

    ``forces`` is MoBeE's ``forces`` port (every term, then the total; n each), of which this
    system reads the ``total`` and the ``damping`` term ``-C v``. The damping is linear and stiff
    (``h C / M`` reaches 1 at MoBeE's rates), so it is integrated implicitly and every other
    force explicitly (semi-implicit Euler):

        v+ = (v + h (total - damping) / M) / (1 + h C / M),     q+ = q + h v+,

    where ``damping`` is the ``-C v`` MoBeE put into ``total``. For the kinematic robot MoBeE
    reads this system's own state, so ``damping = -C v`` of this state; with
    ``measured_damping`` (the dynamic robot, whose MoBeE sees the plant's measured velocity) it
    is MoBeE's. Either way the update is linear in (q, v) and the forces: a Drake
    :class:`LinearSystem` with period ``h`` (no Python in the loop). The state (q, v) is the
    output, in MoBeE's joint order.
    """

    def __init__(
        self,
        *,
        mass: np.ndarray,
        damping: np.ndarray,
        period: float,
        initial_positions: np.ndarray,
        measured_damping: bool = False,
    ):
        super().__init__()
        mass, damping = np.asarray(mass, dtype=float), np.asarray(damping, dtype=float)
        n, h = len(mass), period
        gain = h / mass / (1.0 + h * damping / mass)  # v+ = keep v + gain (total - damping)
        # With the damping of this state, total - damping = total + C v, and keep = 1.
        keep = 1.0 / (1.0 + h * damping / mass) if measured_damping else np.ones(n)
        A = np.block([[np.eye(n), h * np.diag(keep)], [np.zeros((n, n)), np.diag(keep)]])
        B_total = np.vstack([h * np.diag(gain), np.diag(gain)])
        # Reads the total (the last block of the forces) and, measured, MoBeE's damping term.
        B = np.zeros((2 * n, (len(FORCE_TERMS) + 1) * n))
        B[:, -n:] = B_total
        if measured_damping:
            damping_row = FORCE_TERMS.index("damping")
            B[:, damping_row * n : (damping_row + 1) * n] = -B_total
        builder = DiagramBuilder()
        linear = builder.AddNamedSystem(
            "integrator",
            LinearSystem(A, B, np.eye(2 * n), np.zeros((2 * n, B.shape[1])), time_period=h),
        )
        linear.configure_default_state(np.concatenate([initial_positions, np.zeros(n)]))
        builder.ExportInput(linear.get_input_port(), "forces")
        builder.ExportOutput(linear.get_output_port(), "state")
        builder.BuildInto(self)
