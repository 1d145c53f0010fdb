"""What both parts of the adaptive-space experiment (issue 38) report alike: the runs by
setting, the changes of a space by rule, and the families of paired comparisons (maintained
minus fixed on each space; the roadmap, fixed and maintained, minus the fixed lattice)."""

import collections
from collections.abc import Iterable

import numpy as np

from mobee_drake.experiments.statistics import PairedBySeed
from mobee_drake.planning.space_maintenance import RULES

# Each space as it began, and the same maintained by the rules (both parts' runs).
CONDITIONS = ("fixed", "maintained")


def BySetting(runs: Iterable, fields: tuple[str, ...]) -> dict[tuple, list]:
    """The runs by their values of ``fields`` (the last the condition), sorted; each group in
    seed order."""
    groups = collections.defaultdict(list)
    for r in sorted(runs, key=lambda r: r.seed):
        groups[tuple(getattr(r, f) for f in fields)].append(r)
    return dict(sorted(groups.items()))


def ChangesCell(runs: list) -> str:
    """A report cell: the runs' mean changes per rule, in the order of ``RULES``."""
    return "/".join(f"{np.mean([r.changes.get(rule, 0) for r in runs]):.0f}" for rule in RULES)


def NearnessLines(nearness: dict[str, dict[str, float]]) -> list[str]:
    """Report lines: how near each space's states, as it began, lie to the arm's valid
    configurations (``nearness``: per robot and space, the valid configurations' mean distance
    to the nearest state's centre, fractions of range: the dispersion of the states
    themselves); none without any."""
    if not nearness:
        return []
    spaces = "; ".join(
        f"{robot}, " + ", ".join(f"{space} {d:.3f}" for space, d in by_space.items())
        for robot, by_space in nearness.items()
    )
    return [
        "",
        "How near the spaces' states, as they began, lie to the arm's valid configurations (the "
        f"mean distance from them to the nearest state, fractions of range): {spaces}.",
    ]


def SpaceComparisons(
    groups: dict[tuple, list], lattice: str, measures: dict, family: str = ""
) -> list[str]:
    """Report lines: the paired comparisons of ``groups`` (:func:`BySetting`'s, keyed by
    robot, space, any other fields, then condition) on each of ``measures`` (run -> value): on
    each space, maintained minus fixed; and where they ran, the roadmap ("trm"), fixed and
    maintained, minus the fixed ``lattice`` (the second is ch. 9.4.5's whole proposal, a space
    placed for the task and reshaped by what is learned, against the source's space); Holm over
    them all, a ``family`` of their own (named in the heading: what it learned, what it cost)."""
    maintained = {
        " ".join([robot, space, *more]) + ", maintained minus fixed": tuple(
            groups.get((robot, space, *more, condition), [])
            for condition in ("maintained", "fixed")
        )
        for robot, space, *more in sorted({key[:-1] for key in groups})
    }
    labels = {
        "fixed": f"trm minus {lattice} (both fixed)",
        "maintained": f"trm maintained minus {lattice} fixed",
    }
    roadmap = {}
    for robot, *more in sorted({(key[0], *key[2:-1]) for key in groups}):
        grid = groups.get((robot, lattice, *more, "fixed"), [])
        for condition, label in labels.items():
            trm = groups.get((robot, "trm", *more, condition), [])
            if trm and grid:
                roadmap[" ".join([robot, *more]) + f", {label}"] = (trm, grid)
    heading = "Maintained minus fixed" + (f" and trm minus {lattice}" if roadmap else "")
    heading += f", {family}" if family else ""
    return PairedBySeed(maintained | roadmap, measures, heading)
