"""Watches a run for what matters to safety: closest approaches and penetrations of solids."""

import dataclasses as dc

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import GeometryId
from pydrake.systems.framework import BasicVector, LeafSystem

from mobee_drake.mobee.fields import NO_FIELD_PAIRS

SELF = "(self)"


@dc.dataclass
class SafetyReport:
    # Closest signed distance (m) of the robot's solids to each object and to themselves
    # ("(self)"), among the times the pair was inside its field; None: never inside a field.
    closest_approach: dict[str, float | None]
    # Control periods in which some solid pair penetrated, and the deepest penetration (m, >= 0).
    penetrating_steps: int
    deepest_penetration: float


class SafetyMonitor(LeafSystem):
    """Reads MoBeE's field pairs every ``period`` and keeps the worst case in its state.

    .. pydrake_system::

        name: SafetyMonitor
        input_ports:
        - field_pairs

    State: per watched object the closest distance seen (inf until inside a field), the same for
    the robot's own pairs, the number of periods with a penetration and the deepest penetration.

    Args:
        objects: the geometry of each watched object, by name.
    """

    def __init__(self, *, objects: dict[str, GeometryId], period: float):
        super().__init__()
        self._names = list(objects) + [SELF]
        self._index = {geometry_id: i for i, geometry_id in enumerate(objects.values())}
        self._self_index = len(objects)
        self._pairs_port = self.DeclareAbstractInputPort(
            "field_pairs", AbstractValue.Make(NO_FIELD_PAIRS))
        initial = np.concatenate([np.full(len(self._names), np.inf), [0.0, 0.0]])
        self._state = self.DeclareDiscreteState(BasicVector(initial))
        self.DeclarePeriodicDiscreteUpdateEvent(period_sec=period, offset_sec=0.0,
                                                update=self._Update)

    def _Update(self, context, discrete_state) -> None:
        x = context.get_discrete_state(self._state).value().copy()
        n = len(self._names)
        pairs = self._pairs_port.Eval(context)
        if len(pairs):
            for geometry_id, distance in zip(pairs.geometry_B, pairs.distance):
                i = self._index.get(geometry_id, self._self_index)
                x[i] = min(x[i], distance)
            deepest_now = -pairs.distance.min()
            if deepest_now > 0:
                x[n] += 1
                x[n + 1] = max(x[n + 1], deepest_now)
        discrete_state.get_mutable_vector(self._state).SetFromVector(x)

    def Report(self, context) -> SafetyReport:
        x = context.get_discrete_state(self._state).value()
        n = len(self._names)
        return SafetyReport(
            closest_approach={name: (None if np.isinf(x[i]) else float(x[i]))
                              for i, name in enumerate(self._names)},
            penetrating_steps=int(x[n]), deepest_penetration=float(x[n + 1]))
