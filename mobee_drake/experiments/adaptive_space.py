"""Experiment: a state-action space that reshapes itself (ch. 9.4.5; docs/adaptive_space.md).

The curious agent of ch. 7 explores an arm (``--robots``: :mod:`~mobee_drake.experiments.arms`,
the iCub's right shoulder and elbow, the Katana's first four joints among its obstacles) for
``--actions`` actions on a fixed space and on the same space maintained by the rules of
:mod:`mobee_drake.planning.space_maintenance`, ``--seeds`` runs of each, paired by seed (the same
generator). The spaces (``--spaces``): ch. 7.3's rank-4 lattice at 12.5-87.5 % (256 states; on
the iCub its corner states beyond the shoulder's cable constraints are never entered), ch. 7.2's
rank-3 lattice (81 states), and ``trm``: a task-relevant roadmap over the valid configurations
themselves (:mod:`mobee_drake.trm.configuration`; ``--trm-spacing``, at most ``--trm-states``
states, the rank-4 lattice's number by default), built once per arm by the battery's job
``<robot>_roadmap``, its vertices the states and its edges the actions both ways. The ch. 8 part
(``--part reaching``) is :mod:`mobee_drake.experiments.adaptive_space_reaching`.

Per run, at the end:

- *coverage*: the share of a fixed sample of the arm's valid configurations (within the joint
  limits, every constraint clause satisfied, no collision; ``arms.VALID_SAMPLES`` of them, drawn
  uniformly in fractions of each joint's range) within ``--radius`` (fractions of range; by
  default half the rank-4 lattice's spacing: at the spacing itself a run of 2000 actions
  leaves no valid configuration uncovered) of a configuration in which one of the run's actions
  ended (:attr:`~mobee_drake.planning.supervisor.AgentRecord.settled`, where the arm was, not
  the state it was counted in): how much of what the arm can do the agent has been near, whatever
  its space and however that space was cut;
- *dispersion*: the mean distance (fractions of range) from those valid configurations to the
  nearest configuration in which an action ended (no threshold);
- *prediction error*: ``--tests`` state-actions of states the robot was in (an action started
  or ended there: as the model shows, and as the maintenance saw it where ``drop`` made the
  model forget; :attr:`~mobee_drake.planning.space_maintenance.Maintenance.entered`), drawn at
  random, run once each on a fresh robot (put in the state's centre first; skipped if it does
  not get there): one minus the probability the learned model gave the outcome (held out: the
  model does not learn from them);
- *state-actions tried*: the share of the space's state-actions tried at least once (ch. 7.2's
  coverage, of the space as it ended);
- the space's states and state-actions at the end, its changes by rule, the robot's simulated
  time per action, the wall time and the penetrating periods.

Maintained minus fixed on each space, and the roadmap, fixed and maintained, minus the fixed
rank-4 lattice, are compared paired by seed in two families, each Holm-corrected over its
comparisons: what was learned (coverage, dispersion, prediction error, state-actions tried; the
shares' differences in percentage points, dispersion's in thousandths of range) and what it cost
(robot seconds per action, wall seconds per run). No round is made at the run's last action count
(``MaintenanceConfig.until``): the measures see the space the agent explored in its last
``--every`` actions, not one just reshaped. The command, its figures and the battery's stages are
:mod:`mobee_drake.experiments.adaptive_space_command`.
"""

import dataclasses as dc

import numpy as np
import scipy.spatial

from mobee_drake.experiments.adaptive_space_report import (
    BySetting,
    ChangesCell,
    NearnessLines,
    SpaceComparisons,
)
from mobee_drake.experiments.arms import (
    TARGET_RADIUS,
    Arms,
    RoadmapFolder,
    RoadmapLines,
    ValidConfigurations,
)
from mobee_drake.experiments.battery import RunFolder
from mobee_drake.experiments.ch7_model_learning import ExploreJob, Stop
from mobee_drake.experiments.ch8_reaching import ReachRobot
from mobee_drake.experiments.exploration import ExplorationRun
from mobee_drake.planning.explorers import ExplorerConfig, LoadAgentModel
from mobee_drake.planning.space_maintenance import (
    RULES,
    ChangesByRule,
    MaintenanceConfig,
    VisitedStates,
)
from mobee_drake.planning.supervisor import ExploringAgent, SavedMaintenance, SavedSettled

