"""Benchmark: NGIK (xNES, SNES) against CMA-ES and Drake's InverseKinematics (ch. 3.1-3.2).

The same IK problems go to every solver: put the iCub's right palm on a point (within 1 cm), and
in the second family also turn the palm's normal to a direction (within 10 degrees), with the
torso and right arm (10 joints) free, the other joints at home; the third family is the second
with all 20 of the model's joints free (torso, neck, both arms: the source ran its comparison on
the 41-joint upper body, hands included, which cannot move the palm). No collision pair (a table
and a ball are in the workspace), within the joint limits and the shoulder cable clauses. Every
target comes from a random valid, collision-free pose of the torso and right arm, so every
problem has a solution.

- NGIK and CMA-ES minimise the same cost (:class:`IkProblem`, Table 3.1's position, orientation
  and collision terms) from the home pose with the same initial spread and budget, and stop when
  the cost is half the position tolerance;
- Drake's ``InverseKinematics`` states the same requirements as constraints (position box,
  angle between vectors, minimum distance 0 between the solids, joint limits, the linear clauses)
  and solves them with its default solver (SNOPT) from the home pose.

A solve succeeds when the kinematic model finds the returned pose valid, free of collisions and
meeting every term. One process, one core.

The source's claim (ch. 3.2: "NES outperforms the other optimization approaches at solving IK" on
the iCub) is marked from the runs (:func:`OptimiserMark`); ``--doc`` writes the table and the mark
into a doc's generated block.

Run: ``mobee-drake bench ik [--problems 50] [--seed 0] [--doc docs/roadmaps.md]``.
"""

import dataclasses as dc
import time

import cma
import numpy as np
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.solvers import Solve
from scipy import stats

from mobee_drake.experiments.arguments import CommandParser, NonNegativeInt, PositiveInt
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable
from mobee_drake.experiments.statistics import Holm
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
NES_SOLVERS = ("ngik_xnes", "ngik_snes")
# The problem families: (name, the palm's normal required, the joints searched; None: all).
FAMILIES = (
    ("position", False, JOINTS),
    ("position + normal", True, JOINTS),
    ("position + normal, all 20 joints", True, None),
)
DOC_TABLE = "ngik-benchmark"


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


def _Solve(
    solver: str, problem: IkProblem, target: Target, oriented: bool, seed: int, k: int
) -> IkSolution:
    """Problem ``k`` solved by ``solver`` from home."""
    target_cost = problem.terms[0].tolerance / 2
    if solver.startswith("ngik"):
        config = NesConfig(
            variant=solver.split("_")[1], max_evaluations=BUDGET, target_cost=target_cost
        )
        return SolveNgik(
            problem, problem.model.home, SIGMA, config, np.random.default_rng([seed, k])
        )
    if solver == "cma_es":
        return SolveCma(problem, problem.model.home, target_cost, seed + k)
    return SolveDrakeIk(problem, target, oriented)


def Run(problems: int, seed: int) -> list[dict]:
    model = KinematicModel(IcubConfig(), OBJECTS)
    rng = np.random.default_rng(seed)
    print(
        f"kinematic model: {PosesPerSecond(model, rng):.0f} random poses/s with a table and a ball"
    )
    targets = RandomTargets(model, problems, rng)
    rows = []
    for family, oriented, joints in FAMILIES:
        for solver in SOLVERS:
            solutions = [
                _Solve(solver, IkProblem(model, Terms(model, target, oriented), joints=joints),
                       target, oriented, seed, k)
                for k, target in enumerate(targets)
            ]  # fmt: skip
            seconds = np.array([s.seconds for s in solutions])
            solved = np.array([s.solved for s in solutions])
            rows.append(
                {
                    "family": family,
                    "solver": solver,
                    "solved": float(solved.mean()),
                    "median_ms": 1000 * float(np.median(seconds)),
                    "mean_ms": 1000 * float(seconds.mean()),
                    "evaluations": float(np.mean([s.evaluations for s in solutions])),
                    "solves_per_s": float(len(solutions) / seconds.sum()),
                    "evaluations_each": [s.evaluations for s in solutions],
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


def OptimiserMark(rows: list[dict]) -> tuple[str, str]:
    """The source's claim that NES outperforms the other samplers, on these problems: in every
    family, the better NES variant (fewer evaluations on average) solves at least as many
    problems as CMA-ES and needs fewer evaluations per problem (Wilcoxon's signed-rank test on
    the same problems, Holm over the families). ``reproduced`` when every family says so,
    ``not reproduced`` when none does, else ``reproduced only on`` the families that do; the
    evidence gives CMA-ES's evaluations as a ratio of each NES variant's."""
    by = {(r["family"], r["solver"]): r for r in rows}
    families = list(dict.fromkeys(r["family"] for r in rows))
    found, p_values = [], []
    for family in families:
        best = min(NES_SOLVERS, key=lambda s: by[family, s]["evaluations"])
        nes, cma_es = by[family, best], by[family, "cma_es"]
        differences = np.subtract(nes["evaluations_each"], cma_es["evaluations_each"])
        p_values.append(float(stats.wilcoxon(differences).pvalue) if np.any(differences) else 1.0)
        found.append((family, best, nes, cma_es, float(np.median(differences))))
    adjusted = Holm(p_values)
    held, evidence = [], []
    for (family, best, nes, cma_es, median), p in zip(found, adjusted, strict=True):
        ratios = ", ".join(
            f"{cma_es['evaluations'] / by[family, s]['evaluations']:.2f} of {s}'s"
            for s in NES_SOLVERS
        )
        held.append(nes["solved"] >= cma_es["solved"] and median < 0 and p < 0.05)
        evidence.append(
            f"{family}: CMA-ES's evaluations {ratios}; {best} minus CMA-ES per problem, median "
            f"{median:+.0f} (Wilcoxon, Holm p = {p:.2g}); solved {100 * nes['solved']:.0f} % "
            f"and {100 * cma_es['solved']:.0f} %"
        )
    if all(held) or not any(held):
        return ("reproduced" if all(held) else "not reproduced"), "; ".join(evidence)
    only = ", ".join(f for f, h in zip(families, held, strict=True) if h)
    return f"reproduced only on: {only}", "; ".join(evidence)


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
    parser.add_argument("--doc", help="a doc whose generated block to rewrite with the results")
    parser.add_argument("--doc-table", default=DOC_TABLE, help="the name of --doc's block")
    args = parser.parse_args(argv)
    CheckDocBlocks(parser, args.doc, args.doc_table)
    rows = Run(args.problems, args.seed)
    mark, evidence = OptimiserMark(rows)
    text = (
        f"{Format(rows, args.problems)}\n\nNES outperforms the other samplers (ch. 3.2): "
        f"**{mark}**; {evidence}."
    )
    print(text)
    if args.doc:
        command = f"mobee-drake bench ik --problems {args.problems} --seed {args.seed}"
        WriteGeneratedTable(args.doc, args.doc_table, f"{command} --doc {args.doc}", text)


if __name__ == "__main__":
    main()
