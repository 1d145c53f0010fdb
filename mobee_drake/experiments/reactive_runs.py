"""The reactive benchmark's measurements (:mod:`mobee_drake.experiments.bench_reactive`): each
run as a typed :class:`RunResult`, each controller over the tasks as a
:class:`ControllerSummary`."""

from collections.abc import Callable
import dataclasses as dc

import numpy as np

from mobee_drake.experiments.reactive_controllers import ReactiveController, Trajectory
from mobee_drake.experiments.reactive_tasks import PERIOD, QUERY_DISTANCE, ReachTask, TaskScene
from mobee_drake.station.safety import SELF

# Reached: the palm within this distance of the goal's palm position (m); counted by EARLY (s)
# and by the horizon.
REACHED = 0.02
EARLY = 5.0
HORIZON = 15.0
# A joint limit or a clause is broken when a posture is beyond it by more than this (rad).
LIMIT_TOLERANCE = 1e-9


@dc.dataclass
class RunResult:
    """One controller on one task (distances in m, times in s, angles in rad)."""

    controller: str
    task: str
    kind: str
    # The first time the palm was within REACHED of the goal's palm position (None: never).
    reached_at: float | None
    final_error: float
    # The least signed distance of the robot's solids to the obstacles and to themselves over
    # the run (QUERY_DISTANCE when never closer).
    obstacle_clearance: float
    self_clearance: float
    # Periods in which two solids penetrated (a signed distance < 0).
    penetrating_steps: int
    # Periods that broke a clause of MoBeE's constraints or a joint limit, and the worst depth.
    violating_steps: int
    worst_violation: float
    peak_speed: float  # rad/s, the fastest joint
    step_seconds: np.ndarray = dc.field(repr=False)
    failed_steps: int = 0
    palm_error: np.ndarray = dc.field(default_factory=lambda: np.zeros(0), repr=False)


def MeasureRun(
    scene: TaskScene, task: ReachTask, trajectory: Trajectory, controller: str
) -> RunResult:
    """Replays ``trajectory`` on ``scene`` with the task's objects and measures it."""
    scene.SetObjects(task.objects)
    lower, upper = scene.mobee.position_limits
    clauses = scene.mobee.clauses
    errors = np.empty(len(trajectory.q))
    obstacle = clearance_self = QUERY_DISTANCE
    penetrating = violating = 0
    worst = 0.0
    for k, q in enumerate(trajectory.q):
        scene.Pose(q)
        errors[k] = np.linalg.norm(scene.Palm() - task.goal_palm)
        closest = scene.Clearances()
        here_self = closest.pop(SELF, QUERY_DISTANCE)
        here_obstacle = min(closest.values(), default=QUERY_DISTANCE)
        obstacle, clearance_self = min(obstacle, here_obstacle), min(clearance_self, here_self)
        penetrating += min(here_obstacle, here_self) < 0
        depth = max(
            clauses.Violation(q),
            float(np.max(lower - q, initial=0.0)),
            float(np.max(q - upper, initial=0.0)),
        )
        if depth > LIMIT_TOLERANCE:
            violating += 1
            worst = max(worst, depth)
    inside = np.flatnonzero(errors < REACHED)
    speeds = np.abs(np.diff(trajectory.q, axis=0)) / PERIOD
    return RunResult(
        controller=controller,
        task=task.name,
        kind=task.kind,
        reached_at=float(inside[0] * PERIOD) if inside.size else None,
        final_error=float(errors[-1]),
        obstacle_clearance=float(obstacle),
        self_clearance=float(clearance_self),
        penetrating_steps=int(penetrating),
        violating_steps=violating,
        worst_violation=worst,
        peak_speed=float(speeds.max(initial=0.0)),
        step_seconds=trajectory.step_seconds,
        failed_steps=trajectory.failed_steps,
        palm_error=errors,
    )


@dc.dataclass
class ControllerSummary:
    """One controller over the task set (distances in m, times in s, angles in rad)."""

    label: str
    tasks: int
    reached_early: int
    reached: int
    median_time: float | None  # over the tasks reached by the horizon
    median_final_error: float
    obstacle_clearance: float
    self_clearance: float
    penetrating_steps: int
    penetrating_tasks: int
    violating_tasks: int
    worst_violation: float
    step_median: float
    step_p95: float
    peak_speed: float
    failed_steps: int


def Summarize(label: str, results: list[RunResult], early: float = EARLY) -> ControllerSummary:
    times = [r.reached_at for r in results if r.reached_at is not None]
    steps = np.concatenate([r.step_seconds for r in results])
    return ControllerSummary(
        label=label,
        tasks=len(results),
        reached_early=sum(t <= early for t in times),
        reached=len(times),
        median_time=float(np.median(times)) if times else None,
        median_final_error=float(np.median([r.final_error for r in results])),
        obstacle_clearance=min(r.obstacle_clearance for r in results),
        self_clearance=min(r.self_clearance for r in results),
        penetrating_steps=sum(r.penetrating_steps for r in results),
        penetrating_tasks=sum(r.penetrating_steps > 0 for r in results),
        violating_tasks=sum(r.violating_steps > 0 for r in results),
        worst_violation=max(r.worst_violation for r in results),
        step_median=float(np.median(steps)),
        step_p95=float(np.percentile(steps, 95)),
        peak_speed=max(r.peak_speed for r in results),
        failed_steps=sum(r.failed_steps for r in results),
    )


def RunBenchmark(
    tasks: list[ReachTask],
    controllers: dict[str, ReactiveController],
    horizon: float,
    scene: TaskScene,
    progress: Callable[[str], None] | None = None,
) -> dict[str, list[RunResult]]:
    """Every controller on every task: the results by controller name."""
    results = {name: [] for name in controllers}
    for task in tasks:
        for name, controller in controllers.items():
            trajectory = controller.run(task, horizon)
            results[name].append(MeasureRun(scene, task, trajectory, name))
            if progress:
                progress(f"{task.name} ({task.kind}), {name}: {_Reached(results[name][-1])}")
    return results


def _Reached(result: RunResult) -> str:
    if result.reached_at is None:
        return f"not reached, {100 * result.final_error:.1f} cm short"
    return f"reached at {result.reached_at:.2f} s"
