"""Several clients on one robot at once (dissertation ch. 9.4.2, parallel behaviours).

Each *behaviour* is a client (see :mod:`mobee_drake.station.parts`) that owns a declared set of
MoBeE's joints and, where it pushes on markers, of its markers: head and eyes that keep a target
in view beside an arm that reaches, a wrist that keeps the palm facing the target, a torso that
brings the target closer. :func:`ComposeBehaviours` builds each behaviour's systems, checks the
ownership (a joint or marker unknown to MoBeE, or claimed twice, is refused in one line naming
the behaviours and the joint), and adds a :class:`BehaviourComposer` that makes MoBeE's inputs:

- the attractor: each joint's entry from the behaviour that owns it, the home angle for joints
  no behaviour owns;
- the configuration-space force: each behaviour's entries on its own joints, summed;
- the marker forces: each behaviour's forces on its own markers, summed.

A behaviour reads another's outputs through declared ports: its ``ClientPorts`` lists the ports it
``offers`` and the input ports it ``needs``, by name, and the composition connects each need to
the offer of the same name (a need no behaviour offers is refused). The composite declares every
behaviour's hooks, so outcomes, data logs, checkpoints and world events keep working.
"""

from collections.abc import Callable
import dataclasses as dc

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from mobee_drake.station.parts import ClientPorts, Declared, StationParts


@dc.dataclass(frozen=True)
class Behaviour:
    """A client and what it owns on the robot: MoBeE's joints and markers, by name."""

    name: str
    joints: tuple[str, ...]
    add_to_builder: Callable[[StationParts], ClientPorts]
    markers: tuple[str, ...] = ()


class BehaviourComposer(LeafSystem):
    """MoBeE's attractor and client forces from the behaviours' (see the module).

    .. pydrake_system::

        name: BehaviourComposer

        input_ports:
        - <behaviour>.attractor (one per behaviour)
        - <behaviour>.config_force (for a behaviour that sets one)
        - <behaviour>.marker_forces (for a behaviour that sets them)

        output_ports:
        - attractor
        - config_force
        - marker_forces

    Each input is MoBeE-sized (every joint, or three entries per marker); only the behaviour's own
    entries are read.
    """

    def __init__(
        self,
        *,
        home: np.ndarray,
        num_markers: int,
        owned_joints: dict[str, list[int]],
        owned_markers: dict[str, list[int]],
        config_forces: list[str],
        marker_forces: list[str],
    ):
        super().__init__()
        n, m = len(home), num_markers
        self._home = np.asarray(home, dtype=float)
        self._attractors = [
            (self.DeclareVectorInputPort(f"{name}.attractor", n), joints)
            for name, joints in owned_joints.items()
        ]
        self._config_forces = [
            (self.DeclareVectorInputPort(f"{name}.config_force", n), owned_joints[name])
            for name in config_forces
        ]
        # A marker's three entries, for each owned marker.
        self._marker_forces = [
            (
                self.DeclareVectorInputPort(f"{name}.marker_forces", 3 * m),
                [3 * i + k for i in owned_markers[name] for k in range(3)],
            )
            for name in marker_forces
        ]
        self.DeclareVectorOutputPort("attractor", n, self._CalcAttractor)
        self.DeclareVectorOutputPort("config_force", n, self._CalcConfigForce)
        self.DeclareVectorOutputPort("marker_forces", 3 * m, self._CalcMarkerForces)

    @staticmethod
    def _Sum(context, inputs, size: int) -> np.ndarray:
        total = np.zeros(size)
        for port, entries in inputs:
            total[entries] += port.Eval(context)[entries]
        return total

    def _CalcAttractor(self, context, output: BasicVector) -> None:
        q_star = self._home.copy()
        for port, joints in self._attractors:
            q_star[joints] = port.Eval(context)[joints]
        output.SetFromVector(q_star)

    def _CalcConfigForce(self, context, output: BasicVector) -> None:
        output.SetFromVector(self._Sum(context, self._config_forces, len(self._home)))

    def _CalcMarkerForces(self, context, output: BasicVector) -> None:
        output.SetFromVector(self._Sum(context, self._marker_forces, output.size()))


