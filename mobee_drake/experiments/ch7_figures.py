"""The figures of the model-learning experiments of dissertation ch. 7 (Fig. 7.1-7.12), from
the runs' results (:mod:`mobee_drake.experiments.ch7_model_learning`)."""

import numpy as np

from mobee_drake.experiments.ch7_model_learning import UNRELIABLE, MovingBoxResult
from mobee_drake.experiments.exploration import ExplorationRun
from mobee_drake.experiments.plots import Figure, Legend, StackedBars, plt
from mobee_drake.planning.state_space import Lattice

COVERAGE_STATE_ACTIONS = 1296  # 7.2: 81 states x 16 nearest neighbours
TRIES = "tries [count]"
VALUE = "value V(s, a) [nats]"  # expected discounted KL reward (Alg. 6)
STATE_ACTION = "state-action [index]"


def HypercubeFigure(results: list[ExplorationRun]) -> Figure:
    """Fig. 7.2-7.3 on the hypercube: tries and values per state-action after 320 actions, one
    column per gamma, the runs stacked."""
    gammas = sorted({r.labels["gamma"] for r in results})
    figure, axes = plt.subplots(2, len(gammas), figsize=(6 * len(gammas), 6.5), squeeze=False)
    for column, gamma in enumerate(gammas):
        mine = [r for r in results if r.labels["gamma"] == gamma]
        for row, (key, unit) in enumerate((("tries", TRIES), ("values", VALUE))):
            axis = axes[row, column]
            StackedBars(
                axis,
                np.array([r.snapshots[320][key] for r in mine]),
                [f"run {r.labels['run']}" for r in mine],
            )
            axis.set(
                xlabel=STATE_ACTION,
                ylabel=f"{unit}, runs stacked",
                title=f"gamma {gamma}: {key} after 320 actions, {len(mine)} runs",
            )
    figure.suptitle("7.1, the right arm's hypercube (cf. Fig. 7.2-7.3)")
    return figure


def CoverageFigure(results: list[ExplorationRun]) -> Figure:
    """Fig. 7.5: state-actions tried against transitions, one line per run."""
    figure, axis = plt.subplots(figsize=(8, 4))
    # Solid under dashed under dotted: strategies whose lines coincide all stay visible.
    for strategy, colour, style, width in (
        ("curious", "tab:green", "-", 3.0),
        ("random", "tab:red", "--", 1.5),
        ("least_tried", "tab:blue", ":", 1.5),
    ):
        for r in [r for r in results if r.labels["strategy"] == strategy]:
            coverage = np.array(r.coverage)
            axis.plot(
                coverage[:, 0],
                coverage[:, 1],
                color=colour,
                linestyle=style,
                linewidth=width,
                label=strategy if r.labels["run"] == 0 else None,
            )
    axis.axhline(COVERAGE_STATE_ACTIONS, color="0.5", linestyle=":", label="all state-actions")
    runs = len({r.labels["run"] for r in results})
    axis.set(
        xlabel="transitions [count]",
        ylabel=f"state-actions tried [count, of {COVERAGE_STATE_ACTIONS}]",
        title=f"7.2, coverage of the rank-3 lattice (16 nearest neighbours),\n{runs} runs "
        "per strategy (cf. Fig. 7.5)",
    )
    Legend(axis, title="strategy (one line per run)")
    return figure


