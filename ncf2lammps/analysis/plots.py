"""Plots: plain functions taking ``ax=None`` (matplotlib, headless).

Renders of the cell draw every bead as a disc of its true diameter, in depth order, so the face
that a viewer would see ends up on top (painter's algorithm); the cell is tiled ``repeat``
times like the paper's Fig. 4.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import EllipseCollection

__all__ = [
    "CAPTIONS",
    "VIEWS",
    "plot_histories",
    "plot_local_thickness",
    "plot_study",
    "render_cell",
    "render_views",
    "tile_cell",
]

#: View name -> (horizontal axis, vertical axis, depth axis, depth sign toward the viewer).
VIEWS = {
    "front": (0, 1, 2, 1.0),  # loop face, seen from +z
    "back": (0, 1, 2, -1.0),  # underlap face, seen from -z (mirrored in x)
    "side": (0, 2, 1, -1.0),  # seen from -y
}
#: View name -> panel caption.
CAPTIONS = {"front": "front (loop face)", "back": "back (underlap face)", "side": "side"}

_COLOURS = np.array(
    [[0.15, 0.15, 0.15], [0.45, 0.45, 0.45], [0.85, 0.2, 0.1], [0.2, 0.4, 0.8], [0.3, 0.7, 0.3]]
)


def tile_cell(positions, box_lengths, tilt_xy, repeat):
    """(N * rx * ry, 3) positions tiled over ``repeat`` cells of the (sheared) box, and rx * ry."""
    rx, ry = repeat
    a = np.array([box_lengths[0], 0.0, 0.0])
    b = np.array([tilt_xy, box_lengths[1], 0.0])
    shifts = np.array([i * a + j * b for i in range(rx) for j in range(ry)])
    return (positions[None, :, :] + shifts[:, None, :]).reshape(-1, 3), len(shifts)


def render_cell(
    positions: np.ndarray,
    diameter: np.ndarray,
    colour_index: np.ndarray,
    box_lengths: np.ndarray,
    view: str = "front",
    repeat: tuple[int, int] = (3, 2),
    tilt_xy: float = 0.0,
    ax=None,
):
    """Draw the beads of a cell seen from one side; returns the axes.

    Args:
        positions: (N, 3) um; diameter: (N,) um; colour_index: (N,) int (e.g. type id).
        box_lengths: (3,) um; tilt_xy: xy tilt of a sheared box (um).
        view: ``front`` (loop face, +z), ``back`` (underlap face, -z) or ``side`` (-y).
        repeat: cells tiled along the two box edges in the plane.
    """
    h, v, depth, sign = VIEWS[view]
    tiled, copies = tile_cell(
        positions, box_lengths, tilt_xy, repeat if view != "side" else (repeat[0], 1)
    )
    size = np.tile(diameter, copies)
    colours = _COLOURS[np.tile(colour_index, copies) % len(_COLOURS)]
    order = np.argsort(sign * tiled[:, depth], kind="stable")
    # Shade by depth so that layers read apart.
    z = sign * tiled[order, depth]
    shade = 0.55 + 0.45 * (z - z.min()) / max(np.ptp(z), 1e-12)
    x = tiled[order, h] * (-1.0 if view == "back" else 1.0)
    y = tiled[order, v]
    if ax is None:
        _, ax = plt.subplots(figsize=(10, 10 * max(np.ptp(y), 1) / max(np.ptp(x), 1) + 0.6))
    discs = EllipseCollection(
        size[order],
        size[order],
        np.zeros(len(order)),
        units="xy",
        offsets=np.column_stack([x, y]),
        offset_transform=ax.transData,
        facecolors=np.clip(colours[order] * shade[:, None], 0, 1),
        edgecolors="none",
    )
    ax.add_collection(discs)
    pad = float(size.max())
    ax.set_xlim(x.min() - pad, x.max() + pad)
    ax.set_ylim(y.min() - pad, y.max() + pad)
    ax.set_aspect("equal")
    ax.set_xlabel(["x", "y", "z"][h] + " (um)" + (" mirrored" if view == "back" else ""))
    ax.set_ylabel(["x", "y", "z"][v] + " (um)")
    return ax


def render_views(positions, diameter, colour_index, box_lengths, title: str, tilt_xy: float = 0.0):
    """Figure with front, back and side renders of a 3 x 2 tiling; returns the figure."""
    fig, axes = plt.subplots(3, 1, figsize=(11, 13), gridspec_kw={"height_ratios": [3, 3, 1.2]})
    for ax, view in zip(axes, ("front", "back", "side"), strict=True):
        render_cell(positions, diameter, colour_index, box_lengths, view, tilt_xy=tilt_xy, ax=ax)
        ax.set_title(f"{title}: {CAPTIONS[view]}")
    fig.tight_layout()
    return fig


def plot_histories(time, series: list[tuple[str, np.ndarray, float | None, bool]], title: str):
    """Stacked time histories sharing the time axis (us); returns the figure.

    ``series``: (label, values, reference line or None, logarithmic) per panel.
    """
    fig, axes = plt.subplots(len(series), 1, figsize=(7, 2.3 * len(series)), sharex=True)
    for ax, (label, values, reference, log) in zip(np.atleast_1d(axes), series, strict=True):
        if log:
            ax.semilogy(time, np.maximum(values, 1e-12))
        else:
            ax.plot(time, values)
        if reference is not None:
            ax.axhline(reference, ls="--", c="k", lw=0.8)
        ax.set_ylabel(label)
    np.atleast_1d(axes)[0].set_title(title)
    np.atleast_1d(axes)[-1].set_xlabel("time (us)")
    fig.tight_layout()
    return fig


def plot_local_thickness(step, thickness_mm, fvf, title: str):
    """Local thickness (min, mean, max over the grid) against step, and the last frame's local
    Vf map. ``step`` (F,); ``thickness_mm``, ``fvf`` (F, nx, ny). Returns the figure."""
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.8))
    flat = thickness_mm.reshape(len(step), -1)
    left.fill_between(step, np.nanmin(flat, 1), np.nanmax(flat, 1), alpha=0.3, label="min-max")
    left.plot(step, np.nanmean(flat, 1), label="mean")
    left.set_xlabel("step")
    left.set_ylabel("local thickness (mm)")
    left.legend(fontsize=8)
    image = right.imshow(fvf[-1].T, origin="lower", cmap="viridis", aspect="auto")
    fig.colorbar(image, ax=right, label="local Vf")
    right.set_xlabel("grid cell along a (x)")
    right.set_ylabel("grid cell along b (y)")
    right.set_title(f"step {int(step[-1])}")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_study(wall_s, error, front, labels, tolerance: float, reference: int):
    """Log-log maximum relative error against wall time, the Pareto front joined; returns the
    figure. The reference point (error 0) is drawn on the lower edge."""
    wall_s = np.asarray(wall_s, dtype=float)
    error = np.asarray(error, dtype=float)
    finite = np.isfinite(error) & (error > 0)
    floor = 0.3 * float(error[finite].min()) if np.any(finite) else 1e-4
    shown = np.where(np.isfinite(error), np.maximum(error, floor), np.nan)
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.loglog(wall_s, shown, "o", c="0.6", label="study point")
    order = np.flatnonzero(front)[np.argsort(wall_s[front])]
    ax.loglog(wall_s[order], shown[order], "-o", c="C3", label="Pareto front")
    ax.loglog(wall_s[reference], shown[reference], "s", c="k", label="reference (error 0)")
    ax.axhline(tolerance, ls="--", c="k", lw=0.8, label=f"{tolerance:.0%} tolerance")
    for x, y, text in zip(wall_s, shown, labels, strict=True):
        if np.isfinite(y):
            ax.annotate(text, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.set_xlabel("wall time (s)")
    ax.set_ylabel("largest relative error of the outputs")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig
