"""Plots: plain functions taking ``ax=None`` (matplotlib's object API: no pyplot, no backend).

A function given ``ax`` draws on it; without one it draws on a new
:class:`~matplotlib.figure.Figure`, which saves to PNG with no backend chosen, so importing or
calling these keeps a Jupyter user's backend. Functions whose panels share a layout (the three
face views sized to the cell, stacked histories sharing the time axis, a curve beside its
colour map) draw and return a whole figure; each says so.

Renders of the cell draw every bead as a disc of its true diameter, in depth order, so the face
that a viewer would see ends up on top (painter's algorithm); the cell is tiled ``repeat``
times like the paper's Fig. 4.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.collections import EllipseCollection
from matplotlib.figure import Figure

from .compaction import EXPERIMENT, PAPER_MODEL_THICKNESS_1KPA_MM
from .shear import EXPERIMENT_FORCE_45DEG_N_PER_M, PAPER_MODEL_FORCE_45DEG_N_PER_M, SENSE_GROUPS

__all__ = [
    "CAPTIONS",
    "VIEWS",
    "paper_comparable",
    "plot_compaction",
    "plot_histories",
    "plot_local_thickness",
    "plot_shear",
    "plot_stitch_tension",
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


def _project(positions, diameter, colour_index, box_lengths, view, repeat, tilt_xy):
    """Discs of one view in drawing order: (M,) x, y, size (um) and (M, 3) RGB."""
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
    return x, tiled[order, v], size[order], np.clip(colours[order] * shade[:, None], 0, 1)


def _extent(x, y, size) -> tuple[float, float]:
    """Width and height (um) of a view's axes limits: the disc centres padded by the largest."""
    pad = 2.0 * float(size.max())
    return float(np.ptp(x)) + pad, float(np.ptp(y)) + pad


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
    h, v, _, _ = VIEWS[view]
    x, y, size, facecolors = _project(
        positions, diameter, colour_index, box_lengths, view, repeat, tilt_xy
    )
    if ax is None:
        width, height = _extent(x, y, size)
        ax = Figure(figsize=(10, 10 * height / width + 0.6)).subplots()
    discs = EllipseCollection(
        size,
        size,
        np.zeros(len(size)),
        units="xy",
        offsets=np.column_stack([x, y]),
        offset_transform=ax.transData,
        facecolors=facecolors,
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


#: Margins of each face-view panel (inches): left (y label), right, top (title), bottom (x label).
_PANEL_MARGINS_IN = (0.95, 0.25, 0.35, 0.55)


def render_views(
    positions,
    diameter,
    colour_index,
    box_lengths,
    title: str,
    tilt_xy: float = 0.0,
    width_in: float = 11.0,
    max_height_in: float = 16.0,
):
    """Figure of the front, back and side renders of a 3 x 2 tiling; returns the figure.

    A whole figure, so that each panel's height follows its view's extent at the cell's aspect
    ratio and the panels fill the canvas: ``width_in`` wide (narrower where the stacked panels
    would be taller than ``max_height_in``). Arguments as in :func:`render_cell`.
    """
    left, right, top, bottom = _PANEL_MARGINS_IN
    views = ("front", "back", "side")
    extents = [
        _extent(
            *_project(positions, diameter, colour_index, box_lengths, view, (3, 2), tilt_xy)[:3]
        )
        for view in views
    ]
    aspects = [height / width for width, height in extents]
    overhead = len(views) * (top + bottom)
    axes_width = min(width_in - left - right, (max_height_in - overhead) / sum(aspects))
    heights = [axes_width * a for a in aspects]
    fig_width, fig_height = axes_width + left + right, sum(heights) + overhead
    fig = Figure(figsize=(fig_width, fig_height))
    upper = fig_height
    for view, height in zip(views, heights, strict=True):
        upper -= top + height
        box = (left / fig_width, upper / fig_height, axes_width / fig_width, height / fig_height)
        ax = fig.add_axes(box)
        render_cell(positions, diameter, colour_index, box_lengths, view, tilt_xy=tilt_xy, ax=ax)
        ax.set_title(f"{title}: {CAPTIONS[view]}")
        upper -= bottom
    return fig


def plot_compaction(results: dict, ax=None, label: str | None = None, paper_marks: bool = True):
    """Pressure against plate gap with the paper's experiment and model marked (``paper_marks``:
    the paper's 0/90 fabric; off for another); returns the axes.

    ``results``: the dict of :func:`~ncf2lammps.io.results.read_results` (its ``compaction``
    group: ``gap_mm``, ``pressure_kPa``, ``pressure_smoothed_kPa``, attrs). Without ``label``
    the run's own figure: raw and smoothed curves, the thickness at 1 and 18 kPa circled, the
    plate speed in the title. With ``label``: the smoothed curve so named, to compare runs on
    one axes (pressure axis up to 100 kPa). The paper's marks are drawn once per axes.
    """
    group = results["compaction"]
    attrs = group["attrs"]
    if ax is None:
        ax = Figure(figsize=(6.5, 4.5)).subplots()
    top = 100.0
    if label is None:
        ax.plot(group["gap_mm"], group["pressure_kPa"], lw=0.6, alpha=0.5, label="this run (raw)")
        ax.plot(
            group["gap_mm"], group["pressure_smoothed_kPa"], lw=1.5, label="this run (smoothed)"
        )
        for t, p in ((attrs["thickness_at_1kPa_mm"], 1.0), (attrs["thickness_at_18kPa_mm"], 18.0)):
            if math.isfinite(t):
                ax.plot([t], [p], "o", mfc="none", mec="C1")
        top = max(top, float(np.nanmax(group["pressure_kPa"])) * 1.2)
        ax.set_title(f"compaction at {attrs['plate_speed_m_s']:.3g} m/s")
    else:
        ax.plot(group["gap_mm"], group["pressure_smoothed_kPa"], lw=1.2, label=label)
    if paper_marks and not _has_paper_marks(ax):
        ax.plot(*zip(*EXPERIMENT, strict=True), "ks", gid="paper", label="experiment (paper)")
        ax.plot(
            [PAPER_MODEL_THICKNESS_1KPA_MM], [1.0], "r^", gid="paper", label="paper model at 1 kPa"
        )
    ax.set_yscale("log")
    ax.set_ylim(0.05, top)
    ax.set_xlabel("thickness = plate gap (mm)")
    ax.set_ylabel("pressure (kPa)")
    ax.legend(fontsize=8)
    return ax


def plot_shear(results: dict, ax=None, label: str | None = None, paper_marks: bool = True):
    """Normalised shear force F_N against shear angle with the paper's values at 45 deg
    (``paper_marks``: the paper's 0/90 fabric; off for another); returns the axes.

    ``results``: the dict of :func:`~ncf2lammps.io.results.read_results` (its ``shear`` and
    ``shear_negative`` groups, the positive and negative senses, as far as run: ``angle_deg``,
    ``force_N_per_m``, ``force_work_N_per_m``, attrs). Without ``label`` the run's own figure:
    virial and work F_N of each sense, the shear rate in the title. With ``label``: the virial
    F_N of each sense so named, to compare runs on one axes. The paper's marks are drawn once
    per axes.
    """
    groups = {s: results[g] for s, g in SENSE_GROUPS.items() if g in results}
    if ax is None:
        ax = Figure(figsize=(6.5, 4.5)).subplots()
    suffixes = {s: f", {s}" if len(groups) > 1 else "" for s in groups}
    for sense, group in groups.items():
        angle, virial = group["angle_deg"], group["force_N_per_m"]
        if label is None:
            ax.plot(angle, virial, lw=1.2, label=f"virial{suffixes[sense]}")
            work_label = f"work dW/(A dg){suffixes[sense]}"
            ax.plot(angle, group["force_work_N_per_m"], "--", lw=1.0, label=work_label)
        else:
            ax.plot(angle, virial, lw=1.0, label=f"{label}{suffixes[sense]}")
    if label is None:
        rate = next(iter(groups.values()))["attrs"]["shear_rate_deg_us"]
        ax.set_title(f"picture-frame shear at {rate:.3g} deg/us")
    if paper_marks and not _has_paper_marks(ax):
        experiment = f"experiment (paper), ~{EXPERIMENT_FORCE_45DEG_N_PER_M:g} N/m"
        model = f"paper model, {PAPER_MODEL_FORCE_45DEG_N_PER_M:g} N/m"
        ax.plot([45.0], [EXPERIMENT_FORCE_45DEG_N_PER_M], "ks", gid="paper", label=experiment)
        ax.plot([45.0], [PAPER_MODEL_FORCE_45DEG_N_PER_M], "r^", gid="paper", label=model)
    ax.set_yscale("symlog", linthresh=0.1)
    ax.set_xlabel("shear angle (deg)")
    ax.set_ylabel("normalised shear force F_N (N/m)")
    ax.legend(fontsize=8)
    return ax


def plot_stitch_tension(results: dict, ax=None):
    """Mean and largest stitch bond tension (N) against shear angle of every sense run (the
    evidence of which sense stretches the stitch), broken bonds marked; returns the axes.

    ``results``: as :func:`plot_shear`, groups with ``stitch_angle_deg``,
    ``stitch_tension_mean_N``, ``stitch_tension_max_N`` (and ``stitch_bonds_broken``).
    """
    groups = {s: results[g] for s, g in SENSE_GROUPS.items() if g in results}
    if ax is None:
        ax = Figure(figsize=(6.5, 4.5)).subplots()
    for index, (sense, group) in enumerate(groups.items()):
        angle = group["stitch_angle_deg"]
        colour = f"C{index}"
        ax.plot(angle, group["stitch_tension_mean_N"], lw=1.2, color=colour, label=f"mean, {sense}")
        ax.plot(
            angle,
            group["stitch_tension_max_N"],
            "--",
            lw=1.0,
            color=colour,
            label=f"largest, {sense}",
        )
        broken = group.get("stitch_bonds_broken")
        if broken is not None and np.any(broken > 0):
            first = int(np.argmax(broken > 0))
            ax.axvline(angle[first], color=colour, lw=0.8, ls=":", label=f"first break, {sense}")
    ax.set_xlabel("shear angle (deg)")
    ax.set_ylabel("stitch bond tension (N)")
    ax.legend(fontsize=8)
    return ax


def paper_comparable(ply_angles_deg) -> bool:
    """Whether the paper's marks belong on a run's figures: a fabric of 0 and 90 deg plies only
    (the paper's experiment is a 0/90 NCF)."""
    return set(np.round(np.asarray(ply_angles_deg, dtype=float), 9)) <= {0.0, 90.0}


def _has_paper_marks(ax) -> bool:
    """Whether the paper's marks are already on ``ax``."""
    return any(line.get_gid() == "paper" for line in ax.get_lines())


def plot_histories(time, series: list[tuple[str, np.ndarray, float | None, bool]], title: str):
    """Stacked time histories sharing the time axis (us); returns the figure (a whole one: the
    panels share the time axis).

    ``series``: (label, values, reference line or None, logarithmic) per panel.
    """
    fig = Figure(figsize=(7, 2.3 * len(series)))
    axes = fig.subplots(len(series), 1, sharex=True)
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
    Vf map. ``step`` (F,); ``thickness_mm``, ``fvf`` (F, nx, ny). Returns the figure (a whole
    one: the map's colour bar takes its own axes)."""
    fig = Figure(figsize=(10, 3.8))
    left, right = fig.subplots(1, 2)
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


def plot_study(wall_s, error, front, labels, tolerance: float, reference: int, ax=None):
    """Log-log maximum relative error against wall time, the Pareto front joined; returns the
    figure (``ax``'s, if given). The reference point (error 0) is drawn on the lower edge.

    ``wall_s``, ``error``: (P,) per study point (s, relative); ``front``: (P,) bool;
    ``labels``: (P,) point names; ``reference``: index of the reference point.
    """
    wall_s = np.asarray(wall_s, dtype=float)
    error = np.asarray(error, dtype=float)
    finite = np.isfinite(error) & (error > 0)
    floor = 0.3 * float(error[finite].min()) if np.any(finite) else 1e-4
    shown = np.where(np.isfinite(error), np.maximum(error, floor), np.nan)
    own = ax is None
    if own:
        ax = Figure(figsize=(6.4, 4.4)).subplots()
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
    if own:
        ax.figure.tight_layout()
    return ax.figure