# The lattices compared: their levels (fractions of each joint's range; rank3 is ch. 8's); and
# "trm", a roadmap over the valid configurations (mobee_drake.trm.configuration), built once per
# battery.
LATTICES = {"rank4": [0.125, 0.375, 0.625, 0.875], "rank3": [0.25, 0.5, 0.75]}
SPACES = (*LATTICES, "trm")
AGENT = "right_arm"


@dc.dataclass
class AdaptiveSpaceRun:
    """One run: a robot, a space, fixed or maintained, a seed (see the module for the
    measures)."""

    robot: str
    space: str
    condition: str
    seed: int
    actions: int
    coverage: float
    dispersion: float
    prediction_error: float
    tests: int
    tried_share: float
    states: int
    state_actions: int
    changes: dict[str, int]
    robot_seconds_per_action: float
    wall_seconds: float
    penetrating_steps: int


def Nearest(settled: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """Per configuration of ``valid``, its distance to the nearest configuration in which an
    action ended (``settled``, both in fractions of range; inf: none)."""
    if not len(settled):
        return np.full(len(valid), np.inf)
    return scipy.spatial.cKDTree(settled).query(valid)[0]


def PredictionError(
    robot: str, explorer, visited: np.ndarray, tests: int, seed: int
) -> tuple[float, int]:
    """(the mean of one minus the model's probability of each held-out test's outcome, the
    tests run): see the module. The tests are actions of the states the robot was in
    (``visited``, per state) and run on a fresh robot of the arm ``robot``, the reach learner's
    (its state-action executor)."""
    space = explorer.space
    visited = np.flatnonzero(visited)
    candidates = np.flatnonzero(np.isin(space.action_state, visited))
    rng = np.random.default_rng(seed)
    chosen = rng.choice(candidates, size=min(tests, len(candidates)), replace=False)
    fresh = ReachRobot(space, TARGET_RADIUS, robot=robot)
    T = explorer.transitions.Probabilities()
    errors = []
    for sa in chosen:
        state = int(space.action_state[sa])
        if fresh.Transition(state) != state:
            continue  # (the robot could not be put there)
        outcome = fresh.Transition(int(space.action_goal[sa]))
        errors.append(1.0 - T[sa, outcome])
    return (float(np.mean(errors)) if errors else float("nan")), len(errors)


def AdaptiveSpaceJob(
    run: RunFolder, *, robot: str, space: str, condition: str, seed: int, actions: int,
    tests: int, radius: float, maintenance: MaintenanceConfig,
) -> dict:  # fmt: skip
    """The battery job: one run (see the module)."""
    arm = Arms()[robot]
    agent = ExploringAgent(
        name=AGENT,
        joints=list(arm.joints),
        maintenance=dc.replace(maintenance, until=actions) if condition == "maintained" else None,
    )
    if space in LATTICES:
        agent.levels = LATTICES[space]
    else:
        agent.roadmap = str(RoadmapFolder(run.path.parent, robot))
    explored = ExplorationRun.FromJson(
        ExploreJob(
            run,
            agents=[agent],
            stop=Stop(actions=actions),
            labels=dict(robot=robot, space=space, condition=condition, seed=seed),
            objects=arm.objects,
            random_seed=seed,
            chunk=5.0,
            keep_model=True,
            robot=None if robot == "icub" else arm.robot,  # (the iCub's upper body, as ch. 7)
        )
    )
    folder = str(run.path / "model")
    explorer = LoadAgentModel(folder, AGENT, ExplorerConfig())
    maintenance = SavedMaintenance(folder, AGENT, MaintenanceConfig())
    visited = VisitedStates(explorer)  # (and those the model forgot when `drop` removed all
    if maintenance is not None:  # of a state's tried transitions)
        visited |= maintenance.entered
    error, tested = PredictionError(robot, explorer, visited, tests, seed)
    done = explored.actions[0]
    nearest = Nearest(SavedSettled(folder, AGENT), ValidConfigurations(arm))
    return dc.asdict(
        AdaptiveSpaceRun(
            robot=robot,
            space=space,
            condition=condition,
            seed=seed,
            actions=done,
            coverage=float(np.mean(nearest <= radius)),
            dispersion=float(np.mean(nearest)),
            prediction_error=error,
            tests=tested,
            tried_share=float(np.mean(explorer.tries > 0)),
            states=explorer.space.num_states,
            state_actions=explorer.space.num_state_actions,
            changes=ChangesByRule(c.rule for c in (maintenance.changes if maintenance else ())),
            robot_seconds_per_action=explored.simulated_seconds / max(done, 1),
            wall_seconds=explored.wall_seconds,
            penetrating_steps=explored.penetrating_steps,
        )
    )


# What a run learned, and what it cost: each a family of comparisons of its own. The shares'
# differences in percentage points; dispersion's (a distance in the joints' fractions of range,
# the table's unit) in thousandths of it (the maintained lattices' differ by a few).
_MEASURES = {
    "coverage (percentage points)": lambda r: 100 * r.coverage,
    "dispersion (thousandths of range)": lambda r: 1000 * r.dispersion,
    "prediction error (percentage points)": lambda r: 100 * r.prediction_error,
    "state-actions tried (percentage points)": lambda r: 100 * r.tried_share,
}
_COSTS = {
    "robot s per action": lambda r: r.robot_seconds_per_action,
    "wall s per run": lambda r: r.wall_seconds,
}


# A run's setting, its condition last.
SETTING = ("robot", "space", "condition")


def _Row(key: tuple, rs: list[AdaptiveSpaceRun]) -> str:
    return (
        f"| {' | '.join(key)} | {len(rs)} | {np.mean([r.actions for r in rs]):.0f} | "
        f"{100 * np.mean([r.coverage for r in rs]):.1f} % | "
        f"{np.mean([r.dispersion for r in rs]):.3f} | "
        f"{np.nanmean([r.prediction_error for r in rs]):.3f} "
        f"({np.mean([r.tests for r in rs]):.0f}) | "
        f"{100 * np.mean([r.tried_share for r in rs]):.0f} % | "
        f"{np.mean([r.states for r in rs]):.0f} | "
        f"{np.mean([r.state_actions for r in rs]):.0f} | {ChangesCell(rs)} | "
        f"{np.mean([r.robot_seconds_per_action for r in rs]):.2f} | "
        f"{sum(r.penetrating_steps for r in rs)} | "
        f"{np.mean([r.wall_seconds for r in rs]):.0f} |"
    )


def Report(
    runs: list[AdaptiveSpaceRun],
    roadmaps: dict[str, dict],
    command: str,
    nearness: dict[str, dict[str, float]] | None = None,
) -> str:
    """The report's table, the trm spaces' roadmaps (``roadmaps``: per robot, its roadmap
    job's result), how near each space's states lie to the valid configurations
    (``nearness``, see :func:`~mobee_drake.experiments.adaptive_space_report.NearnessLines`)
    and the paired comparisons (markdown)."""
    group = BySetting(runs, SETTING)
    lines = [
        "| robot | space | condition | runs | actions | coverage | dispersion "
        "| prediction error (tests) | state-actions tried | states | state-actions "
        f"| changes ({'/'.join(RULES)}) | robot s per action | penetrating periods "
        "| wall s per run |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|",
        *(_Row(key, rs) for key, rs in group.items()),
    ]
    lines += RoadmapLines(roadmaps) + NearnessLines(nearness or {})
    lines += SpaceComparisons(group, "rank4", _MEASURES, "what was learned")
    lines += SpaceComparisons(group, "rank4", _COSTS, "what it cost")
    return "\n".join(lines) + f"\n\nCommand: `{command}`."
