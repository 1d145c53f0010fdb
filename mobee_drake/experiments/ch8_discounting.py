"""When a greedy reach planner moves (issue 23, point 5): the reward ratio one step and a path
of steps need, in closed form (:mod:`mobee_drake.reaching.discounting`) against value iteration on
a learned MDP, and what the ch. 8 runs' rewards and predictions give (docs/reaching_history.md).

With ``--reach-force``, it also measures what moving could gain (issue 23, point 6): reaches for a
sample of the problems from a sample of start states, on the reach learner's robot with each
force, and per distance unit the ratio of the best start state's reward to each state's, against
the ratio one step and a random start need.

Run: ``mobee-drake experiment ch8-discounting --model BATTERY/runs/mdp_tries5/model [--runs
BATTERY/runs/*/result.json] [--reach-force 300 30]``.
"""

import json
import pathlib

import numpy as np

from mobee_drake.experiments.arguments import (
    CommandParser,
    Discount,
    NonNegativeInt,
    PositiveFloat,
    PositiveInt,
)
from mobee_drake.experiments.ch8_reaching import AGENT, ReachRobot, ReachRun
from mobee_drake.planning.explorers import ExplorerConfig, LoadAgentModel
from mobee_drake.reaching.discounting import (
    BestOverOwn,
    MoveThreshold,
    PathRatio,
    PredictedSpread,
    RewardRatio,
    StepRatio,
    Steps,
)
from mobee_drake.reaching.learner import ReachLearner, ReachLearningConfig
from mobee_drake.reaching.predictors import PredictorConfig
from mobee_drake.reaching.targets import LoadTargetGrid


def ReachMisses(space, force: float, states, problems: np.ndarray, radius: float) -> np.ndarray:
    """The misses (m) of reaches for ``problems`` (targets of ``radius``, k x 3) from each of
    ``states``, with ``force`` on the palm; NaN where the transition to the state failed."""
    robot = ReachRobot(space, radius, force)
    misses = np.full((len(states), len(problems)), np.nan)
    for i, state in enumerate(states):
        for j, target in enumerate(problems):
            robot.SetProblem(target)
            if robot.Transition(int(state)) == state:
                misses[i, j] = np.linalg.norm(robot.Reach(target) - target)
    return misses


def _Parser() -> CommandParser:
    """The command line of ``mobee-drake experiment ch8-discounting``."""
    parser = CommandParser(prog="mobee-drake experiment ch8-discounting", description=__doc__)
    parser.add_argument("--model", required=True, help="the MDP's folder (runs/mdp_tries5/model)")
    parser.add_argument(
        "--gamma", type=Discount, default=0.9, help="the discount factor, in [0, 1)"
    )
    parser.add_argument(
        "--favourites",
        type=NonNegativeInt,
        nargs="+",
        default=[57, 77],
        help="the favourite pre-reach states (the source's reaches 489 and 509)",
    )
    parser.add_argument(
        "--misses",
        type=PositiveFloat,
        nargs=2,
        default=[0.01, 0.33],
        help="the misses' range in m (the first the smaller)",
    )
    parser.add_argument(
        "--units",
        type=PositiveFloat,
        nargs="+",
        default=[1.0, 0.1, 0.03, 0.01],
        help="distance units (m)",
    )
    parser.add_argument(
        "--runs",
        nargs="*",
        default=[],
        help="result.json files of ch8 runs on this MDP: their reach rewards, and the spread of "
        "eq. 8.5's predictions after the run (histories rebuilt from the log)",
    )
    parser.add_argument(
        "--reach-force",
        type=PositiveFloat,
        nargs="*",
        default=[],
        help="measure reaches with these forces on the palm (N) from --probe-states start states "
        "for --probe-problems problems, drawn with --seed",
    )
    parser.add_argument("--probe-states", type=PositiveInt, default=12, help="start states drawn")
    parser.add_argument("--probe-problems", type=PositiveInt, default=9, help="problems drawn")
    parser.add_argument("--seed", type=NonNegativeInt, default=0, help="seed of the draws")
    return parser


def main(argv=None) -> None:
    parser = _Parser()
    args = parser.parse_args(argv)
    if args.misses[0] >= args.misses[1]:
        parser.error(f"--misses: the first must be the smaller, got {args.misses}")
    for path in args.runs:  # (checked before any work)
        if not pathlib.Path(path).is_file():
            parser.error(f"--runs: {path} is not a file")
    try:
        model = LoadAgentModel(args.model, AGENT, ExplorerConfig())
    except (OSError, ValueError) as error:
        parser.error(f"--model: {error}")
    space, counts = model.space, model.transitions.counts
    if any(s >= space.num_states for s in args.favourites):
        parser.error(f"--favourites: states are 0..{space.num_states - 1}, got {args.favourites}")
    learner = ReachLearner(
        space, counts, np.zeros((1, 3)), ReachLearningConfig(gamma=args.gamma, delta=1e-10)
    )
    p, thresholds = _PrintModelRatios(args, model, learner)
    _PrintReplays(args, model)
    _PrintUnits(args)
    _PrintReachForces(args, model, StepRatio(args.gamma, p), float(thresholds.mean()))


