"""A torso that puts the target where the learned reaches work (dissertation ch. 9.4.2).

After ch. 8's learning the reach learner holds a map of how well the arm reaches each target
relative to the shoulder: for a target seen in the learning frame (the shoulder's, placed as it
stands with the torso at home: ``Robot.LearningFrame``), the best predicted reward of a reach
(:func:`ReachMap`: eq. 8.5 over the reaching state-actions). This behaviour owns the torso's
joints; when the target is a new one (it looks every ``period``), it looks at a grid of torso
postures around home, sees where each would put the target in the learning frame, and sets the
torso's attractor to the posture whose map value is highest (among equal values, the one nearest
home; home itself when no posture beats it).
The arm's planner keeps deciding in the shoulder's frame, so the torso's motion does not disturb
it; MoBeE moves the torso as any joint, fields and limits included.

The shoulder's frame depends on the torso's joints only (it is fixed on the chest), so the grid's
transforms are computed once, when the behaviour is built.
"""

from collections.abc import Callable
import dataclasses as dc
import itertools

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from mobee_drake.behaviours.world_target import AddTargetPosition
from mobee_drake.reaching.learner import ReachLearner
from mobee_drake.station.parts import ClientPorts, StationParts

# Map values within this of the best are ties, decided by the distance from home.
_TIE = 1e-9


# The readings of "a map of the reachability of the workspace relative to the shoulder":
# "prediction": the best predicted reward of a reach (eq. 8.5), which far from every recorded
# target tends to eq. 8.5's optimistic prior; "evidence": the best mean reward a reach achieved
# for the recorded targets within EVIDENCE_RADIUS, 0 where none was recorded.
REACH_MAPS = ("prediction", "evidence")
EVIDENCE_RADIUS = 0.05


def ReachMap(learner: ReachLearner, kind: str = "prediction") -> Callable[[np.ndarray], np.ndarray]:
    """The reach map of ``kind`` (one of REACH_MAPS) for each row of an (k, 3) array of
    targets in the learning frame."""
    reaches = range(learner.num_transitions, learner.num_state_actions)
    histories = learner.histories
    if kind == "prediction":
        return lambda targets: np.array(
            [max(histories.Predict(sa, x) for sa in reaches) for x in targets]
        )
    if kind != "evidence":
        raise ValueError(f"unknown reach map '{kind}'; one of {', '.join(REACH_MAPS)}")
    records = [histories.Records(sa) for sa in reaches]

    def Evidence(targets: np.ndarray) -> np.ndarray:
        best = np.zeros(len(targets))
        for recorded, rewards in records:
            if len(rewards) == 0:
                continue
            near = np.linalg.norm(targets[:, None] - recorded[None], axis=2) <= EVIDENCE_RADIUS
            counts = near.sum(axis=1)
            means = np.divide(near @ rewards, counts, out=np.zeros(len(targets)), where=counts > 0)
            best = np.maximum(best, means)
        return best

    return Evidence


