"""The client contract (station/parts.py): what a client offers is what its ClientPorts declare,
checked when the station is built; nothing is found by searching the diagram (issue 32)."""

import unittest

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem

from mobee_drake.experiments.ch8_reaching import ReachScenario
from mobee_drake.scenario import BuildScenario, LoadScenario
from mobee_drake.station.builder import MakeMobeeStation
from mobee_drake.station.parts import ClientContractError, ClientPorts
from mobee_drake.station.runner import CompletedActions


class Home(LeafSystem):
    """A client that holds MoBeE's home; hooks are added by subclasses."""

    def __init__(self, home: np.ndarray):
        super().__init__()
        self.DeclareVectorOutputPort(
            "attractor", len(home), lambda context, output: output.SetFromVector(home)
        )


class Misspelt(Home):
    def FinishedActions(self, context) -> int:
        return 0


class WrongSignature(Home):
    def CompletedActions(self) -> int:
        return 0


class VectorRequests(Home):
    def __init__(self, home):
        super().__init__(home)
        self.DeclareVectorOutputPort("requests", 1, lambda context, output: None)


class CountsTwo(Home):
    def __init__(self, home):
        super().__init__(home)
        self.DeclareAbstractOutputPort(
            "requests", lambda: AbstractValue.Make([]), lambda context, output: None
        )

    def CompletedActions(self, context) -> int:
        return 2


class WrongLog(Home):
    def __init__(self, home):
        super().__init__(home)
        self.DeclareVectorOutputPort("data_log", 3, lambda context, output: None)

    def DataLogColumns(self) -> list[tuple[str, str]]:
        return [("a", "m"), ("b", "m")]


class Lenient(Home):
    def CompletedActions(self, context, scale: int = 5) -> int:
        return scale


def _Station(client_class, **hooks):
    """reach_around_ball with a client of ``client_class``, declared with ``hooks`` (each
    "self" for the client's system, or "requests" for its port of that name)."""

    def AddClient(parts):
        system = parts.builder.AddSystem(client_class(parts.mobee.home))
        named = {"self": system, "requests": getattr(system, "GetOutputPort", None)}
        declared = {}
        for hook, value in hooks.items():
            if value == "requests":
                declared[hook] = [system.GetOutputPort("requests")]
            elif isinstance(value, tuple):
                declared[hook] = tuple(named[v] for v in value)
            else:
                declared[hook] = [named[value]] if hook.endswith("s") else named[value]
        return ClientPorts(system=system, attractor=system.GetOutputPort("attractor"), **declared)

    return MakeMobeeStation(LoadScenario("reach_around_ball"), prebuild_callback=AddClient)


class TestClientContract(unittest.TestCase):
    def test_a_misspelt_hook_fails_the_build(self):
        with self.assertRaisesRegex(
            ClientContractError,
            "declared as action_counters, has no method CompletedActions "
            r"\(it has FinishedActions\)",
        ):
            _Station(Misspelt, action_counters="self")

    def test_a_hook_of_the_wrong_signature_fails_the_build(self):
        with self.assertRaisesRegex(
            ClientContractError, r"CompletedActions\(\) must take \(context\)"
        ):
            _Station(WrongSignature, action_counters="self")
        with self.assertRaisesRegex(ClientContractError, "has no method Outcome"):
            _Station(CountsTwo, outcome="self")
        with self.assertRaisesRegex(ClientContractError, "has no method DataLogColumns"):
            _Station(CountsTwo, data_log="self")
        with self.assertRaisesRegex(ClientContractError, "must be abstract"):
            _Station(VectorRequests, world_events="requests")
        with self.assertRaisesRegex(ClientContractError, "its 'data_log' port must be a vector"):
            _Station(WrongLog, data_log="self")
        # A tuple of counters, and a method with an extra optional parameter, are fine.
        station = _Station(Lenient, action_counters=("self",))
        context = station.diagram.CreateDefaultContext()
        self.assertEqual(CompletedActions(station, context), 5)

    def test_only_declared_hooks_are_read(self):
        """A system that implements a hook counts only when its client declares it; one left
        undeclared is named in a warning."""
        declared = _Station(CountsTwo, action_counters="self", world_events="requests")
        with self.assertLogs("mobee_drake.station.parts", "WARNING") as logs:
            undeclared = _Station(CountsTwo)
        self.assertIn("implements the action_counters hook, but no client declares", logs.output[0])
        for station, actions, ports in ((declared, 2, 1), (undeclared, 0, 0)):
            context = station.diagram.CreateDefaultContext()
            self.assertEqual(CompletedActions(station, context), actions)
            self.assertEqual(len(station.request_ports), ports)

    def test_the_shipped_clients_declare_their_hooks(self):
        """The state-action executor's finished actions are counted (they were not: its method
        was named FinishedActions, the runner looked for CompletedActions)."""
        station = BuildScenario(ReachScenario())
        executor = station.client
        self.assertEqual(station.Hooks("action_counters"), [executor])
        self.assertIs(station.client_ports.outcome, executor)
        context = station.diagram.CreateDefaultContext()
        executor_context = executor.GetMyMutableContextFromRoot(context)
        state = executor.State(executor_context)
        state.finished_actions = 3
        executor.SetState(executor_context, state)
        self.assertEqual(CompletedActions(station, context), 3)
        explorer = BuildScenario(LoadScenario("explore_hypercube"))
        for hook in ("action_counters", "checkpointed"):
            self.assertEqual(explorer.Hooks(hook), [explorer.client])


if __name__ == "__main__":
    unittest.main()
