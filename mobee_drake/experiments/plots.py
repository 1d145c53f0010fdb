"""Plotting for the experiments' reports: the one place that chooses matplotlib's backend (Agg:
files, no window), and the figure kinds more than one experiment draws."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402 (after the backend is chosen)
import numpy as np  # noqa: E402

__all__ = ["plt", "StackedBars"]


def StackedBars(axis, stack: np.ndarray, x=None, width: float = 1.0, title: str = "") -> None:
    """Bars of the rows of ``stack`` stacked in colours (e.g. one bar per state-action, one
    colour per run: Fig. 7.2-7.7)."""
    x = np.arange(stack.shape[1]) if x is None else x
    bottom = np.zeros(stack.shape[1])
    for row in stack:
        axis.bar(x, row, bottom=bottom, width=width)
        bottom += row
    if title:
        axis.set_title(title)
