"""Figures and summary.md of a run folder, from results.h5 and the state files written by scenes."""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from ..analysis.plots import render_views
from ..io.datafile import read_data
from ..io.results import read_results

__all__ = ["write_report"]


def _history_figure(group: dict, title: str):
    """Stitch tension, thickness and kinetic ratio against time."""
    fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
    time = group["time_us"]
    axes[0].plot(time, group["stitch_tension_N"])
    axes[0].axhline(
        group["attrs"]["stitch_tension_target_N"], ls="--", c="k", lw=0.8, label="target"
    )
    axes[0].set_ylabel("stitch tension (N)")
    axes[0].legend()
    axes[1].plot(time, group["thickness_mm"])
    axes[1].set_ylabel("thickness (mm)")
    axes[2].semilogy(time, np.maximum(group["kinetic_ratio"], 1e-12))
    axes[2].axhline(group["attrs"]["kinetic_ratio_target"], ls="--", c="k", lw=0.8)
    axes[2].set_ylabel("kinetic / potential")
    axes[2].set_xlabel("time (us)")
    axes[0].set_title(title)
    fig.tight_layout()
    return fig


def _format(value) -> str:
    if isinstance(value, float | np.floating):
        return f"{value:.5g}"
    if isinstance(value, bytes):
        return value.decode()
    return str(value)


def write_report(directory: str | os.PathLike) -> list[Path]:
    """Write figures/*.png and summary.md for the run in ``directory``; returns the files."""
    directory = Path(directory)
    results = read_results(directory / "results.h5")
    figures = directory / "figures"
    figures.mkdir(exist_ok=True)
    written = []
    if "manufacture" in results and (directory / "manufactured.data").is_file():
        state = read_data(directory / "manufactured.data")
        fig = render_views(
            state.positions,
            state.diameter,
            state.type_id,
            state.box.hi - state.box.lo,
            "as manufactured",
        )
        written.append(figures / "manufacture_views.png")
        fig.savefig(written[-1], dpi=110)
        plt.close(fig)
        fig = _history_figure(results["manufacture"], "manufacture")
        written.append(figures / "manufacture_history.png")
        fig.savefig(written[-1], dpi=110)
        plt.close(fig)
    root = results["attrs"]
    lines = [
        "# ncf2lammps run summary",
        "",
        f"ncf2lammps {_format(root['ncf2lammps_version'])}, LAMMPS {_format(root['lammps_version'])},"
        f" {_format(root['n_atoms'])} atoms, {_format(root['n_bonds'])} bonds,"
        f" {_format(root['mpi_ranks'])} MPI rank(s), created {_format(root['created'])};"
        f" complete: {bool(root['complete'])}.",
        "",
    ]
    for scene, group in results.items():
        if scene == "attrs":
            continue
        lines += [f"## {scene}", "", "| quantity | value |", "|---|---|"]
        lines += [f"| {k} | {_format(v)} |" for k, v in sorted(group["attrs"].items())]
        lines += [""] + [
            f"![{p.stem}](figures/{p.name})" for p in written if p.stem.startswith(scene)
        ]
        lines.append("")
    (directory / "summary.md").write_text("\n".join(lines))
    written.append(directory / "summary.md")
    return written
