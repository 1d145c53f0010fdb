"""MoBeE's virtual dynamics (eq. 5.7) integrated in discrete time: the kinematic robot's motion."""

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem


class VirtualDynamics(LeafSystem):
    """Integrates ``M q'' = total`` with period ``h`` from the forces of MoBeE.

    .. pydrake_system::

        name: VirtualDynamics
        input_ports:
        - total
        - damping
        output_ports:
        - state

    ``total`` is MoBeE's total force and ``damping`` its damping term ``-C v`` (both n). The
    damping is linear and stiff (``h C / M`` reaches 1 at MoBeE's rates), so it is integrated
    implicitly and every other force explicitly (semi-implicit Euler):

        v+ = (v + h (total - damping) / M) / (1 + h C / M),     q+ = q + h v+.

    The ``damping`` input carries ``-C v`` of whatever velocity MoBeE saw (the dynamic robot's
    measured one), and is replaced by the implicit damping of this system's own velocity. Left
    unconnected, MoBeE saw this system's own velocity (the kinematic robot, whose MoBeE reads this
    state), and ``damping = -C v`` is computed here (the same numbers, one port read fewer).
    The state (q, v) is the output, in MoBeE's joint order.
    """

    def __init__(
        self, *, mass: np.ndarray, damping: np.ndarray, period: float, initial_positions: np.ndarray
    ):
        super().__init__()
        n = len(mass)
        mass, damping = np.asarray(mass, dtype=float), np.asarray(damping, dtype=float)
        self._period = period
        self._h_over_mass = period / mass
        self._damping = damping
        self._damping_factor = 1.0 / (1.0 + period * damping / mass)
        self._total_port = self.DeclareVectorInputPort("total", n)
        self._damping_port = self.DeclareVectorInputPort("damping", n)
        state = self.DeclareDiscreteState(
            BasicVector(np.concatenate([initial_positions, np.zeros(n)]))
        )
        self.DeclareStateOutputPort("state", state)
        self.DeclarePeriodicDiscreteUpdateEvent(
            period_sec=period, offset_sec=0.0, update=self._Update
        )

    def _Update(self, context, discrete_state) -> None:
        x = context.get_discrete_state_vector().value()
        n = len(self._h_over_mass)
        if self._damping_port.HasValue(context):
            undamped = self._total_port.Eval(context) - self._damping_port.Eval(context)
        else:  # total - (-C v)
            undamped = self._total_port.Eval(context) + self._damping * x[n:]
        v_next = (x[n:] + self._h_over_mass * undamped) * self._damping_factor
        discrete_state.get_mutable_vector().SetFromVector(
            np.concatenate([x[:n] + self._period * v_next, v_next])
        )
