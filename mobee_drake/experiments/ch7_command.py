"""``mobee-drake experiment ch7``: the command line of the model-learning experiments (see
:mod:`mobee_drake.experiments.ch7_model_learning`)."""

import sys

from mobee_drake.atomic_files import WriteTextAtomically
from mobee_drake.experiments.arguments import CommandParser, InRange, PositiveInt
from mobee_drake.experiments.battery import (
    AddBackendArguments,
    BackendOf,
    Provenance,
)
from mobee_drake.experiments.ch7_model_learning import (
    RunCoverage,
    RunDynamicPlanning,
    RunHypercube,
    RunInitializations,
    RunRank4,
    RunThreeAgents,
    RunThreeAgentsControls,
)
from mobee_drake.experiments.ch7_report import REPORTS
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable
from mobee_drake.owned_folders import ClaimFolder


def _Parser() -> CommandParser:
    """The command line of ``mobee-drake experiment ch7``."""
    parser = CommandParser(
        prog="mobee-drake experiment ch7",
        description=__doc__,
    )
    parser.add_argument(
        "--experiment",
        choices=["7.1", "7.2", "7.2i", "7.3", "7.4", "7.4c", "7.4.1"],
        required=True,
        help="which experiment of ch. 7",
    )
    parser.add_argument(
        "--output", default="results/ch7", help="the battery folder (runs, plots, report)"
    )
    parser.add_argument("--runs", type=PositiveInt, default=5, help="runs (seeds) per setting")
    parser.add_argument(
        "--transitions",
        type=PositiveInt,
        default=None,
        help="7.2: the cap per run, which stops once every state-action was tried (default "
        "20,000); 7.3: per lattice (default: the source's 14,597 and 26,963); 7.4 and 7.4c: in "
        "all (default 18,000)",
    )
    parser.add_argument(
        "--transition-noise",
        type=InRange(0.0, 0.5),
        default=0.0,
        help="a stochastic robot (not for 7.4.1): the actuation noise's standard deviation "
        "per joint, a fraction of its range (runs named ..._noise<sd>)",
    )
    parser.add_argument(
        "--doc", help="a doc whose generated block 'ch7-<experiment>' gets the report's table"
    )
    AddBackendArguments(parser)
    return parser


def main(argv=None) -> None:
    parser = _Parser()
    argv = sys.argv[1:] if argv is None else argv
    args = parser.parse_args(argv)
    noise = args.transition_noise
    if noise and args.experiment == "7.4.1":
        parser.error("--transition-noise: 7.4.1 runs on the noise-free robot only")
    block = f"ch7-{args.experiment}"
    CheckDocBlocks(parser, args.doc, block)
    output = ClaimFolder(args.output, "battery")  # (a file or a user's folder refused)
    backend = BackendOf(args)
    if args.experiment == "7.1":
        results = RunHypercube(output, args.runs, backend, transition_noise=noise)
    elif args.experiment == "7.2":
        results = RunCoverage(output, args.transitions or 20000, args.runs, backend, noise)
    elif args.experiment == "7.2i":
        results = RunInitializations(output, args.runs, backend, transition_noise=noise)
    elif args.experiment == "7.3":
        results = RunRank4(output, args.transitions, backend, noise)
    elif args.experiment == "7.4":
        results = RunThreeAgents(output, args.transitions or 18000, backend, noise)
    elif args.experiment == "7.4c":
        transitions = args.transitions or 18000
        results = [RunThreeAgents(output, transitions, backend, noise)]
        results += RunThreeAgentsControls(output, transitions, backend, noise)
    else:
        results = RunDynamicPlanning(output, args.transitions or 1000, args.runs, backend)
    table = REPORTS[args.experiment](output, results)
    text = (
        f"# Experiment {args.experiment}\n\n`mobee-drake experiment ch7 "
        f"{' '.join(argv)}` ({Provenance(output)})\n\n" + "\n".join(table) + "\n"
    )
    WriteTextAtomically(output / f"report_{args.experiment}.md", text)
    print(text)
    if args.doc:
        command = f"mobee-drake experiment ch7 {' '.join(argv)}"
        WriteGeneratedTable(args.doc, block, command, "\n".join(table))


if __name__ == "__main__":
    main()
