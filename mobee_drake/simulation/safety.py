"""Watches a run for what matters to safety: closest approaches and penetrations of solids."""

import dataclasses as dc

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import BasicVector, LeafSystem

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
    """Reads MoBeE's field contacts every ``period`` and keeps the worst case in its state.

    .. pydrake_system::

        name: SafetyMonitor
        input_ports:
        - field_contacts

    State: per watched name the closest distance seen (inf until inside a field), the number of
    periods with a penetration, and the deepest penetration.
    """

    def __init__(self, *, names: list[str], period: float):
        super().__init__()
        self._names = list(names) + [SELF]
        self._index = {name: i for i, name in enumerate(self._names)}
        self._contacts_port = self.DeclareAbstractInputPort(
            "field_contacts", AbstractValue.Make([]))
        initial = np.concatenate([np.full(len(self._names), np.inf), [0.0, 0.0]])
        self._state = self.DeclareDiscreteState(BasicVector(initial))
        self.DeclarePeriodicDiscreteUpdateEvent(period_sec=period, offset_sec=0.0,
                                                update=self._Update)

    def _Update(self, context, discrete_state) -> None:
        x = context.get_discrete_state(self._state).value().copy()
        n = len(self._names)
        deepest_now = 0.0
        for contact in self._contacts_port.Eval(context):
            name = SELF if contact.name_B not in self._index else contact.name_B
            i = self._index[name]
            x[i] = min(x[i], contact.distance)
            deepest_now = max(deepest_now, -contact.distance)
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