def _PrintModelRatios(args, model, learner) -> tuple[float, np.ndarray]:
    """The learned MDP's success probability, and the value ratio a move needs, closed form
    against value iteration, per number of steps to the favourites; returns (p, the needed
    ratio of each state)."""
    space = model.space
    probabilities = model.transitions.Probabilities()
    rows = np.arange(space.num_state_actions)
    success = probabilities[rows, space.action_goal]
    stay = probabilities[rows, space.action_state]
    p = float(success.mean())
    print(
        f"learned MDP: P(goal) mean {p:.3f} (median {np.median(success):.3f}, "
        f"{success.min():.3f}-{success.max():.3f}); P(stay) mean {stay.mean():.3f}"
    )
    print(
        f"closed form, gamma {args.gamma}, p {p:.3f}: one step needs {StepRatio(args.gamma, p):.3f}"
    )
    steps = Steps(learner, args.favourites)
    thresholds = np.array(
        [
            MoveThreshold(learner, s, args.favourites) if steps[s] > 0 else 1.0
            for s in range(space.num_states)
        ]
    )
    print(f"steps from the {space.num_states} states to the nearest of {args.favourites}:")
    for d in range(1, steps.max() + 1):
        at = thresholds[steps == d]
        print(
            f"  {d} steps ({len(at)} states): closed form {PathRatio(args.gamma, p, d):.3f}, "
            f"value iteration on the learned T {at.min():.3f}-{at.max():.3f} (mean {at.mean():.3f})"
        )
    print(
        f"from a random start (all {space.num_states} equally likely): mean steps "
        f"{steps.mean():.2f}, needed ratio mean {thresholds.mean():.3f}, median "
        f"{np.median(thresholds):.3f}; closed form at the mean steps "
        f"{StepRatio(args.gamma, p) ** steps.mean():.3f}"
    )
    return p, thresholds


def _PrintReplays(args, model) -> None:
    """Each run of ``--runs`` replayed: its rewards, eq. 8.5's spread and where greedy moves."""
    space, counts = model.space, model.transitions.counts
    for path in args.runs:
        run = ReachRun.FromJson(json.loads(pathlib.Path(path).read_text()))
        unit = run.settings.distance_unit
        config = ReachLearningConfig(
            gamma=args.gamma,
            predictor=PredictorConfig(
                run.settings.predictor, distance_unit=unit, eq81=run.settings.eq81
            ),
        )
        replay = ReachLearner(space, counts, LoadTargetGrid().Centres(), config)
        log = np.array(run.log)
        for row in log:
            replay.histories.Record(int(row[2]), row[7:], row[5], row[6])
        rewards = log[log[:, 2] >= replay.num_transitions, 6]
        ratios, moving = PredictedSpread(replay)
        print(
            f"{path}: {len(log)} actions; reach rewards {rewards.min():.3f}-{rewards.max():.3f} "
            f"(misses {unit * 100 * (1 / rewards.max() - 1):.1f}-"
            f"{unit * 100 * (1 / rewards.min() - 1):.1f} cm); eq. 8.5's largest over smallest "
            f"prediction per problem: median {np.median(ratios):.3f}, max {ratios.max():.3f}; "
            f"start states from which the greedy policy moves: {100 * moving.mean():.1f} % "
            f"(at most {100 * moving.max():.1f} % for a problem)"
        )


def _PrintUnits(args) -> None:
    """The rewards of the misses ``--misses`` in each unit of ``--units``."""
    low, high = args.misses
    for unit in args.units:
        print(
            f"misses {100 * low:g}-{100 * high:g} cm in units of {unit:g} m: rewards "
            f"{1 / (1 + high / unit):.3f}-{1 / (1 + low / unit):.3f}, ratio at most "
            f"{RewardRatio(low, high, unit):.2f}"
        )


def _PrintReachForces(args, model, step: float, start: float) -> None:
    """Per reach force: the misses from probe start states, and how often the best state's
    reward beats one step's and a random start's needed ratio."""
    space = model.space
    rng = np.random.default_rng(args.seed)
    grid = LoadTargetGrid()
    targets = grid.Centres()
    states = rng.choice(space.num_states, min(args.probe_states, space.num_states), replace=False)
    problems = targets[rng.choice(len(targets), min(args.probe_problems, len(targets)), False)]
    for force in args.reach_force:
        misses = ReachMisses(space, force, states, problems, grid.radius)
        measured = misses[~np.isnan(misses)]
        if measured.size == 0:
            print(f"reach force {force:g} N: no start state reached")
            continue
        print(
            f"reach force {force:g} N, {len(states)} start states x {len(problems)} problems: "
            f"misses {100 * measured.min():.1f}-{100 * measured.max():.1f} cm (median "
            f"{100 * np.median(measured):.1f}; {np.isnan(misses).sum()} transitions failed)"
        )
        for unit in args.units:
            gain = BestOverOwn(misses, unit)
            gain = gain[~np.isnan(gain)]
            print(
                f"  unit {unit:g} m: best state's reward over this state's median "
                f"{np.median(gain):.2f}; above one step's {step:.2f}: "
                f"{100 * np.mean(gain > step):.0f} %; above a random start's {start:.2f}: "
                f"{100 * np.mean(gain > start):.0f} %"
            )


if __name__ == "__main__":
    main()
