"""Watches a run for what matters to safety: closest approaches and penetrations of solids, and
solids that penetrate where no motion brought them (at the start, or by a world event)."""

import dataclasses as dc
import logging

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import QueryObject
from pydrake.systems.framework import BasicVector, LeafSystem

from mobee_drake.mobee.fields import NO_FIELD_PAIRS
from mobee_drake.mobee.system import Mobee

SELF = "(self)"
OTHERS = "(other objects)"


@dc.dataclass
class SafetyReport:
    # Closest signed distance (m) of the robot's solids to each object and to themselves
    # ("(self)"), among the times the pair was inside its field; None: never inside a field.
    closest_approach: dict[str, float | None]
    # Control periods in which some solid pair penetrated, and the deepest penetration (m, >= 0).
    penetrating_steps: int
    deepest_penetration: float
    # Control periods in which MoBeE's safety barrier changed the total force (f_barrier != 0).
    barrier_periods: int = 0


class SafetyMonitor(LeafSystem):
    """Reads MoBeE's field pairs and safety barrier every ``period`` and keeps the worst case in
    its state.

    .. pydrake_system::

        name: SafetyMonitor
        input_ports:
        - field_pairs
        - geometry_query
        - f_barrier

    State: per watched object (by its geometry's name, so it survives the live world's changes)
    the closest distance seen (inf until inside a field), the same for the robot's own pairs and
    for objects added later, the number of periods with a penetration, the deepest one, and the
    number of periods in which the barrier acted (``f_barrier``, n: MoBeE's port; unconnected,
    none).
    """

    def __init__(self, *, names: list[str], period: float, num_joints: int):
        super().__init__()
        self._names = list(names) + [SELF, OTHERS]
        self._index = {name: i for i, name in enumerate(names)}
        self._self_index, self._others_index = len(names), len(names) + 1
        self._pairs_port = self.DeclareAbstractInputPort(
            "field_pairs", AbstractValue.Make(NO_FIELD_PAIRS)
        )
        self._query_port = self.DeclareAbstractInputPort(
            "geometry_query", AbstractValue.Make(QueryObject())
        )
        self._barrier_port = self.DeclareVectorInputPort("f_barrier", num_joints)
        initial = np.concatenate([np.full(len(self._names), np.inf), [0.0, 0.0, 0.0]])
        self._state = self.DeclareDiscreteState(BasicVector(initial))
        self.DeclarePeriodicDiscreteUpdateEvent(
            period_sec=period, offset_sec=0.0, update=self._Update
        )

    def _Update(self, context, discrete_state) -> None:
        pairs = self._pairs_port.Eval(context)
        n = len(self._names)
        barrier = self._barrier_port.HasValue(context) and self._barrier_port.Eval(context).any()
        if not (len(pairs) or barrier):
            return  # Nothing to record: the state (which Drake passes in) stays as it is.
        x = context.get_discrete_state(self._state).value().copy()
        x[n + 2] += barrier
        if len(pairs):
            self._RecordPairs(context, pairs, x)
        discrete_state.get_mutable_vector(self._state).SetFromVector(x)

    def _RecordPairs(self, context, pairs, x: np.ndarray) -> None:
        """The pairs' closest approaches and penetration into the state vector ``x``."""
        n = len(self._names)
        inspector = self._query_port.Eval(context).inspector()
        for geometry_id, distance, robot in zip(pairs.geometry_B, pairs.distance, pairs.b_is_robot):
            i = (
                self._self_index
                if robot
                else self._index.get(inspector.GetName(geometry_id), self._others_index)
            )
            x[i] = min(x[i], distance)
        deepest_now = -pairs.distance.min()
        if deepest_now > 0:
            x[n] += 1
            x[n + 1] = max(x[n + 1], deepest_now)

    def Report(self, context) -> SafetyReport:
        x = context.get_discrete_state(self._state).value()
        n = len(self._names)
        return SafetyReport(
            closest_approach={
                name: (None if np.isinf(x[i]) else float(x[i]))
                for i, name in enumerate(self._names)
            },
            penetrating_steps=int(x[n]),
            deepest_penetration=float(x[n + 1]),
            barrier_periods=int(x[n + 2]),
        )


class StartsInPenetrationError(ValueError):
    """A run whose robot starts inside an object or itself (the message names the pairs)."""


def PenetratingPairs(diagram, root_context) -> list[tuple[float, str, str, str]]:
    """Each pair of solids that penetrates at ``root_context``, for every MoBeE in ``diagram``:
    (signed distance (m, < 0), the robot, solid A, solid B), deepest first."""
    found = []
    for system in diagram.GetSystems():
        if isinstance(system, Mobee):
            # A companion's MoBeE is named after it ("katana_mobee"), the robot's "mobee".
            robot = system.get_name().removesuffix("mobee").removesuffix("_") or "the robot"
            context = system.GetMyContextFromRoot(root_context)
            for contact in system.GetOutputPort("field_contacts").Eval(context):
                if contact.distance < 0:
                    found.append((contact.distance, robot, contact.name_A, contact.name_B))
    return sorted(found)


def Penetrations(diagram, root_context) -> list[str]:
    """:func:`PenetratingPairs` in words: ``the robot: 'r_hand' 12.3 mm inside 'table'``."""
    return [
        f"{r}: '{a}' {-1000 * d:.1f} mm inside '{b}'"
        for d, r, a, b in PenetratingPairs(diagram, root_context)
    ]


def CheckStart(diagram, root_context) -> None:
    """Raises :class:`StartsInPenetrationError` if the robot starts in penetration: MoBeE's
    safety barrier keeps solids apart, it cannot make a run that starts inside an object
    faithful (move the object, or the robot's home)."""
    found = Penetrations(diagram, root_context)
    if found:
        raise StartsInPenetrationError(
            f"the robot starts in penetration: {', '.join(found[:3])}"
            + (f" and {len(found) - 3} more" if len(found) > 3 else "")
            + "; move the object or the robot"
        )


def WarnOfPenetrations(diagram, root_context, what: str) -> None:
    """Logs a warning naming the pairs that ``what`` (a world event) left in penetration."""
    found = Penetrations(diagram, root_context)
    if found:
        logging.getLogger(__name__).warning(
            "%s put solids in penetration at t = %.3f s: %s (MoBeE's fields push them apart)",
            what, root_context.get_time(), ", ".join(found[:3]),
        )  # fmt: skip
