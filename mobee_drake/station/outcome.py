"""What a run achieved, besides its speed and safety: the figures of its summary.

- The attractor's: how far the robot ended from it, as the largest joint error, and how far each
  marker the task involves ended from where it would be at the attractor (its goal). A marker is
  involved when the attractor puts it elsewhere than the robot's home does.
- The targets': for each object with the ``target`` role, the involved marker closest to it, its
  distance to the target's surface at the end, and whether that is within reach
  (:data:`TARGET_REACHED`).
- The world events applied: the scenario's scripted ones, in order, and how many a client
  requested.
- The client's own, from the system its ``ClientPorts`` declare as ``outcome``
  the exploring agents' actions, state-actions tried and value-iteration residual; the
  state-action executor's finished actions and its last reach's distance to the target.
"""

import numpy as np

from mobee_drake.station.builder import Station
from mobee_drake.station.parts import Declared
from mobee_drake.world.point_distance import SignedDistance

# A marker the attractor moves less than this (m) from its home position is not part of the task.
INVOLVED_MARKER = 1e-3
# A marker this close to a target's surface (m), or inside it, has reached it.
TARGET_REACHED = 0.01


def _MarkerPositions(mobee, q: np.ndarray) -> np.ndarray:
    """The markers' positions (rows) with the robot at rest at ``q``."""
    context = mobee.CreateDefaultContext()
    mobee.GetInputPort("state").FixValue(context, np.concatenate([q, np.zeros(len(q))]))
    return mobee.GetOutputPort("marker_positions").Eval(context).reshape(-1, 3)


def InvolvedMarkers(station: Station, context) -> list[int]:
    """The markers the attractor of the root ``context`` moves away from their home positions."""
    mobee = station.mobee
    moved = _MarkerPositions(mobee, station.attractor.Eval(context)) - _MarkerPositions(
        mobee, mobee.home
    )
    return [int(i) for i in np.flatnonzero(np.linalg.norm(moved, axis=1) > INVOLVED_MARKER)]


def AttractorOutcome(station: Station, context) -> dict:
    """How far the robot is from MoBeE's attractor in the root ``context``."""
    mobee, n = station.mobee, len(station.mobee.joints)
    q = station.robot_state.Eval(context)[:n]
    q_star = station.attractor.Eval(context)
    error = np.degrees(np.abs(q - q_star))
    worst = int(np.argmax(error))
    goals = _MarkerPositions(mobee, q_star)
    now = _MarkerPositions(mobee, q)
    return {
        "largest_joint_error_deg": float(error[worst]),
        "largest_error_joint": mobee.joints[worst],
        "marker_distance_to_goal_m": {
            mobee.marker_names[i]: float(np.linalg.norm(now[i] - goals[i]))
            for i in InvolvedMarkers(station, context)
        },
    }


def TargetOutcome(station: Station, context) -> dict:
    """Per target object: the closest involved marker (any marker if none is involved), its
    distance to the target's surface (m, negative inside) and whether it reached it."""
    mobee, n = station.mobee, len(station.mobee.joints)
    markers = InvolvedMarkers(station, context) or list(range(len(mobee.marker_names)))
    now = _MarkerPositions(mobee, station.robot_state.Eval(context)[:n])
    targets = {}
    for name, (_, role, shape, X_WO) in station.world.Objects(context).items():
        if role != "target":
            continue
        distance, closest = min((SignedDistance(shape, X_WO, now[i]), i) for i in markers)
        targets[name] = {
            "reached": bool(distance <= TARGET_REACHED),
            "marker": mobee.marker_names[closest],
            "distance_m": distance,
        }
    return targets


_ARTICLES = {"obstacle": "an", "target": "a", "ghost": "a"}


def TargetLines(targets: dict) -> list[str]:
    """The targets' outcome as the summary prints it, a line per target."""
    lines = []
    for name, t in targets.items():
        d = 100 * t["distance_m"]
        where = f"{-d:.1f} cm inside it" if d < 0 else f"{d:.1f} cm from its surface"
        verdict = "reached" if t["reached"] else f"not reached (within {100 * TARGET_REACHED:g} cm)"
        lines.append(f"{name}: {verdict}: {t['marker']} ended {where}")
    return lines


def WorldEventsOutcome(station: Station, context) -> list[str]:
    """The world events applied by the time of the root ``context``, one line each."""
    ledger = station.event_ledger
    counts = ledger.Counts(ledger.GetMyContextFromRoot(context)).astype(int)
    lines = []
    for event in station.scripted_events[: counts[0]]:
        changes = ([f"becomes {_ARTICLES[event.role]} {event.role}"] if event.role else []) + (
            [f"moves to {[round(float(x), 4) for x in event.position]}"] if event.position else []
        )
        lines.append(f"{event.time:g} s: {event.object} {' and '.join(changes)}")
    if counts[1:].sum():
        lines.append(f"requested by the client: {counts[1:].sum()}")
    return lines


def RunOutcome(station: Station, context) -> dict:
    """The attractor's outcome, the targets' and the world events applied, if there are any,
    and, if the client has one, the client's."""
    outcome = {"attractor": AttractorOutcome(station, context)}
    targets = TargetOutcome(station, context)
    if targets:
        outcome["targets"] = targets
    events = WorldEventsOutcome(station, context)
    if events:
        outcome["world_events"] = events
    clients = Declared(station.client_ports, "outcome") if station.client_ports else []
    figures = {c.get_name(): c.Outcome(c.GetMyContextFromRoot(context)) for c in clients}
    if len(figures) == 1:
        (outcome["client"],) = figures.values()
    elif figures:  # behaviours composed: each under its system's name
        outcome["client"] = figures
    return outcome
