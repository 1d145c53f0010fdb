"""World events in a running station: the scenario's scripted ones and those a client requests.

A client changes the world by listing every :class:`~mobee_drake.world.objects.WorldEvent` it has
issued, in order, on an abstract output port (the list is a function of its state) that its
``ClientPorts`` declare among its ``world_events`` (see :mod:`mobee_drake.station.parts`).
SceneGraph's world lives in its Context's parameters, which no system's event may change, so the
events are applied between simulation steps by a Simulator *monitor* (:func:`MakeSimulator`): after
every step it applies the scripted events that are due and the requests not yet applied. How many of
each have been applied is the discrete state of a :class:`WorldEventLedger` in the diagram, so a
plain ``Simulator.AdvanceTo`` in one call, the runner's chunks, two contexts and a restored
checkpoint all agree on the world.

An event at time t is applied when the step that reaches t ends, before the discrete updates at
t (the robot's next period sees the new world); a request issued by an update at t is applied
at the end of the next step.
"""

import numpy as np
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator, SimulatorConfig
from pydrake.systems.framework import BasicVector, EventStatus, LeafSystem

from mobee_drake.station.safety import WarnOfPenetrations


class WorldEventLedger(LeafSystem):
    """How many world events have been applied: the scripted ones, then each client's requests.

    .. pydrake_system::

        name: WorldEventLedger

        output_ports:
        - counts

    It has no events: :func:`ApplyWorldEvents` keeps its state; ``counts`` is that state (the
    data log reads when each event was applied from it).
    """

    def __init__(self, *, num_request_ports: int):
        super().__init__()
        self._counts = self.DeclareDiscreteState(BasicVector(np.zeros(1 + num_request_ports)))
        self.DeclareStateOutputPort("counts", self._counts)

    def Counts(self, context) -> np.ndarray:
        """(scripted events applied, requests applied per port), in this system's ``context``."""
        return context.get_discrete_state(self._counts).value()

    def SetCounts(self, context, counts: np.ndarray) -> None:
        context.SetDiscreteState(self._counts, counts)


def ApplyWorldEvents(station, root_context) -> None:
    """Applies the station's due scripted events and new requests to ``root_context``."""
    ledger = station.event_ledger
    before = ledger.Counts(ledger.GetMyContextFromRoot(root_context))
    counts = before.copy()
    scripted, now = station.scripted_events, root_context.get_time()
    while counts[0] < len(scripted) and scripted[int(counts[0])].time <= now:
        station.world.Apply(root_context, scripted[int(counts[0])])
        counts[0] += 1
    for i, port in enumerate(station.request_ports, start=1):
        issued = port.Eval(port.get_system().GetMyContextFromRoot(root_context))
        for event in issued[int(counts[i]) :]:
            station.world.Apply(root_context, event)
        counts[i] = len(issued)
    if np.any(counts != before):  # (Most steps change nothing: no mutable context then.)
        ledger.SetCounts(ledger.GetMyMutableContextFromRoot(root_context), counts)
        WarnOfPenetrations(station.diagram, root_context, "a world event")


def MakeSimulator(station, config: SimulatorConfig | None = None) -> Simulator:
    """A Simulator of ``station``'s diagram (set up by Drake's ``config``, if given) that applies
    the station's world events after every step."""
    simulator = Simulator(station.diagram)
    if config is not None:
        ApplySimulatorConfig(config, simulator)
    if station.scripted_events or station.request_ports:

        def Monitor(root_context) -> EventStatus:
            ApplyWorldEvents(station, root_context)
            return EventStatus.Succeeded()

        simulator.set_monitor(Monitor)
    return simulator
