"""Plots of the validation cases (matplotlib's object API, no backend; functions writing PNGs)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

__all__ = ["line_plot"]


def line_plot(
    path: Path,
    curves: Sequence[tuple[np.ndarray, np.ndarray, str]],
    xlabel: str,
    ylabel: str,
    title: str,
    styles: Sequence[str] | None = None,
    log_y: bool = False,
) -> Path:
    """Write one axes of ``(x, y, label)`` curves to ``path`` (PNG); returns ``path``.

    ``styles`` are matplotlib format strings, one per curve (default: lines); ``log_y`` draws
    the y axis logarithmic.
    """
    fig = Figure(figsize=(6.0, 4.0), dpi=110)
    ax = fig.subplots()
    for i, (x, y, label) in enumerate(curves):
        ax.plot(x, y, styles[i] if styles else "-", label=label)
    if log_y:
        ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    return path
