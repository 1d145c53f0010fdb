"""Benchmark: NGIK (xNES, SNES) against CMA-ES and Drake's InverseKinematics (ch. 3.1-3.2).

The same IK problems go to every solver: put the iCub's right palm on a point (within 1 cm), and
in the second family also turn the palm's normal to a direction (within 10 degrees), with the
torso and right arm (10 joints) free, the other joints at home, no collision pair (a table and a
ball are in the workspace), within the joint limits and the shoulder cable clauses. Every target
comes from a random valid, collision-free pose, so every problem has a solution.

- NGIK and CMA-ES minimise the same cost (:class:`IkProblem`, Table 3.1's position, orientation
  and collision terms) from the home pose with the same initial spread and budget, and stop when
  the cost is half the position tolerance;
- Drake's ``InverseKinematics`` states the same requirements as constraints (position box,
  angle between vectors, minimum distance 0 between the solids, joint limits, the linear clauses)
  and solves them with its default solver (SNOPT) from the home pose.

A solve succeeds when the kinematic model finds the returned pose valid, free of collisions and
meeting every term. One process, one core.

Run: ``mobee-drake bench ik [--problems 50] [--seed 0]``.
"""

import dataclasses as dc
import time

import cma
import numpy as np
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.solvers import Solve

from mobee_drake.experiments.arguments import CommandParser, NonNegativeInt, PositiveInt
from mobee_drake.ngik.costs import CollisionCost, MarkerOrientationCost, MarkerPositionCost
from mobee_drake.ngik.kinematic_model import KinematicModel
from mobee_drake.ngik.nes import NesConfig
from mobee_drake.ngik.solver import IkProblem, IkSolution, SolveNgik
from mobee_drake.robots.icub import RIGHT_ARM_JOINTS, TORSO_JOINTS, IcubConfig
from mobee_drake.world.objects import Box, SceneObject, Sphere

JOINTS = list(TORSO_JOINTS + RIGHT_ARM_JOINTS)
OBJECTS = [
    SceneObject(name="table", shape=Box(size=[0.5, 0.9, 0.04]), position=[-0.38, 0.0, -0.17]),
    SceneObject(name="ball", shape=Sphere(radius=0.06), position=[-0.32, 0.12, 0.05]),
]
SIGMA = 0.3  # initial spread (rad) of the sampling solvers
BUDGET = 6000  # cost evaluations per solve
SOLVERS = ("ngik_xnes", "ngik_snes", "cma_es", "drake_ik")


@dc.dataclass(frozen=True)
class Target:
    position: np.ndarray
    direction: np.ndarray


def RandomTargets(model: KinematicModel, count: int, rng: np.random.Generator) -> list[Target]:
    """Palm positions and normals of random valid, collision-free poses of the searched joints."""
    columns = [model.JointIndex(j) for j in JOINTS]
    palm = model.MarkerIndex("r_palm")
    targets = []
    while len(targets) < count:
        q = model.home.copy()
        q[columns] = rng.uniform(model.lower[columns], model.upper[columns])
        e = model.Evaluate(q)
        if model.IsValid(q) and not e.collision_pairs:
            targets.append(Target(e.marker_positions[palm], e.marker_directions[palm]))
    return targets


def Terms(model: KinematicModel, target: Target, oriented: bool) -> list:
    palm = model.MarkerIndex("r_palm")
    terms = [MarkerPositionCost(palm, target.position), CollisionCost()]
    if oriented:
        terms.append(MarkerOrientationCost(palm, target.direction))
    return terms


def SolveCma(problem: IkProblem, start: np.ndarray, target_cost: float, seed: int) -> IkSolution:
    began = time.perf_counter()
    options = {
        "ftarget": target_cost,
        "maxfevals": BUDGET,
        "verbose": -9,
        "seed": seed + 1,
        "tolx": 1e-4,
    }
    strategy = cma.CMAEvolutionStrategy(problem.SearchVector(start), SIGMA, options)
    strategy.optimize(problem.Cost)
    seconds = time.perf_counter() - began
    evaluation, cost = problem.Evaluate(strategy.result.xbest)
    return IkSolution(
        q=evaluation.q,
        cost=cost,
        solved=problem.IsSolved(evaluation),
        evaluations=strategy.result.evaluations,
        seconds=seconds,
    )


