"""The reach learner on a space that reshapes itself (ch. 9.4.5).

A round of :class:`~mobee_drake.planning.space_maintenance.Maintenance` reads the learner's MDP
as an explorer's model (its outcome counts; the tries of each transition are the outcomes it
observed), and the states the learner favours: "certain states, from which reach actions worked
well to a wide range of target locations" (ch. 9.4.5), here the ``top`` states whose reaches
have the highest mean reward over at least ``min_records`` recorded targets. The edit moves the
MDP's counts (:func:`~mobee_drake.planning.space_maintenance.CarryExplorer`) and the learner
(:meth:`~mobee_drake.reaching.learner.ReachLearner.Reshape`) onto the new space.

New transitions start with Alg. 6's optimistic counts; with ``learn_mdp`` (ch. 9.4.1) the
learner's own transitions then teach the model what they do, without it they keep that prior.
"""

import numpy as np

from mobee_drake.planning.explorers import Explorer, ExplorerConfig, ObservedOutcomes
from mobee_drake.planning.space_maintenance import CarryExplorer, Maintenance
from mobee_drake.reaching.learner import ReachLearner


def ModelView(learner: ReachLearner, config: ExplorerConfig | None = None) -> Explorer:
    """The learner's MDP as an explorer's model (``config``: the initialisation it was learned
    with, 50-50 by default): its counts, and as tries the outcomes each transition observed."""
    view = Explorer(learner.space, config or ExplorerConfig())
    view.transitions.counts[...] = learner.model.counts
    view.tries[...] = ObservedOutcomes(view).sum(axis=1)
    return view


def FavouredStates(learner: ReachLearner, top: int, min_records: int) -> list[int]:
    """The ``top`` states whose reaches' mean reward is highest, among those with at least
    ``min_records`` records (fewer if fewer qualify), best first."""
    means = {}
    for state in range(learner.space.num_states):
        _, rewards = learner.histories.Records(learner.Reach(state))
        if len(rewards) >= min_records:
            means[state] = float(np.mean(rewards))
    return sorted(means, key=lambda s: -means[s])[:top]


def MaintainReachSpace(
    learner: ReachLearner,
    maintenance: Maintenance,
    state: int,
    done: int,
    *,
    top: int = 3,
    min_records: int = 5,
) -> bool:
    """A round of ``maintenance`` on the learner's space, the robot in ``state`` after ``done``
    problem-tries; whether the space changed (then the learner is on the new one)."""
    view = ModelView(learner)
    favoured = FavouredStates(learner, top, min_records)
    edit = maintenance.Plan(view, state, done, favoured)
    if edit is None:
        return False
    carried = CarryExplorer(view, edit.space, edit.state_index, edit.action_index)
    learner.Reshape(edit.space, edit.state_index, edit.action_index, carried.transitions.counts)
    return True


def ObserveTransitions(learner: ReachLearner, maintenance: Maintenance, since: int) -> None:
    """Shows ``maintenance`` the learner's transitions logged from entry ``since`` on (the
    chains that ``shortcut`` counts; a reach leaves the robot where it was)."""
    for _, _, sa, state, outcome, *_ in learner.log[since:]:
        if 0 <= sa < learner.num_transitions:
            maintenance.Observe(learner.space, state, sa, outcome)
