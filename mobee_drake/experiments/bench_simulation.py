"""Benchmark: real-time factor and safety of motor babbling, kinematic and dynamic robots.

Runs ``diagrams/motor_babbling.yaml`` (random attractors for the 20 upper-body joints every 4 s,
a table in front) headless for a given simulated time, once with the kinematic robot and once
with the dynamic robot for each requested control modality, and prints the real-time factor, the
number of control periods in which solid geometry penetrated, the deepest penetration, and the
closest approach to the table and of the robot to itself.

Run: ``mobee-drake bench simulation [--seconds 600] [--controls position velocity force]``.
"""

from mobee_drake.experiments.arguments import CommandParser, PositiveFloat
from mobee_drake.scenario import LoadScenario, RunScenario

SCENARIO = "motor_babbling"


def main(argv=None) -> None:
    parser = CommandParser(
        prog="mobee-drake bench simulation",
        description=__doc__,
    )
    parser.add_argument(
        "--seconds", type=PositiveFloat, default=600.0, help="simulated time per run"
    )
    parser.add_argument(
        "--controls",
        nargs="*",
        default=["position"],
        help="dynamic-robot modalities to run (none: kinematic only)",
    )
    parser.add_argument(
        "--scenario", default=str(SCENARIO), help="the scenario run (a file or a shipped name)"
    )
    args = parser.parse_args(argv)
    runs = [("kinematic", "-")] + [("dynamic", control) for control in args.controls]
    print(f"{args.scenario}, {args.seconds:g} s simulated per run")
    print(
        "| robot | control | real-time factor | penetrating periods | deepest (mm) "
        "| closest to table (m) | closest to itself (m) |"
    )
    print("|---|---|---:|---:|---:|---:|---:|")
    for robot_model, control in runs:
        mover = "!Kinematic {}" if control == "-" else f"!Dynamic {{control: {control}}}"
        overrides = f"{{mover: {mover}, duration: {args.seconds}}}"
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
