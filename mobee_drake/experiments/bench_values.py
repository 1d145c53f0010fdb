"""Benchmark: the reach learner's value iteration (Alg. 7) with T sparse, against T dense.

The reach learner keeps T as a sparse array: a transition's row holds the outcomes it observed,
a reach's row is empty. Before, T was a dense (state-actions x states) array, so each sweep of
value iteration read every state of every state-action; on a roadmap that ``develop`` grew
(ch. 9.4.5) that is tens of millions of numbers a sweep, a sweep being what the learner plans
with before every action.

For each size (states, transitions) a model like a learner's is drawn: each transition from a
random state to another, its counts Alg. 6's initialisation (the curious agent's, as the MDP a
learner starts from) and ``--outcomes`` more outcomes observed in random states; one reach per
state; rewards drawn in [-10, 1] (eq. 8.1's penalty to eq. 8.4's best). Value iteration runs
with the learner's gamma and delta on the same T sparse and dense, best of ``--repeats``; the
table gives both times, their ratio and the largest difference of the values (summation order).

Run: ``mobee-drake bench values [--sizes 81x432 80x620 432x55054] [--doc docs/benchmarks.md]``;
the generated table's command names the BLAS thread counts its environment set.
The default sizes are the rank-3 lattice, the roadmap of 80 states and the roadmap that the
reaching battery's first developed run (iCub, greedy, seed 0) ended with.
"""

import argparse
import os
import time

import numpy as np

from mobee_drake.experiments.arguments import CommandParser, PositiveInt
from mobee_drake.experiments.battery import BLAS_THREADS
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable
from mobee_drake.planning.explorers import Explorer, ExplorerConfig
from mobee_drake.planning.state_space import StateActionSpace
from mobee_drake.planning.value_iteration import ValueIteration
from mobee_drake.reaching.learner import ReachLearningConfig, SortedTransitions

DOC_TABLE = "value iteration"
DEFAULT_SIZES = ("81x432", "80x620", "432x55054")


def Size(text: str) -> tuple[int, int]:
    """'STATESxTRANSITIONS' (at least 2 states, at least 1 transition)."""
    states, _, transitions = text.partition("x")
    try:
        size = int(states), int(transitions)
    except ValueError:
        size = (0, 0)
    if size[0] < 2 or size[1] < 1:
        raise argparse.ArgumentTypeError(f"'{text}' is not STATESxTRANSITIONS (e.g. 81x432)")
    return size


def LearnerModel(states: int, transitions: int, outcomes: int, seed: int = 0):
    """(T sparse, rewards, each state-action's state), in value iteration's order, of a
    model like a reach learner's (see the module)."""
    rng = np.random.default_rng(seed)
    start = np.sort(rng.integers(states, size=transitions))
    goal = (start + rng.integers(1, states, size=transitions)) % states
    space = StateActionSpace(rng.random((states, 2)), start, goal)
    counts = Explorer(space, ExplorerConfig()).transitions  # (Alg. 6's initialisation)
    for _ in range(outcomes):
        for sa, outcome in enumerate(rng.integers(states, size=transitions)):
            counts.Observe(sa, outcome)
    action_state = np.concatenate([start, np.arange(states)])  # (then one reach per state)
    order = np.argsort(action_state, kind="stable")
    T = SortedTransitions(counts.Probabilities(), order)
    rewards = rng.uniform(-10.0, 1.0, size=transitions + states)[order]
    return T, rewards, action_state[order]


def _Best(repeats: int, solve) -> tuple[float, tuple]:
    times, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = solve()
        times.append(time.perf_counter() - start)
    return min(times), result


def Row(states: int, transitions: int, outcomes: int, repeats: int) -> str:
    """The table's row of a model of ``states`` and ``transitions`` (see the module)."""
    config = ReachLearningConfig()
    T, rewards, action_state = LearnerModel(states, transitions, outcomes)
    dense = T.toarray()

    def Solve(matrix):
        return lambda: ValueIteration(
            matrix, rewards, action_state, states, config.gamma, config.delta
        )

    sparse_seconds, (_, v_sparse) = _Best(repeats, Solve(T))
    dense_seconds, (_, v_dense) = _Best(repeats, Solve(dense))
    return (
        f"| {states:,} | {transitions:,} | {T.nnz:,} | {dense.nbytes / 2**20:,.1f} "
        f"| {dense_seconds * 1e3:,.2f} | {sparse_seconds * 1e3:,.2f} "
        f"| {dense_seconds / sparse_seconds:,.1f} | {np.max(np.abs(v_sparse - v_dense)):.1e} |"
    )


def main(argv=None) -> None:
    parser = CommandParser(prog="mobee-drake bench values", description=__doc__)
    parser.add_argument(
        "--sizes",
        type=Size,
        nargs="+",
        default=list(DEFAULT_SIZES),
        metavar="STATESxTRANSITIONS",
        help="the models' sizes",
    )
    parser.add_argument(
        "--outcomes", type=PositiveInt, default=1, help="outcomes observed per transition"
    )
    parser.add_argument("--repeats", type=PositiveInt, default=5, help="timings of each, best")
    parser.add_argument("--doc", help="a doc whose generated value-iteration table to rewrite")
    args = parser.parse_args(argv)
    CheckDocBlocks(parser, args.doc, DOC_TABLE)  # Checked before anything runs.
    sizes = [Size(size) if isinstance(size, str) else size for size in args.sizes]  # (defaults)
    lines = [
        "| states | transitions | stored entries of T | dense T (MiB) | dense (ms) "
        "| sparse (ms) | dense / sparse | largest V difference |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    print("\n".join(lines), flush=True)
    for states, transitions in sizes:
        lines.append(Row(states, transitions, args.outcomes, args.repeats))
        print(lines[-1], flush=True)
    if args.doc:
        named = " ".join(f"{s}x{t}" for s, t in sizes)
        threads = "".join(f"{n}={os.environ[n]} " for n in BLAS_THREADS if n in os.environ)
        command = (
            f"{threads}mobee-drake bench values --sizes {named} --outcomes {args.outcomes} "
            f"--repeats {args.repeats}"
        )
        WriteGeneratedTable(args.doc, DOC_TABLE, f"{command} --doc {args.doc}", "\n".join(lines))


if __name__ == "__main__":
    main()
