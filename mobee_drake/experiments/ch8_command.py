"""``mobee-drake experiment ch8``: the command line of the reach-learning battery (see
:mod:`mobee_drake.experiments.ch8_reaching`)."""

import itertools
import pathlib
import sys

from pydrake.geometry import StartMeshcat

from mobee_drake.atomic_files import (
    WriteTextAtomically,
)
from mobee_drake.experiments.arguments import (
    CommandParser,
    InRange,
    NonNegativeInt,
    PositiveInt,
)
from mobee_drake.experiments.battery import (
    AddBackendArguments,
    BackendOf,
    Provenance,
)
from mobee_drake.experiments.ch8_claims import ClaimsTables
from mobee_drake.experiments.ch8_reaching import (
    DISTANCE_UNIT_RANGE,
    MDPS,
    REACH_FORCE_RANGE,
    REACH_PRESETS,
    READINGS,
    SOURCE_STAGES,
    SOURCE_STRATEGIES,
    MdpName,
    RunOne,
    RunReachBattery,
    RunSettings,
    StoredResults,
    TrainMdp,
)
from mobee_drake.experiments.ch8_report import Report
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable
from mobee_drake.owned_folders import ClaimFolder, OwnedFolder
from mobee_drake.reaching.learner import (
    EVALUATION_HISTORIES,
    PLATEAU_RULES,
    TIE_BREAKS,
    ReachLearningConfig,
)
from mobee_drake.reaching.predictors import (
    EQ81_READINGS,
    PREDICTORS,
)
from mobee_drake.reaching.strategies import REACH_STRATEGIES

# The generated block of docs/reaching.md that --doc rewrites by default.
DOC_TABLE = "ch8-claims"


def _Parser() -> CommandParser:
    """The command line of ``mobee-drake experiment ch8``."""
    parser = CommandParser(
        prog="mobee-drake experiment ch8",
        description=__doc__,
    )
    parser.add_argument(
        "--output", default="results/ch8", help="the battery folder (runs, plots, report)"
    )
    parser.add_argument(
        "--strategies",
        nargs="+",
        choices=list(REACH_STRATEGIES),
        default=list(SOURCE_STRATEGIES),
        help="exploration strategies, one run per seed each",
    )
    parser.add_argument("--seeds", type=PositiveInt, default=5, help="seeds per strategy")
    parser.add_argument(
        "--first-seed",
        type=NonNegativeInt,
        default=0,
        help="the first seed (fresh seeds test a setting chosen on others)",
    )
    parser.add_argument(
        "--problem-tries", type=PositiveInt, default=6400, help="exploratory problem-tries per run"
    )
    parser.add_argument(
        "--stages",
        type=NonNegativeInt,
        nargs="+",
        default=None,
        help="when to evaluate (default: the source's 100, 200, ..., 6400 up to --problem-tries)",
    )
    parser.add_argument(
        "--evaluations", type=PositiveInt, default=5, help="exploitation evaluations at each stage"
    )
    parser.add_argument(
        "--mdp-tries",
        type=PositiveInt,
        default=5,
        help="the MDP is learned until every state-action was tried this often",
    )
    parser.add_argument(
        "--checkpoint-every",
        type=PositiveInt,
        default=50,
        help="problem-tries between two checkpoints of a run",
    )
    parser.add_argument(
        "--watch",
        action="store_true",
        help="run only the first strategy's seed 0, in this process, shown in "
        "Meshcat in real time (the address is printed)",
    )
    _AddSettingArguments(parser)
    parser.add_argument(
        "--report-only",
        action="store_true",
        help="run nothing: write the plots and report.md of the finished runs in --output "
        "(runs/*/result.json; batteries of earlier versions too)",
    )
    parser.add_argument(
        "--doc",
        help="a doc whose generated claims table (block --doc-table) to rewrite from the runs",
    )
    parser.add_argument(
        "--doc-table",
        default=DOC_TABLE,
        help="the name of --doc's generated block (several batteries' tables in one doc)",
    )
    AddBackendArguments(parser, workers=2)
    return parser


def _AddSettingArguments(parser: CommandParser) -> None:
    """The reach learner's settings: its predictor, its MDP, the distance unit and reach force
    (a preset or swept values) and how the greedy policy breaks ties."""
    parser.add_argument(
        "--predictor",
        choices=PREDICTORS,
        default="weighted",
        help="the reward predictor: the source's weighted averages (eq. 8.1-8.7) "
        "or a Gaussian process (use another --output)",
    )
    parser.add_argument(
        "--mdp",
        choices=MDPS,
        default="learned_first",
        help="learn the MDP first and keep it (ch. 8), or learn it with the "
        "reaches (ch. 9.4.1; use another --output)",
    )
    parser.add_argument(
        "--preset",
        choices=list(REACH_PRESETS),
        default="calibrated",
        help="the distance unit and reach force: calibrated against the source's behaviour "
        "(issue 23) or metres with the full reach (the first reading; use another --output)",
    )
    parser.add_argument(
        "--reach-force",
        type=InRange(*REACH_FORCE_RANGE),
        nargs="+",
        default=None,
        help="the reach's force on the palm in N (default: the preset's; use another "
        "--output); several values sweep them (with every --distance-unit)",
    )
    parser.add_argument(
        "--distance-unit",
        type=InRange(*DISTANCE_UNIT_RANGE),
        nargs="+",
        default=None,
        help="the length in m that counts as 1 in the rewards and predictions of eq. 8.1-8.7 "
        "(default: the preset's; use another --output); several values sweep them: one "
        "battery, one MDP, the runs named <strategy>_unit<u>_force<F>_seed<k>",
    )
    parser.add_argument(
        "--tie-break",
        choices=TIE_BREAKS,
        default=ReachLearningConfig().tie_break,
        help="how the greedy policy picks among state-actions of equal value: the first "
        "(transitions before the reach) or a random one (use another --output)",
    )
    _AddReadingArguments(parser)


