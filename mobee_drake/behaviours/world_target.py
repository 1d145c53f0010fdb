"""A world object's position as a signal: what a behaviour points at or reaches for.

The object is named by the scenario; its pose is read from SceneGraph's query object at every
evaluation, so a world event that moves it moves the target (see
:mod:`mobee_drake.world.live_world`).
"""

from pydrake.common.value import AbstractValue
from pydrake.geometry import QueryObject
from pydrake.systems.framework import BasicVector, LeafSystem, OutputPort

from mobee_drake.station.parts import StationParts
from mobee_drake.world.live_world import LiveWorld


class WorldObjectPosition(LeafSystem):
    """The position (world) of the world object ``name``.

    .. pydrake_system::

        name: WorldObjectPosition

        input_ports:
        - query

        output_ports:
        - position
    """

    def __init__(self, world: LiveWorld, name: str):
        super().__init__()
        self._world, self._name = world, name
        self._query = self.DeclareAbstractInputPort("query", AbstractValue.Make(QueryObject()))
        self.DeclareVectorOutputPort("position", 3, self._CalcPosition)

    def _CalcPosition(self, context, output: BasicVector) -> None:
        objects = self._world.ObjectsSeenBy(self._query.Eval(context).inspector())
        if self._name not in objects:
            now = ", ".join(sorted(objects))
            raise ValueError(f"target '{self._name}': no such world object (now: {now})")
        output.SetFromVector(objects[self._name][3].translation())


def AddTargetPosition(parts: StationParts, name: str) -> OutputPort:
    """Adds the position of the world object ``name`` to the station; returns its port.

    Raises:
        ValueError: naming the object, if the world has none of that name.
    """
    if name not in parts.world.names:
        raise ValueError(
            f"target '{name}': no such world object; objects: " + ", ".join(parts.world.names)
        )
    system = parts.builder.AddNamedSystem(
        f"{parts.prefix}target_{name}", WorldObjectPosition(parts.world, name)
    )
    parts.builder.Connect(parts.scene_graph.get_query_output_port(), system.get_input_port())
    return system.get_output_port()