def SolveDrakeIk(problem: IkProblem, target: Target, oriented: bool) -> IkSolution:
    model = problem.model
    plant = model.plant
    context = plant.GetMyMutableContextFromRoot(model.context)
    model.SetPose(model.home)
    began = time.perf_counter()
    ik = InverseKinematics(plant, context, with_joint_limits=True)
    q = ik.q()
    positions = model.position_index
    fixed = np.setdiff1d(np.arange(len(model.joints)), problem.columns)
    for i in fixed:  # the joints that are not searched stay at home
        ik.prog().AddBoundingBoxConstraint(model.home[i], model.home[i], q[positions[i]])
    palm = model.markers[model.MarkerIndex("r_palm")]
    hand = plant.GetBodyByName(palm.body_name).body_frame()
    half = MarkerPositionCost(0, target.position).tolerance / 2
    ik.AddPositionConstraint(
        hand, palm.p_BM, plant.world_frame(), target.position - half, target.position + half
    )
    if oriented:
        ik.AddAngleBetweenVectorsConstraint(
            plant.world_frame(), target.direction, hand, palm.u_B, 0.0, np.radians(9.0)
        )
    ik.AddMinimumDistanceLowerBoundConstraint(0.0, 0.02)
    # A single-literal clause is a linear constraint a.q + b >= 0; the disjunctions are not (a
    # pose that violates one fails the final check).
    normals, offsets = model.clauses.SingleLiterals()
    if len(offsets):
        A = np.zeros((len(offsets), plant.num_positions()))
        A[:, positions] = normals
        ik.prog().AddLinearConstraint(A, -offsets, np.full(len(offsets), np.inf), q)
    ik.prog().SetInitialGuess(q, plant.GetPositions(context))
    result = Solve(ik.prog())
    seconds = time.perf_counter() - began
    q_found = result.GetSolution(q)[positions]
    evaluation, cost = problem.Evaluate(q_found[problem.columns])
    return IkSolution(
        q=evaluation.q,
        cost=cost,
        solved=problem.IsSolved(evaluation),
        evaluations=0,
        seconds=seconds,
    )


def PosesPerSecond(model: KinematicModel, rng: np.random.Generator, count: int = 2000) -> float:
    """Kinematic-model evaluations (markers and collision pairs) per second, random poses of all
    controlled joints (the source: about 1,000 per second without obstacles, ch. 4.3.3)."""
    poses = rng.uniform(model.lower, model.upper, size=(count, len(model.joints)))
    began = time.perf_counter()
    for q in poses:
        model.Evaluate(q)
    return count / (time.perf_counter() - began)


def Run(problems: int, seed: int) -> list[dict]:
    model = KinematicModel(IcubConfig(), OBJECTS)
    rng = np.random.default_rng(seed)
    print(
        f"kinematic model: {PosesPerSecond(model, rng):.0f} random poses/s with a table and a ball"
    )
    targets = RandomTargets(model, problems, rng)
    rows = []
    for oriented in (False, True):
        for solver in SOLVERS:
            solutions = []
            for k, target in enumerate(targets):
                problem = IkProblem(model, Terms(model, target, oriented), joints=JOINTS)
                target_cost = problem.terms[0].tolerance / 2
                if solver.startswith("ngik"):
                    config = NesConfig(
                        variant=solver.split("_")[1],
                        max_evaluations=BUDGET,
                        target_cost=target_cost,
                    )
                    solutions.append(
                        SolveNgik(
                            problem, model.home, SIGMA, config, np.random.default_rng([seed, k])
                        )
                    )
                elif solver == "cma_es":
                    solutions.append(SolveCma(problem, model.home, target_cost, seed + k))
                else:
                    solutions.append(SolveDrakeIk(problem, target, oriented))
            seconds = np.array([s.seconds for s in solutions])
            solved = np.array([s.solved for s in solutions])
            rows.append(
                {
                    "family": "position + normal" if oriented else "position",
                    "solver": solver,
                    "solved": float(solved.mean()),
                    "median_ms": 1000 * float(np.median(seconds)),
                    "mean_ms": 1000 * float(seconds.mean()),
                    "evaluations": float(np.mean([s.evaluations for s in solutions])),
                    "solves_per_s": float(len(solutions) / seconds.sum()),
                }
            )
    return rows


def Format(rows: list[dict], problems: int) -> str:
    lines = [
        f"{problems} problems per family; budget {BUDGET} evaluations; sigma {SIGMA} rad",
        "| problems | solver | solved | median ms | mean ms | evaluations | solves/s |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        evaluations = f"{r['evaluations']:.0f}" if r["evaluations"] else "-"
        lines.append(
            f"| {r['family']} | {r['solver']} | {100 * r['solved']:.0f} % | "
            f"{r['median_ms']:.1f} | {r['mean_ms']:.1f} | {evaluations} | "
            f"{r['solves_per_s']:.1f} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = CommandParser(
        prog="mobee-drake bench ik",
        description=__doc__.split("\n")[0],
    )
    parser.add_argument(
        "--problems", type=PositiveInt, default=50, help="random IK problems per solver"
    )
    parser.add_argument(
        "--seed", type=NonNegativeInt, default=0, help="seed of the problems and the solvers"
    )
    args = parser.parse_args(argv)
    print(Format(Run(args.problems, args.seed), args.problems))


if __name__ == "__main__":
    main()
