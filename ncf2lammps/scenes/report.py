"""Figures and summary.md of a run folder, from results.h5 and the state files written by scenes."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..io.results import read_results
from .build import SCENES, scene_module

__all__ = ["write_report"]


def _format(value) -> str:
    if isinstance(value, float | np.floating):
        return f"{value:.5g}"
    if isinstance(value, bytes):
        return value.decode()
    return str(value)


#: Per-scene error indicators shown first in summary.md: (scene, attribute, attribute of its
#: limit; "" when there is none).
INDICATORS = (
    ("manufacture", "stitch_tension_error", "tension_tolerance"),
    ("manufacture", "kinetic_ratio", "kinetic_ratio_target"),
    ("compaction", "max_kinetic_ratio", "kinetic_ratio_target"),
    ("compaction", "plate_force_imbalance", ""),
    ("shear", "max_kinetic_ratio", "kinetic_ratio_target"),
    ("shear", "work_virial_max_deviation", ""),
)


def _indicator_lines(results: dict) -> list[str]:
    """The error-indicator table: time-step margin, then each scene's checks, wall time, steps."""
    root = results["attrs"]
    lines = [
        "## Error indicators",
        "",
        "| scene | indicator | value | limit |",
        "|---|---|---|---|",
    ]
    if "dt_margin" in root:
        lines.append(
            f"| all | time step {_format(root['dt_us'])} us, margin to the stable limit"
            f" ({_format(root['dt_governing'])}) | {_format(root['dt_margin'])} | > 1 |"
        )
    for scene in SCENES:
        if scene not in results:
            continue
        attrs = results[scene]["attrs"]
        for indicator_scene, key, limit_key in INDICATORS:
            if indicator_scene == scene and key in attrs:
                limit = _format(attrs[limit_key]) if limit_key in attrs else ""
                lines.append(f"| {scene} | {key} | {_format(attrs[key])} | {limit} |")
        lines.append(
            f"| {scene} | wall time (s), steps | {_format(attrs.get('wall_s', float('nan')))},"
            f" {_format(attrs.get('steps', ''))} | |"
        )
    return [*lines, ""]


def write_report(directory: str | os.PathLike) -> list[Path]:
    """Write figures/*.png and summary.md for the run in ``directory``; returns the files."""
    directory = Path(directory)
    results = read_results(directory / "results.h5")
    (directory / "figures").mkdir(exist_ok=True)
    written: list[Path] = []
    for scene in SCENES:
        if scene in results:
            written += scene_module(scene).figures(results, directory)
    root = results["attrs"]
    lines = [
        "# ncf2lammps run summary",
        "",
        f"ncf2lammps {_format(root['ncf2lammps_version'])}, LAMMPS {_format(root['lammps_version'])},"
        f" {_format(root['n_atoms'])} atoms, {_format(root['n_bonds'])} bonds,"
        f" {_format(root['mpi_ranks'])} MPI rank(s), created {_format(root['created'])};"
        f" complete: {bool(root['complete'])}.",
        "",
        *_indicator_lines(results),
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