def _Owners(
    behaviours: list[Behaviour], what: str, known: list[str], owned
) -> dict[str, list[int]]:
    """Each behaviour's indices among ``known`` of the names ``owned(behaviour)`` lists.

    Raises:
        ValueError: for a name not in ``known`` or claimed by two behaviours (both named).
    """
    owner, indices = {}, {}
    for b in behaviours:
        indices[b.name] = []
        for name in owned(b):
            if name not in known:
                raise ValueError(
                    f"behaviour '{b.name}': unknown {what} '{name}'; MoBeE's {what}s are: "
                    + ", ".join(known)
                )
            if name in owner:
                raise ValueError(
                    f"behaviours '{owner[name]}' and '{b.name}' both claim the {what} '{name}'"
                )
            owner[name] = b.name
            indices[b.name].append(known.index(name))
    return indices


def _ConnectNeeds(builder, declared: dict[str, ClientPorts]) -> None:
    """Connects each behaviour's needed inputs to the output another behaviour offers by the
    same name."""
    offers = {}
    for name, ports in declared.items():
        for offer, port in ports.offers.items():
            if offer in offers:
                raise ValueError(
                    f"behaviours '{offers[offer][0]}' and '{name}' both offer '{offer}'"
                )
            offers[offer] = (name, port)
    for name, ports in declared.items():
        for need, port in ports.needs.items():
            if need not in offers:
                raise ValueError(
                    f"behaviour '{name}' needs '{need}', which no behaviour offers (offered: "
                    + (", ".join(offers) or "none")
                    + ")"
                )
            builder.Connect(offers[need][1], port)


def ComposeBehaviours(parts: StationParts, behaviours: list[Behaviour]) -> ClientPorts:
    """Adds every behaviour and the composer of their attractors and forces (see the module);
    returns the composite's declaration.

    Raises:
        ValueError: in one line, for two behaviours of one name, an unknown or twice-claimed
            joint or marker, or a needed port no behaviour offers.
    """
    names = [b.name for b in behaviours]
    if not behaviours or len(set(names)) < len(names):
        raise ValueError(f"behaviours need names of their own, got {names}")
    mobee = parts.mobee
    joints = _Owners(behaviours, "joint", list(mobee.joints), lambda b: b.joints)
    markers = _Owners(behaviours, "marker", list(mobee.marker_names), lambda b: b.markers)
    declared = {
        b.name: b.add_to_builder(
            dc.replace(parts, prefix=f"{parts.prefix}{b.name}_", joints=tuple(b.joints))
        )
        for b in behaviours
    }
    _ConnectNeeds(parts.builder, declared)
    pushing = [name for name, p in declared.items() if p.marker_forces is not None]
    for name in pushing:
        if not markers[name]:
            raise ValueError(f"behaviour '{name}' pushes markers but owns none: list its markers")
    composer = parts.builder.AddNamedSystem(
        f"{parts.prefix}behaviours",
        BehaviourComposer(
            home=mobee.home,
            num_markers=len(mobee.marker_names),
            owned_joints=joints,
            owned_markers=markers,
            config_forces=[n for n, p in declared.items() if p.config_force is not None],
            marker_forces=pushing,
        ),
    )
    for name, ports in declared.items():
        parts.builder.Connect(ports.attractor, composer.GetInputPort(f"{name}.attractor"))
        for kind in ("config_force", "marker_forces"):
            if getattr(ports, kind) is not None:
                parts.builder.Connect(getattr(ports, kind), composer.GetInputPort(f"{name}.{kind}"))
    hooks = {
        hook: [x for ports in declared.values() for x in Declared(ports, hook)]
        for hook in ("outcome", "action_counters", "data_log", "checkpointed", "world_events")
    }
    return ClientPorts(
        system=composer,
        attractor=composer.GetOutputPort("attractor"),
        marker_forces=composer.GetOutputPort("marker_forces") if pushing else None,
        config_force=composer.GetOutputPort("config_force"),
        **hooks,
    )
