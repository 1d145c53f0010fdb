"""Benchmark: MoBeE 1.0 (the rewinding reflex, ch. 4.1) against MoBeE 2.0 on motor babbling.

Both controllers run the same scenario (``diagrams/motor_babbling.yaml``: random attractors for
every upper-body joint, a table in front of the robot; here a new attractor every 8 s, as MoBeE
1.0's position moves at 20 deg/s take up to 7 s) with the same seeds, so they get the same
sequence of commands. For each we count, per simulated minute:

- solid penetrations: control periods in which some pair of solids interpenetrated;
- commands completed: attractors the robot reached (every joint within 2 deg, or 10 deg) before
  the next, and the median over commands of the largest joint error when the next one came
  (MoBeE 2.0 settles where its attractor, joint-limit, constraint and field forces balance: near,
  not on, an attractor close to a limit);
- reflexes (MoBeE 1.0: rewinds) or stalls (MoBeE 2.0: commands still more than 10 deg away);
- runs stuck with no safe pose left (MoBeE 1.0 only: a rewind that ran out of history; MoBeE 2.0
  never rewinds).

Run: ``mobee-drake bench babbling [--seeds 5] [--minutes 5]``.
"""

import contextlib
import tempfile
import time

import numpy as np
from pydrake.systems.primitives import LogVectorOutput

from mobee_drake.experiments.arguments import CommandParser, PositiveFloat, PositiveInt
from mobee_drake.experiments.battery import (
    AddBackendArguments,
    BackendOf,
    Job,
    RunBattery,
    RunFolder,
)
from mobee_drake.mobee.reflex import Status
from mobee_drake.scenario import LoadScenario
from mobee_drake.station.builder import MakeMobeeStation
from mobee_drake.station.world_events import MakeSimulator

SCENARIO = "motor_babbling"
PERIOD = 8.0  # s between commands
REACHED_DEG = 2.0  # a command is completed when every joint is this close to it,
NEAR_DEG = 10.0  # and nearly so within this; MoBeE 2.0 stalls on a command it is farther from


def CommandErrors(q: np.ndarray, q_star: np.ndarray) -> np.ndarray:
    """For each command (a run of equal attractors in the logs), the robot's distance from it
    when the next one came: the largest joint error (deg)."""
    changes = np.flatnonzero(np.any(np.diff(q_star, axis=1) != 0, axis=0)) + 1
    ends = np.r_[changes, q_star.shape[1]] - 1
    return np.degrees(np.max(np.abs(q[:, ends] - q_star[:, ends]), axis=0))


def RunOne(run: RunFolder, controller: str, seed: int, minutes: float, scenario_file: str) -> dict:
    """The battery job of one controller's babbling with one seed."""
    mover = "!Reflex {}" if controller == "reflex" else "!Kinematic {}"
    scenario = LoadScenario(
        scenario_file, f"{{mover: {mover}, random_seed: {seed}, data_log: {{enabled: false}}}}"
    )
    scenario.attractor.period = PERIOD
    logs = {}

    def AddClientAndLoggers(parts):
        client = scenario.attractor.AddToBuilder(parts)
        logs["state"] = LogVectorOutput(parts.robot_state, parts.builder, scenario.time_step)
        logs["attractor"] = LogVectorOutput(client.attractor, parts.builder, scenario.time_step)
        return client

    simulation = MakeMobeeStation(scenario, prebuild_callback=AddClientAndLoggers)
    simulator = MakeSimulator(simulation)
    context = simulator.get_mutable_context()
    began = time.perf_counter()
    simulator.AdvanceTo(60.0 * minutes)
    wall = time.perf_counter() - began
    safety = simulation.monitor.Report(simulation.monitor.GetMyContextFromRoot(context))
    n = len(simulation.mobee.joints)
    state = logs["state"].FindLog(context)
    attractor = logs["attractor"].FindLog(context)
    errors = CommandErrors(state.data()[:n], attractor.data())
    row = {
        "controller": controller,
        "seed": seed,
        "wall": wall,
        "commands": len(errors),
        "completed": int(np.sum(errors <= REACHED_DEG)),
        "near": int(np.sum(errors <= NEAR_DEG)),
        "errors": errors.tolist(),
        "penetrating": safety.penetrating_steps,
        "deepest": safety.deepest_penetration,
    }
    if controller == "reflex":
        reflex = simulation.mover
        status = reflex.GetOutputPort("status").Eval(reflex.GetMyContextFromRoot(context))
        row.update(reflexes=int(status[Status.REFLEXES]), stuck=int(status[Status.STUCK_COUNT] > 0))
    else:
        row.update(reflexes=int(np.sum(errors > NEAR_DEG)), stuck=0)
    return row


def main(argv: list[str] | None = None) -> None:
    parser = CommandParser(
        prog="mobee-drake bench babbling",
        description=__doc__.split("\n")[0],
    )
    parser.add_argument("--seeds", type=PositiveInt, default=5, help="seeds per controller")
    parser.add_argument(
        "--minutes", type=PositiveFloat, default=5.0, help="simulated minutes per run"
    )
    parser.add_argument(
        "--scenario", default=SCENARIO, help="the babbling scenario (a file or a shipped name)"
    )
    parser.add_argument(
        "--output", default=None, help="keep the runs here (default: a temporary folder)"
    )
    AddBackendArguments(parser)
    args = parser.parse_args(argv)
    print(f"{SCENARIO}, {args.seeds} seeds x {args.minutes} simulated minutes per controller")
    print(
        "| controller | penetrating periods/min | deepest mm | commands/min | within 2 deg/min "
        "| within 10 deg/min | median error deg | reflexes or stalls/min | runs stuck "
        "| wall s/run |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    controllers = ("reflex", "mobee2")
    jobs = [
        Job(
            f"{controller}_seed{seed}",
            RunOne,
            dict(
                controller=controller, seed=seed, minutes=args.minutes, scenario_file=args.scenario
            ),
        )
        for controller in controllers
        for seed in range(args.seeds)
    ]
    with contextlib.ExitStack() as stack:
        output = args.output or stack.enter_context(tempfile.TemporaryDirectory())
        results = RunBattery(jobs, output, backend=BackendOf(args), description="babbling")
    for controller in controllers:
        rows = [results[f"{controller}_seed{seed}"] for seed in range(args.seeds)]
        per_minute = {
            key: np.mean([r[key] for r in rows]) / args.minutes
            for key in ("penetrating", "commands", "completed", "near", "reflexes")
        }
        median_error = np.median(np.concatenate([r["errors"] for r in rows]))
        label = "MoBeE 1.0 (reflex)" if controller == "reflex" else "MoBeE 2.0"
        print(
            f"| {label} | {per_minute['penetrating']:.2f} | "
            f"{1000 * max(r['deepest'] for r in rows):.1f} | {per_minute['commands']:.1f} | "
            f"{per_minute['completed']:.2f} | {per_minute['near']:.2f} | {median_error:.1f} | "
            f"{per_minute['reflexes']:.2f} | "
            f"{sum(r['stuck'] for r in rows)} of {len(rows)} | "
            f"{np.mean([r['wall'] for r in rows]):.1f} |"
        )


if __name__ == "__main__":
    main()