def Rank4Figure(r: ExplorationRun, space: Lattice, never: np.ndarray) -> Figure:
    """Fig. 7.8-7.9 on a rank-4 lattice: tries and values per state-action, coloured by their
    outcomes, and the actions taken from each state, the states never entered shaded."""
    tries, misses = np.array(r.tries[0]), np.array(r.misses[0])
    outcomes = {
        "several outcomes (>= 3 tries)": ("tab:red", (misses > 0) & (misses < 1) & (tries >= 3)),
        "never reaches its goal (>= 3 tries)": ("tab:orange", (misses == 1) & (tries >= 3)),
    }
    colours = np.full(len(tries), "tab:blue", dtype=object)
    for colour, chosen in outcomes.values():
        colours[chosen] = colour
    legend = {label: colour for label, (colour, _) in outcomes.items()}
    legend["reaches its goal, or tried < 3 times"] = "tab:blue"
    figure, axes = plt.subplots(3, 1, figsize=(13, 9))
    caption = f"{r.labels['lattice']} % lattice after {r.actions[0]} actions"
    for axis, heights, unit, what in (
        (axes[0], tries, TRIES, "tries"),
        (axes[1], r.values[0], VALUE, "value"),
    ):
        axis.bar(np.arange(len(tries)), heights, width=1.0, color=colours)
        axis.set(xlabel=STATE_ACTION, ylabel=unit, title=f"{caption}: {what} per state-action")
        Legend(axis, legend)
    visits = np.bincount(space.action_state, weights=tries, minlength=space.num_states)
    axes[2].bar(np.arange(space.num_states), visits, width=1.0, label="actions from the state")
    for state in never:
        axes[2].axvspan(state - 0.5, state + 0.5, color="grey", alpha=0.4)
    axes[2].set(
        xlabel="state [index]",
        ylabel="actions taken [count]",
        title=f"{caption}: actions taken from each state",
    )
    Legend(axes[2], {"never entered": ("grey", 0.4)})
    return figure


def InitializationFigure(results: list[ExplorationRun], initialization: str) -> Figure:
    """Fig. 7.6-7.7: tries and values per state-action after every state-action was tried 5
    times, one pair of rows per gamma, the runs stacked."""
    mine = [r for r in results if r.labels["initialization"] == initialization]
    gammas = sorted({r.labels["gamma"] for r in mine})
    figure, axes = plt.subplots(2 * len(gammas), 1, figsize=(13, 5.2 * len(gammas)), squeeze=False)
    for row, gamma in enumerate(gammas):
        runs = [r for r in mine if r.labels["gamma"] == gamma]
        for offset, (key, unit) in enumerate((("tries", TRIES), ("values", VALUE))):
            axis = axes[2 * row + offset, 0]
            StackedBars(
                axis,
                np.array([getattr(r, key)[0] for r in runs]),
                [f"run {r.labels['run']}" for r in runs],
            )
            axis.set(
                xlabel=STATE_ACTION,
                ylabel=f"{unit}, runs stacked",
                title=f"{initialization} initialisation, gamma {gamma}: {key} per state-action "
                f"once each was tried 5 times, {len(runs)} runs",
            )
    return figure


def MovingBoxFigure(results: MovingBoxResult) -> Figure:
    """Ch. 7.4.1: the share of tries reaching the goal per state-action, learned among the
    moving box and without it, the state-actions found unreliable shaded."""
    figure, axis = plt.subplots(figsize=(13, 4))
    for offset, (trained, label) in enumerate(
        (("moving_box", "learned among the moving box"), ("no_box", "learned without it"))
    ):
        reliability = results.planners[trained].reliability
        axis.bar(np.arange(len(reliability)) + 0.4 * offset, reliability, width=0.4, label=label)
    for sa in results.unreliable:
        axis.axvspan(sa - 0.3, sa + 0.7, color="red", alpha=0.15)
    axis.set(
        xlabel=STATE_ACTION,
        ylabel="tries reaching the goal [fraction]",
        title="7.4.1, the right arm's hypercube: reliability of each state-action "
        "(1 when tried < 5 times)",
    )
    Legend(axis, {f"unreliable (< {UNRELIABLE:.0%} among the box)": ("red", 0.15)})
    return figure


def ThreeAgentsFigure(results: ExplorationRun) -> Figure:
    """Fig. 7.10-7.12: each agent's tries per state-action, exploring together by a table."""
    figure, axes = plt.subplots(3, 1, figsize=(13, 9))
    for axis, name, tries, actions in zip(axes, results.agents, results.tries, results.actions):
        axis.bar(np.arange(len(tries)), tries, label=f"{name}, {actions} actions")
        axis.set(
            xlabel=STATE_ACTION,
            ylabel=TRIES,
            title=f"7.4, three agents by a table ({sum(results.actions)} transitions in "
            f"all): {name}'s tries per state-action",
        )
        Legend(axis)
    return figure
