"""``mobee-drake experiment saggriac``: the command line of the SAGG-RIAC battery (see
:mod:`mobee_drake.experiments.saggriac`)."""

import argparse
import pathlib
import sys
import time

from mobee_drake.experiments.arguments import CommandParser, NonNegativeInt, PositiveInt
from mobee_drake.experiments.battery import (
    RESULT,
    AddBackendArguments,
    BackendOf,
)
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable
from mobee_drake.experiments.saggriac import FULL, METHODS, SMOKE, VARIANTS, RunAll, RunSpec
from mobee_drake.experiments.saggriac_interest import Issue34Lines
from mobee_drake.experiments.saggriac_report import Analyse
from mobee_drake.owned_folders import OwnedFolder


def _Parser() -> CommandParser:
    """The command line of ``mobee-drake experiment saggriac``."""
    parser = CommandParser(
        prog="mobee-drake experiment saggriac",
        description=__doc__,
    )
    parser.add_argument(
        "--experiments",
        type=int,
        nargs="+",
        choices=[1, 2],
        default=[1, 2],
        help="which experiments of Sec. IV",
    )
    parser.add_argument(
        "--methods",
        nargs="+",
        choices=list(METHODS),
        default=list(METHODS),
        help="the learners compared",
    )
    parser.add_argument(
        "--variants",
        nargs="+",
        choices=list(VARIANTS),
        default=["paper"],
        help="settings per method (a variant runs only with the methods it applies to): "
        + "; ".join(
            f"{name}: {variant.description} ({', '.join(variant.methods)})"
            for name, variant in VARIANTS.items()
        ),
    )
    parser.add_argument(
        "--seeds",
        type=PositiveInt,
        default=argparse.SUPPRESS,
        help=f"number of seeds (default: {FULL['seeds']}; paper: 15)",
    )
    parser.add_argument("--first-seed", type=NonNegativeInt, default=0, help="the first seed")
    parser.add_argument(
        "--budget-exp1",
        type=PositiveInt,
        default=argparse.SUPPRESS,
        help=f"movements (default: {FULL['budget_exp1']:,}, the paper's)",
    )
    parser.add_argument(
        "--budget-exp2",
        type=PositiveInt,
        default=argparse.SUPPRESS,
        help=f"time steps (default: {FULL['budget_exp2']:,}, the paper's)",
    )
    parser.add_argument(
        "--checkpoints",
        type=PositiveInt,
        default=argparse.SUPPRESS,
        help=f"evaluations after step 0 (default: {FULL['checkpoints']})",
    )
    parser.add_argument(
        "--output",
        type=pathlib.Path,
        default=pathlib.Path("results/saggriac"),
        help="the battery folder (runs, curves, report)",
    )
    parser.add_argument(
        "--analyse-only", action="store_true", help="only rebuild the report from run files"
    )
    parser.add_argument(
        "--doc",
        help="a doc whose generated block (--doc-table) to rewrite with the interest tables and "
        "marks of the runs",
    )
    parser.add_argument(
        "--doc-table",
        default="saggriac-interest",
        help="the name of --doc's generated block",
    )
    parser.add_argument(
        "--smoke",
        action="store_true",
        help="tiny battery, unless the flags say otherwise: "
        + ", ".join(f"--{name.replace('_', '-')} {value}" for name, value in SMOKE.items()),
    )
    AddBackendArguments(parser)
    return parser


def main(argv=None) -> None:
    """Command line: runs the missing runs, then analyses.

    Args:
        argv: Arguments (default: sys.argv[1:]).
    """
    parser = _Parser()
    args = parser.parse_args(argv)
    # --smoke's sizes, or the paper's, for what the command line does not give.
    for name, value in (SMOKE if args.smoke else FULL).items():
        setattr(args, name, getattr(args, name, value))
    budgets = {1: args.budget_exp1, 2: args.budget_exp2}
    for experiment in args.experiments:
        if args.checkpoints > budgets[experiment]:
            parser.error(
                f"--checkpoints {args.checkpoints}: more evaluations than experiment "
                f"{experiment}'s budget of {budgets[experiment]}"
            )
    CheckDocBlocks(parser, args.doc, args.doc_table)
    # Seed-major order: an interrupted battery leaves every group with about as many seeds.
    specs = [
        RunSpec(experiment, method, seed, budgets[experiment], args.checkpoints, variant)
        for experiment in args.experiments
        for seed in range(args.first_seed, args.first_seed + args.seeds)
        for variant in args.variants
        for method in args.methods
        if method in VARIANTS[variant].methods
    ]
    if not specs:
        parser.error(
            f"no run: none of the variants {args.variants} applies to the methods {args.methods}"
        )
    started = time.perf_counter()
    if not args.analyse_only:
        RunAll(specs, args.output, BackendOf(args))
    command = "mobee-drake experiment saggriac " + " ".join(
        argv if argv is not None else sys.argv[1:]
    )
    # (Claimed like the battery: a user's folder, or another battery's, is never written into.)
    with OwnedFolder(args.output, "battery"):
        if not any((args.output / "runs" / spec.Name() / RESULT).exists() for spec in specs):
            parser.error(f"--output {args.output}: holds no SAGG-RIAC run of these arguments")
        all_runs = Analyse(specs, args.output, command)
    if args.doc:  # (The command that rewrites the block runs nothing.)
        again = command if args.analyse_only else f"{command} --analyse-only"
        groups = list(dict.fromkeys(spec.Label() for spec in specs))
        WriteGeneratedTable(
            args.doc, args.doc_table, again, "\n".join(Issue34Lines(all_runs, groups))
        )
    print(
        f"done in {time.perf_counter() - started:.1f} s; report: {args.output / 'report.md'}",
        flush=True,
    )


if __name__ == "__main__":
    main()