class TorsoPlacement(LeafSystem):
    """Chooses the torso posture that puts the target best on the reach map (see the module).

    .. pydrake_system::

        name: TorsoPlacement

        input_ports:
        - target

        output_ports:
        - attractor
    """

    def __init__(
        self,
        *,
        plant,
        mobee,
        joints: list[str],
        shoulder_joint: str,
        reach_map: Callable[[np.ndarray], np.ndarray],
        postures: np.ndarray,
        period: float,
    ):
        super().__init__()
        self._map, self._home, self._joints = reach_map, mobee.home, list(joints)
        self._owned = np.array([mobee.joint_index(j) for j in joints], dtype=int)
        self._postures = np.asarray(postures, dtype=float)
        n = len(self._home)
        context = plant.CreateDefaultContext()
        shoulder = plant.GetJointByName(shoulder_joint).frame_on_parent()

        def Shoulder(posture):
            q = self._home.copy()
            q[self._owned] = posture
            plant.SetPositions(context, mobee.PlantPositions(q))
            return shoulder.CalcPoseInWorld(context)

        at_home = Shoulder(self._home[self._owned])
        # Each posture's map from a world point to the learning frame, as 3 x 4 matrices.
        self._to_learning = np.array(
            [(at_home @ Shoulder(p).inverse()).GetAsMatrix34() for p in self._postures]
        )
        self._distance = np.linalg.norm(self._postures - self._home[self._owned], axis=1)
        self._target = self.DeclareVectorInputPort("target", 3)
        self._posture = self.DeclareDiscreteState(self._home[self._owned])
        # The target the posture was chosen for (NaN: none yet): a choice per target.
        self._chosen_for = self.DeclareDiscreteState(np.full(3, np.nan))
        self.DeclarePeriodicDiscreteUpdateEvent(period, 0.0, self._Choose)
        self.DeclareVectorOutputPort(
            "attractor", n, self._CalcAttractor, prerequisites_of_calc={self.xd_ticket()}
        )

    def Scores(self, target_W: np.ndarray) -> np.ndarray:
        """The map's value of ``target_W`` (world) as each posture of the grid would see it."""
        seen = self._to_learning[:, :, :3] @ target_W + self._to_learning[:, :, 3]
        return self._map(seen)

    def _Choose(self, context, discrete_state) -> None:
        target = self._target.Eval(context)
        if np.array_equal(target, context.get_discrete_state(self._chosen_for).value()):
            return  # (the same target: the same choice)
        scores = self.Scores(target)
        best = np.flatnonzero(scores >= scores.max() - _TIE)
        chosen = best[np.argmin(self._distance[best])]
        discrete_state.set_value(self._posture, self._postures[chosen])
        discrete_state.set_value(self._chosen_for, target)

    def _CalcAttractor(self, context, output: BasicVector) -> None:
        q_star = self._home.copy()
        q_star[self._owned] = context.get_discrete_state(self._posture).value()
        output.SetFromVector(q_star)

    def Outcome(self, context) -> dict:
        """The torso's chosen posture (degrees per joint)."""
        posture = np.degrees(context.get_discrete_state(self._posture).value())
        return {"posture_deg": {j: float(a) for j, a in zip(self._joints, posture)}}


def PostureGrid(mobee, joints: list[str], levels: int, range_fraction: float) -> np.ndarray:
    """(levels^k, k): the torso postures tried: per joint, ``levels`` angles evenly over
    ``range_fraction`` of its range, centred on home and kept within its limits."""
    lower, upper = mobee.position_limits
    axes = []
    for joint in joints:
        i = mobee.joint_index(joint)
        half = range_fraction * (upper[i] - lower[i]) / 2
        home = mobee.home[i]
        axes.append(np.clip(np.linspace(home - half, home + half, levels), lower[i], upper[i]))
    return np.array(list(itertools.product(*axes)))


@dc.dataclass
class PlaceTorso:
    """A client that places the torso for the arm's reaches (see the module): in a
    :class:`~mobee_drake.station.composition.Behaviour` on the torso's joints."""

    # The reach map (e.g. ReachMap(learner)): targets (k, 3) in the learning frame -> values (k).
    reach_map: Callable[[np.ndarray], np.ndarray]
    # A world object's name, or "" for the "target" another behaviour offers.
    target: str = ""
    # The joint whose place on its parent body is the shoulder's frame.
    shoulder_joint: str = "r_shoulder_pitch"
    # The grid: angles per joint, over this share of each joint's range; and how often it
    # chooses (s).
    levels: int = 5
    range_fraction: float = 0.5
    period: float = 0.5

    def AddToBuilder(self, parts: StationParts) -> ClientPorts:
        joints = parts.OwnedJoints()
        system = parts.builder.AddNamedSystem(
            f"{parts.prefix}torso_placement",
            TorsoPlacement(
                plant=parts.plant,
                mobee=parts.mobee,
                joints=joints,
                shoulder_joint=self.shoulder_joint,
                reach_map=self.reach_map,
                postures=PostureGrid(parts.mobee, joints, self.levels, self.range_fraction),
                period=self.period,
            ),
        )
        needs = {}
        if self.target:
            parts.builder.Connect(AddTargetPosition(parts, self.target), system.get_input_port())
        else:
            needs["target"] = system.get_input_port()
        return ClientPorts(
            system=system, attractor=system.get_output_port(), outcome=system, needs=needs
        )