def _AddReadingArguments(parser: CommandParser) -> None:
    """The source's ambiguities (issue 33, docs/reaching.md); several values of any make a
    sweep over every combination."""
    parser.add_argument(
        "--plateau-rule",
        choices=PLATEAU_RULES,
        nargs="+",
        default=[READINGS["plateau_rule"]],
        help="when a transition fails: strict (8.1 as stated: its end state is not of higher "
        "value), arrival (a move that arrives where it was sent never fails) or random-tie "
        "(strict, ties of value broken at random)",
    )
    parser.add_argument(
        "--eq81",
        choices=EQ81_READINGS,
        nargs="+",
        default=[READINGS["eq81"]],
        help="eq. 8.1 as printed (one record predicts its reward everywhere) or as its prose "
        "reads (a prediction that fades with the distance to the records' targets)",
    )
    parser.add_argument(
        "--evaluation-history",
        choices=EVALUATION_HISTORIES,
        nargs="+",
        default=[READINGS["evaluation_history"]],
        help="what an evaluation remembers of its own failed transitions: per problem-try, or "
        "over the whole evaluation",
    )
    parser.add_argument(
        "--transition-noise",
        type=InRange(0.0, 0.5),
        nargs="+",
        default=[READINGS["transition_noise"]],
        help="a stochastic robot: the actuation noise's standard deviation per joint, a "
        "fraction of its range (the MDP is learned on the same robot)",
    )
    parser.add_argument(
        "--mdps",
        type=PositiveInt,
        default=1,
        help="independently learned MDPs: seed k's runs use MDP k mod this",
    )


def _Variants(args, stages: list[int]) -> list[RunSettings]:
    """The settings of every combination of the swept values (one unless a sweep)."""
    preset = REACH_PRESETS[args.preset]
    return [
        RunSettings(
            args.strategies[0],
            0,
            args.problem_tries,
            stages,
            args.evaluations,
            args.checkpoint_every,
            args.predictor,
            args.mdp,
            force,
            unit,
            args.tie_break,
            plateau_rule=rule,
            eq81=eq81,
            evaluation_history=history,
            transition_noise=noise,
        )
        for unit, force, rule, eq81, history, noise in itertools.product(
            dict.fromkeys(args.distance_unit or [preset.distance_unit]),
            dict.fromkeys(args.reach_force or [preset.reach_force]),
            dict.fromkeys(args.plateau_rule),
            dict.fromkeys(args.eq81),
            dict.fromkeys(args.evaluation_history),
            dict.fromkeys(args.transition_noise),
        )
    ]


def main(argv=None) -> None:
    parser = _Parser()
    argv = sys.argv[1:] if argv is None else argv
    args = parser.parse_args(argv)
    stages = args.stages or [s for s in SOURCE_STAGES if s <= args.problem_tries]
    if any(s < 0 or s > args.problem_tries for s in stages):
        parser.error(f"--stages must lie in 0..{args.problem_tries}")
    if len(set(stages)) != len(stages):
        parser.error(f"--stages must differ from each other, got {stages}")
    output = pathlib.Path(args.output)
    if args.report_only and not output.is_dir():  # (checked before a folder is made)
        parser.error(f"--report-only: {output} is not a folder of reach-learning runs")
    CheckDocBlocks(parser, args.doc, args.doc_table)
    ClaimFolder(output, "battery")  # (a file, or a folder of the user's, refused in one line)
    variants = _Variants(args, stages)
    settings = variants[0]
    if args.watch:  # In the battery's folder, beside its runs.
        watch = output / "watch"
        with OwnedFolder(output, "battery"):
            mdp_dir = watch / MdpName(args.mdp_tries, 0, settings.transition_noise)
            if settings.mdp == "learned_first":
                TrainMdp(mdp_dir, args.mdp_tries, transition_noise=settings.transition_noise)
            RunOne(watch / settings.strategy, mdp_dir, settings, StartMeshcat())
        return
    if args.report_only:
        with OwnedFolder(output, "battery"):
            results = StoredResults(output)
        if not results:
            parser.error(f"--report-only: no finished reach-learning runs in {output / 'runs'}")
    else:
        results = RunReachBattery(
            output,
            args.strategies,
            range(args.first_seed, args.first_seed + args.seeds),
            variants if len(variants) > 1 else settings,
            args.mdp_tries,
            BackendOf(args),
            mdps=args.mdps,
        )
    text = (
        f"# Reach learning (ch. 8.4)\n\n`mobee-drake experiment ch8 "
        f"{' '.join(argv)}` ({Provenance(output)})\n\n" + Report(output, results) + "\n"
    )
    WriteTextAtomically(output / "report.md", text)
    print(text)
    if args.doc:
        command = f"mobee-drake experiment ch8 --report-only --output {output} --doc {args.doc}"
        if args.doc_table != DOC_TABLE:
            command += f" --doc-table {args.doc_table}"
        WriteGeneratedTable(args.doc, args.doc_table, command, "\n".join(ClaimsTables(results)))


if __name__ == "__main__":
    main()
