"""Plotting for the experiments' reports: the one place that chooses matplotlib's backend (Agg:
files, no window), and what every figure shares: a legend naming each colour, stacked bars, and
saving. Every axes of a figure gets x and y labels (units in brackets), a caption-like title and
a legend or a colour bar (``tests/test_figures.py`` checks)."""

import matplotlib

matplotlib.use("Agg")

from matplotlib.figure import Figure  # noqa: E402 (after the backend is chosen)
from matplotlib.patches import Patch  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

__all__ = ["plt", "Figure", "Legend", "SaveFigure", "StackedBars"]


def Legend(axis, colours: dict | None = None, title: str | None = None) -> None:
    """A legend beside ``axis`` (outside it, so it hides no data) naming its labelled artists
    and, in ``colours`` (label: colour), the colours no single artist carries (bars coloured one
    by one, shaded spans)."""
    handles, labels = axis.get_legend_handles_labels()
    for label, colour in (colours or {}).items():
        handles.append(Patch(color=colour, label=label))
        labels.append(label)
    axis.legend(
        handles,
        labels,
        title=title,
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize="small",
        title_fontsize="small",
    )


def StackedBars(axis, stack: np.ndarray, labels: list[str], x=None, width: float = 1.0) -> None:
    """Bars of the rows of ``stack`` stacked in colours (e.g. one bar per state-action, one
    colour per run: Fig. 7.2-7.7), with a legend: ``labels[i]`` names row i's colour; rows with
    the same label share their colour (e.g. a seed's evaluations, Fig. 8.2), split by thin white
    edges."""
    x = np.arange(stack.shape[1]) if x is None else x
    bottom = np.zeros(stack.shape[1])
    shared = len(set(labels)) < len(labels)
    colours = {}
    for row, label in zip(stack, labels, strict=True):
        first = label not in colours
        colour = colours.setdefault(label, f"C{len(colours)}")
        axis.bar(
            x,
            row,
            bottom=bottom,
            width=width,
            color=colour,
            edgecolor="white",
            linewidth=0.5 if shared else 0.0,
            label=label if first else None,
        )
        bottom += row
    Legend(axis)


def SaveFigure(figure, path, dpi: int = 80) -> None:
    """Lays ``figure`` out, writes it to ``path`` and frees it."""
    figure.tight_layout()
    figure.savefig(path, dpi=dpi)
    plt.close(figure)
