"""Benchmark: real-time factor and safety of motor babbling, kinematic and dynamic robots.

Runs ``diagrams/motor_babbling.yaml`` (random attractors for the 20 upper-body joints every 4 s,
a table in front) headless for a given simulated time, once with the kinematic robot and once
with the dynamic robot for each requested control modality, and prints the real-time factor, the
number of control periods in which solid geometry penetrated, the deepest penetration, and the
closest approach to the table and of the robot to itself.

For the kinematic robot it also prints the cost of one control period (MoBeE, virtual dynamics,
safety monitor, simulator, without the data log: wall time over the periods after the first
second) beside Drake's floor for that period, ``SetPositions`` and the signed-distance query up
to the largest field margin at the period's pose, replayed in the same process on the same
scene; and their ratio.

Run: ``mobee-drake bench simulation [--seconds 600] [--controls position velocity force]``.
"""

import dataclasses as dc
import time

import numpy as np

from mobee_drake.experiments.arguments import CommandParser, PositiveFloat
from mobee_drake.experiments.bench_forces import BuildPosedScene, FloorEvaluation
from mobee_drake.scenario import BuildScenario, LoadScenario, RunScenario, Scenario
from mobee_drake.station.config import CONTROL_MODALITIES, DataLog
from mobee_drake.station.world_events import MakeSimulator

SCENARIO = "motor_babbling"


@dc.dataclass
class PeriodAndFloor:
    """One control period of the kinematic robot beside Drake's floor for it (see the module)."""

    period_us: float
    floor_us: float
    # How far the babbling robot went: the largest range of a joint over the run (deg).
    travel_deg: float


def ControlPeriodAndFloor(scenario: Scenario) -> PeriodAndFloor:
    """One control period and Drake's floor over the scenario's duration (see the module); the
    period is timed without the data log, whose second, untimed run gives the poses the floor
    replays."""
    timed = BuildScenario(dc.replace(scenario, data_log=DataLog(enabled=False)))
    simulator = MakeSimulator(timed)
    simulator.Initialize()
    simulator.AdvanceTo(1.0)  # (First evaluations build Drake's and numpy's caches.)
    start = time.perf_counter()
    simulator.AdvanceTo(scenario.duration)
    periods = round((scenario.duration - 1.0) / scenario.time_step)
    per_period = (time.perf_counter() - start) / periods
    logged = BuildScenario(
        dc.replace(
            scenario, data_log=DataLog(max_rows=round(scenario.duration / scenario.time_step) + 1)
        )
    )
    simulator = MakeSimulator(logged)
    simulator.Initialize()
    simulator.AdvanceTo(scenario.duration)
    log = logged.data_log.Table(simulator.get_context()).to_pandas()
    poses = log[[f"q.{j}" for j in logged.mobee.joints]].to_numpy()
    # The floor: the same robot and objects, posed and queried.
    scene = BuildPosedScene(scenario.robot, scenario.objects)
    _, plant_context, mobee_context = scene.Contexts()
    floor_evaluation, order = FloorEvaluation(scene, mobee_context), scene.PositionOrder()
    x = scene.plant.GetPositions(plant_context)
    start = time.perf_counter()
    for q in poses:
        x[order] = q
        scene.plant.SetPositions(plant_context, x)
        floor_evaluation()
    floor = (time.perf_counter() - start) / len(poses)
    travel = np.degrees((poses.max(axis=0) - poses.min(axis=0)).max())
    return PeriodAndFloor(1e6 * per_period, 1e6 * floor, float(travel))


def main(argv=None) -> None:
    parser = CommandParser(
        prog="mobee-drake bench simulation",
        description=__doc__,
    )
    parser.add_argument(
        "--seconds",
        type=PositiveFloat,
        default=600.0,
        help="simulated time per run (more than the 1 s the timing leaves out)",
    )
    parser.add_argument(
        "--controls",
        nargs="*",
        choices=CONTROL_MODALITIES,
        default=["position"],
        help="dynamic-robot modalities to run (none: kinematic only)",
    )
    parser.add_argument(
        "--scenario", default=str(SCENARIO), help="the scenario run (a file or a shipped name)"
    )
    args = parser.parse_args(argv)
    if args.seconds <= 1.0:
        parser.error(
            f"--seconds: the timing leaves out the first second: give more than 1, got "
            f"{args.seconds:g}"
        )
    try:  # (a user's scenario: checked before any work)
        kinematic = LoadScenario(
            args.scenario, f"{{mover: !Kinematic {{}}, duration: {args.seconds}}}"
        )
    except ValueError as error:
        parser.error(f"--scenario: {error}")
    measured = ControlPeriodAndFloor(kinematic)
    period, floor = measured.period_us, measured.floor_us
    print(
        f"kinematic robot, one control period of {kinematic.time_step * 1000:g} ms: "
        f"{period:.0f} us ({kinematic.time_step * 1e6 / period:.0f}x real time); Drake's floor "
        f"(SetPositions + signed-distance query at the period's pose): {floor:.0f} us; "
        f"ratio {period / floor:.2f}\n"
    )
    runs = [("kinematic", "-")] + [("dynamic", control) for control in args.controls]
    print(f"{args.scenario}, {args.seconds:g} s simulated per run")
    print(
        "| robot | control | real-time factor | penetrating periods | deepest (mm) "
        "| closest to table (m) | closest to itself (m) |"
    )
    print("|---|---|---:|---:|---:|---:|---:|")
    for robot_model, control in runs:
        mover = "!Kinematic {}" if control == "-" else f"!Dynamic {{control: {control}}}"
        overrides = f"{{mover: {mover}, duration: {args.seconds}, data_log: {{enabled: false}}}}"
        summary = RunScenario(LoadScenario(args.scenario, overrides))
        safety = summary.safety
        closest = {
            name: "-" if value is None else f"{value:.4f}"
            for name, value in safety.closest_approach.items()
        }
        print(
            f"| {robot_model} | {control} | {summary.realtime_factor:.1f} | "
            f"{safety.penetrating_steps} | {1000 * safety.deepest_penetration:.2f} | "
            f"{closest.get('table', '-')} | {closest['(self)']} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
