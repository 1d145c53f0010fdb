"""The reach learner on a space that reshapes itself (ch. 9.4.5).

A round of :class:`~mobee_drake.planning.space_maintenance.Maintenance` reads the learner's MDP
as an explorer's model (its outcome counts; the tries of each transition are the outcomes it
observed), and the states the learner favours: "certain states, from which reach actions worked
well to a wide range of target locations" (ch. 9.4.5), here the ``develop_top`` states whose
reaches have the highest mean reward, among those recorded for at least
``develop_min_targets`` different targets.
The edit moves the MDP's counts (:func:`~mobee_drake.planning.space_maintenance.CarryExplorer`)
and the learner (:meth:`~mobee_drake.reaching.learner.ReachLearner.Reshape`) onto the new
space.

New transitions start with Alg. 6's optimistic counts; with ``learn_mdp`` (ch. 9.4.1) the
learner's own transitions then teach the model what they do, without it they keep that prior.
"""

import numpy as np

from mobee_drake.planning.explorers import Explorer, ExplorerConfig, ObservedOutcomes
from mobee_drake.planning.space_maintenance import (
    CarryExplorer,
    ChangesByRule,
    Maintenance,
    MaintenanceConfig,
)
from mobee_drake.planning.state_space import StateActionSpace
from mobee_drake.reaching.learner import ReachLearner


def ModelView(learner: ReachLearner) -> Explorer:
    """The learner's MDP as an explorer's model under the initialisation ch. 8's MDPs are
    learned with (the default's): its counts, and as tries the outcomes each transition
    observed."""
    view = Explorer(learner.space, ExplorerConfig())
    view.transitions.counts[...] = learner.model.counts
    view.tries[...] = ObservedOutcomes(view).sum(axis=1)
    return view


def FavouredStates(learner: ReachLearner, top: int, min_targets: int) -> list[int]:
    """The ``top`` states whose reaches' mean reward is highest, among those whose reaches
    were recorded for at least ``min_targets`` different targets ("a wide range of target
    locations", ch. 9.4.5; fewer states if fewer qualify), best first."""
    means = {}
    for state in range(learner.space.num_states):
        targets, rewards = learner.histories.Records(learner.Reach(state))
        if len(rewards) and len(np.unique(targets, axis=0)) >= min_targets:
            means[state] = float(np.mean(rewards))
    return sorted(means, key=lambda s: -means[s])[:top]


def LoggedStates(learner: ReachLearner) -> list[int]:
    """The states the learner's log shows the robot in (where each action started and ended;
    the MDP's counts miss its reaches, and moves that felt an object, ch. 9.4.1)."""
    return sorted({int(s) for entry in learner.log for s in entry[3:5] if s >= 0})


def MaintainReachSpace(
    learner: ReachLearner, maintenance: Maintenance, state: int, done: int
) -> bool:
    """A round of ``maintenance`` on the learner's space, the robot in ``state`` after ``done``
    problem-tries (its favoured states by the config's ``develop_top`` and
    ``develop_min_targets``); whether the space changed (then the learner is on the new
    one)."""
    config = maintenance.config
    view = ModelView(learner)
    favoured = FavouredStates(learner, config.develop_top, config.develop_min_targets)
    edit = maintenance.Plan(view, state, done, favoured, LoggedStates(learner))
    if edit is None:
        return False
    learner.Reshape(edit, CarryExplorer(view, edit).transitions.counts)
    return True


def ObserveTransitions(learner: ReachLearner, maintenance: Maintenance, since: int) -> None:
    """Shows ``maintenance`` the learner's transitions logged from entry ``since`` on (the
    chains that ``shortcut`` counts; a reach leaves the robot where it was)."""
    for _, _, sa, state, outcome, *_ in learner.log[since:]:
        if 0 <= sa < learner.num_transitions:
            maintenance.Observe(learner.space, state, sa, outcome)


class ReachSpaceKeeper:
    """A reach learner's space maintained through a run: a round of ``config``'s rules every
    ``config.every`` problem-tries (here problem-tries, not actions), and the run's checkpoint
    part (the space, the chain counts, the changes). The robot acts on the learner's space: a
    :class:`~mobee_drake.reaching.robot.SimulatedRobot`'s ``space`` follows it."""

    def __init__(self, config: MaintenanceConfig, num_states: int):
        self.maintenance = Maintenance(config, num_states)

    def Observe(self, learner: ReachLearner, since: int) -> None:
        """After a problem-try: its actions, logged from entry ``since``, shown to the
        maintenance."""
        ObserveTransitions(learner, self.maintenance, since)

    def Maintain(self, learner: ReachLearner, robot, done: int) -> None:
        """A round, if one is due after ``done`` problem-tries. A run calls it after the
        evaluation of a stage at ``done`` (which sees the space as it was learned) and before
        the next try, never after the last."""
        if self.maintenance.Due(done):
            if MaintainReachSpace(learner, self.maintenance, robot.State(), done):
                robot.space = learner.space

    def ToArrays(self, learner: ReachLearner) -> tuple[dict[str, np.ndarray], dict]:
        """The checkpoint's part: the learner's space and MDP counts, and the maintenance."""
        chains, data = self.maintenance.ToData()
        space = learner.space
        arrays = dict(
            space_centres=space.centres,
            space_action_state=space.action_state,
            space_action_goal=space.action_goal,
            space_counts=learner.model.counts,
            maintenance_chains=chains,
        )
        return arrays, data

    def Restore(self, learner: ReachLearner, robot, arrays, data: dict) -> None:
        """Puts a fresh ``learner`` (before its LoadArrays) and ``robot`` on the saved space."""
        space = StateActionSpace(
            np.asarray(arrays["space_centres"]),
            np.asarray(arrays["space_action_state"]),
            np.asarray(arrays["space_action_goal"]),
        )
        learner.PutOnSpace(space, np.asarray(arrays["space_counts"]))
        robot.space = learner.space
        self.maintenance = Maintenance.FromData(
            self.maintenance.config, arrays["maintenance_chains"], data
        )

    def Summary(self, learner: ReachLearner) -> dict:
        """The space at the end: states, state-actions (transitions) and changes by rule."""
        return dict(
            states=learner.space.num_states,
            transitions=learner.num_transitions,
            changes=ChangesByRule(c.rule for c in self.maintenance.changes),
        )
