"""What a run achieved, besides its speed and safety: the figures of its summary.

- The attractor's: how far the robot ended from it, as the largest joint error, and how far each
  marker ended from where it would be at the attractor (its goal).
- The client's own, from the system its ``ClientPorts`` declare as ``outcome``
  the exploring agents' actions, state-actions tried and value-iteration residual; the
  state-action executor's finished actions and its last reach's distance to the target.
"""

import numpy as np

from mobee_drake.station.builder import Station


def AttractorOutcome(station: Station, context) -> dict:
    """How far the robot is from MoBeE's attractor in the root ``context``."""
    mobee, n = station.mobee, len(station.mobee.joints)
    q = station.robot_state.Eval(context)[:n]
    q_star = station.attractor.Eval(context)
    error = np.degrees(np.abs(q - q_star))
    worst = int(np.argmax(error))
    at_goal = mobee.CreateDefaultContext()  # The markers' positions at the attractor.
    mobee.GetInputPort("state").FixValue(at_goal, np.concatenate([q_star, np.zeros(n)]))
    goals = mobee.GetOutputPort("marker_positions").Eval(at_goal).reshape(-1, 3)
    now = (
        mobee.GetOutputPort("marker_positions")
        .Eval(mobee.GetMyContextFromRoot(context))
        .reshape(-1, 3)
    )
    return {
        "largest_joint_error_deg": float(error[worst]),
        "largest_error_joint": mobee.joints[worst],
        "marker_distance_to_goal_m": {
            name: float(d)
            for name, d in zip(mobee.marker_names, np.linalg.norm(now - goals, axis=1))
        },
    }


def RunOutcome(station: Station, context) -> dict:
    """The attractor's outcome and, if the client has one, the client's."""
    outcome = {"attractor": AttractorOutcome(station, context)}
    client = station.client_ports.outcome if station.client_ports is not None else None
    if client is not None:
        outcome["client"] = client.Outcome(client.GetMyContextFromRoot(context))
    return outcome
