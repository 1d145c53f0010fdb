"""A task-relevant roadmap over a robot's configurations themselves (ch. 3.3, 9.4.5).

The task is to be anywhere the robot may be: the task space is the searched joints' positions as
fractions of their ranges (:class:`~mobee_drake.trm.task_space.JointFractions`, the units of an
MDP's states), and the only cost is to collide with nothing (every candidate must also keep the
joint limits and the constraint clauses, Alg. 4's IS_VALID). Alg. 4 then spreads vertices about
``spacing`` apart over the valid configurations, and only over them: an MDP state space whose
states are all where the robot can be, in place of a lattice whose corners may lie beyond the
shoulder's cable constraints.
"""

import numpy as np

from mobee_drake.ngik.costs import CollisionCost
from mobee_drake.ngik.kinematic_model import KinematicModel
from mobee_drake.ngik.solver import IkProblem
from mobee_drake.trm.roadmap import BuildTrm, TaskRelevantRoadmap, TrmConfig
from mobee_drake.trm.task_space import JointFractions, TaskSpace


def BuildConfigurationRoadmap(
    robot,
    joints: list[str],
    spacing: float,
    max_vertices: int,
    *,
    objects=(),
    seed: int = 0,
    progress=None,
) -> TaskRelevantRoadmap:
    """The roadmap over ``joints``' valid configurations of ``robot`` (a scenario's robot
    configuration) among ``objects``, grown from home (see the module)."""
    model = KinematicModel(robot, list(objects))
    columns = tuple(model.JointIndex(j) for j in joints)
    problem = IkProblem(model, [CollisionCost()], joints=list(joints))
    task = TaskSpace(
        (
            JointFractions(
                columns,
                tuple(model.lower[list(columns)].tolist()),
                tuple(model.upper[list(columns)].tolist()),
            ),
        )
    )
    config = TrmConfig(spacing=spacing, max_vertices=max_vertices, sigma=0.3)
    return BuildTrm(
        problem, task, model.home, config, np.random.default_rng(seed), progress=progress
    )
