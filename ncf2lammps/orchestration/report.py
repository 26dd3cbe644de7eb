"""Figures and summary.md of a run folder, from results.h5 and the state files written by scenes."""

from __future__ import annotations

import logging
import os
import re
import tomllib
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from .. import __version__, units
from ..analysis.plots import plot_local_thickness
from ..analysis.shear import SENSE_GROUPS
from ..analysis.trajectory import local_thickness
from ..io.lammpslog import read_loop_times
from ..io.results import ResultsFileError, mark_complete, read_results, write_root, write_scene
from ..io.spectoml import dumps_spec
from ..numerics import prepare
from ..scenes import SCENES, applicable_scenes
from ..spec import SpecError, load_spec, spec_from_dict
from .folder import RunFolderError, check_run_folder

__all__ = ["collect_outputs", "trajectory_group", "write_report"]

_log = logging.getLogger(__name__)
_LAMMPS_VERSION = re.compile(r"^LAMMPS \((\d+) (\w{3})\w* (\d{4})")
_MONTHS = "Jan Feb Mar Apr May Jun Jul Aug Sep Oct Nov Dec".split()


def _lammps_version(log: Path) -> str:
    """``YYYYMMDD`` from the first line of a LAMMPS log, else ``unknown``."""
    if not log.is_file():
        return "unknown"
    match = _LAMMPS_VERSION.match(log.read_text(errors="replace").split("\n", 1)[0])
    if match is None:
        return "unknown"
    day, month, year = match.groups()
    return f"{year}{_MONTHS.index(month) + 1:02d}{int(day):02d}"


def collect_outputs(directory: str | os.PathLike) -> Path:
    """results.h5 of a run made without the Python driver (an exported bundle run by plain
    ``lmp``), from its spec.resolved.toml, logs and scene files; ``complete`` only if every
    scene of the spec finished (left its ``<scene>.final.txt``)."""
    directory = Path(directory)
    run = prepare(load_spec(directory / "spec.resolved.toml"))
    spec, model, step = run.spec, run.model, run.time_step
    scenes = [s for s in applicable_scenes(spec) if (directory / f"{s}.final.txt").is_file()]
    logs = [directory / f"log.{s}.lammps" for s in scenes]
    results = directory / "results.h5"
    write_root(
        results,
        {
            "ncf2lammps_version": __version__,
            "lammps_version": _lammps_version(directory / "log.lammps"),
            "spec_toml": dumps_spec(spec),
            "n_atoms": model.n_atoms,
            "n_bonds": model.n_bonds,
            "mpi_ranks": max((read_loop_times(log)[1] for log in logs), default=1),
            "created": datetime.fromtimestamp(
                (directory / "spec.resolved.toml").stat().st_mtime, UTC
            ).isoformat(timespec="seconds"),
            "driver": "plain lmp",
            "dt_us": step.dt,
            "dt_critical_us": step.critical,
            "dt_governing": step.governing,
            "dt_margin": step.margin,
        },
    )
    for scene, log in zip(scenes, logs, strict=True):
        attrs, datasets = SCENES[scene].collect(run, directory)
        attrs["wall_s"] = read_loop_times(log)[0]
        write_scene(results, scene, attrs, datasets)
    if scenes == list(applicable_scenes(spec)):
        mark_complete(results)
    return results


def _format(value) -> str:
    if isinstance(value, float | np.floating):
        return f"{value:.5g}"
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.ndarray):
        return f"array {value.shape} (results.h5)"
    return str(value)


def trajectory_group(scene: str) -> str:
    """The results.h5 group of a scene's local thickness and Vf (from its dump)."""
    return f"{scene}_trajectory"


def _trajectories(directory: Path, scenes) -> list[Path]:
    """Local thickness and Vf of each finished scene's dump (MDAnalysis): group
    ``<scene>_trajectory`` of results.h5 (grid mean, min and max per frame) and a figure (the
    dump of a scene a killed run left unfinished may end mid-frame: it is skipped)."""
    dumps = [(s, directory / f"{s}.lammpstrj") for s in SCENES if s in scenes]
    dumps = [(s, d) for s, d in dumps if d.is_file() and d.stat().st_size > 0]
    if not dumps:
        return []
    model = prepare(load_spec(directory / "spec.resolved.toml")).model
    written = []
    for scene, dump in dumps:
        try:
            local = local_thickness(dump, model).results
        except ValueError as err:  # not a dump of this model: the rest of the report stands
            _log.warning("no local thickness: %s", err)
            continue
        thickness = units.from_micro(local.thickness, "mm")
        frames = len(local.step)
        datasets = {"step": local.step}
        for name, values in (("thickness_mm", thickness), ("fvf", local.fvf)):
            flat = values.reshape(frames, -1)
            datasets[f"{name}_mean"] = np.nanmean(flat, axis=1)
            datasets[f"{name}_min"] = np.nanmin(flat, axis=1)
            datasets[f"{name}_max"] = np.nanmax(flat, axis=1)
        attrs = {"grid": str(local.fvf.shape[1:]), "source": dump.name}
        write_scene(directory / "results.h5", trajectory_group(scene), attrs, datasets)
        fig = plot_local_thickness(
            local.step, thickness, local.fvf, f"{scene}: local thickness, Vf"
        )
        written.append(directory / "figures" / f"{trajectory_group(scene)}.png")
        fig.savefig(written[-1], dpi=110)
    return written


#: Per-scene error indicators shown first in summary.md: (scene, attribute, attribute of its
#: limit; "" when there is none).
INDICATORS = (
    ("manufacture", "stitch_tension_error", "tension_tolerance"),
    ("manufacture", "kinetic_ratio", "kinetic_ratio_target"),
    ("manufacture", "stitch_creep_per_ms", "stitch_creep_target_per_ms"),
    ("compaction", "max_kinetic_thickness_error", "kinetic_thickness_error_limit"),
    ("compaction", "max_kinetic_stress_ratio", ""),
    ("compaction", "max_kinetic_ratio", ""),
    ("compaction", "plate_force_imbalance", ""),
    ("compaction", "energy_balance_residual", ""),
    *(
        (scene, key, limit)
        for scene in SENSE_GROUPS.values()
        for key, limit in (
            ("max_kinetic_stress_ratio", "kinetic_stress_limit"),
            ("max_kinetic_ratio", ""),
            ("work_virial_max_deviation", ""),
            ("energy_balance_residual", ""),
        )
    ),
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


def _shear_sense_lines(results: dict) -> list[str]:
    """F_N at 45 deg of each shear sense run (at the final angle of a shear that stops short of
    45 deg) and, with both, their ratio F_N+ / F_N-."""
    groups = {s: results[g]["attrs"] for s, g in SENSE_GROUPS.items() if g in results}
    groups = {s: a for s, a in groups.items() if "force_at_45deg_N_per_m" in a}
    if not groups:
        return []
    final = min(float(a["final_angle_deg"]) for a in groups.values())
    key, at = "force_at_45deg_N_per_m", "45"
    if final < 45.0 - 1e-6:
        key, at = "force_at_final_N_per_m", f"{final:.3g}"
    forces = {sense: float(a[key]) for sense, a in groups.items()}
    lines = ["## Shear senses", "", f"| sense | F_N at {at} deg (N/m) |", "|---|---|"]
    lines += [f"| {sense} | {_format(force)} |" for sense, force in forces.items()]
    if len(forces) == 2:
        ratio = forces["positive"] / forces["negative"] if forces["negative"] else float("nan")
        lines.append(f"| asymmetry F_N+({at}) / F_N-({at}) | {_format(ratio)} |")
    return [*lines, ""]


def _incomplete_lines(directory: Path, results: dict, finished, bundle: bool) -> list[str]:
    """The warning of a run that did not finish: the scenes it has and how to continue."""
    if bool(results["attrs"]["complete"]):
        return []
    try:
        stored = results["attrs"]["spec_toml"]
        spec = spec_from_dict(
            tomllib.loads(stored.decode() if isinstance(stored, bytes) else stored)
        )
        missing = [s for s in applicable_scenes(spec) if s not in finished]
    except (SpecError, tomllib.TOMLDecodeError, UnicodeDecodeError, TypeError):
        missing = []
    how = (
        "run the bundle's job again (finished scenes are skipped)"
        if bundle
        else f"continue it with `ncf2lammps run SPEC -o {directory} --resume`"
    )
    return [
        f"**Incomplete run**: the run did not finish; this report shows the scenes it finished"
        f" ({', '.join(finished) or 'none'}), not {', '.join(missing) or 'the rest'}: {how}.",
        "",
    ]


def _owner(figure: Path, results: dict) -> str | None:
    """The group a figure belongs to: the longest group name its file name starts with."""
    names = [g for g in results if g != "attrs" and figure.stem.startswith(g)]
    return max(names, key=len, default=None)


def _summary_head(directory: Path, results: dict, finished: list[str], bundle: bool) -> list[str]:
    """summary.md's first lines: versions, size, ranks, date, completeness and indicators."""
    root = results["attrs"]
    return [
        "# ncf2lammps run summary",
        "",
        f"ncf2lammps {_format(root['ncf2lammps_version'])},"
        f" LAMMPS {_format(root.get('lammps_version', 'unknown'))},"
        f" {_format(root['n_atoms'])} atoms, {_format(root['n_bonds'])} bonds,"
        f" {_format(root.get('mpi_ranks', 'unknown'))} MPI rank(s),"
        f" created {_format(root.get('created', 'unknown'))}; complete: {bool(root['complete'])}.",
        "",
        *_incomplete_lines(directory, results, finished, bundle),
        *_indicator_lines(results),
        *_shear_sense_lines(results),
    ]


def write_report(directory: str | os.PathLike) -> list[Path]:
    """Write figures/*.png and summary.md for the run in ``directory``; returns the files.

    A bundle run by plain ``lmp`` (no results.h5 yet) is first collected into results.h5. The
    folder is checked first (:func:`~ncf2lammps.orchestration.folder.check_run_folder`: a
    one-line RunFolderError if it is not a run folder); a killed run's folder is reported with
    the scenes it finished, and summary.md says that it is incomplete.
    """
    directory = Path(directory)
    folder = check_run_folder(directory, need="report")
    if folder.bundle:
        collect_outputs(directory)
    results = read_results(directory / "results.h5")
    finished = [s for s in SCENES if s in results and results[s]["attrs"].get("complete")]
    (directory / "figures").mkdir(exist_ok=True)
    try:
        written = _trajectories(directory, finished)
        results = read_results(directory / "results.h5")
        for scene in SCENES:
            if scene in results:
                written += SCENES[scene].figures(results, directory)
        lines = _summary_head(directory, results, finished, folder.bundle)
    except (SpecError, ResultsFileError, RunFolderError):
        raise
    except (KeyError, IndexError, TypeError, ValueError) as err:
        # A results file or snapshot that lacks or garbles what the scenes wrote.
        why = " ".join(f"{type(err).__name__}: {err}".split())[:200]
        raise ResultsFileError(
            directory / "results.h5",
            f"or a snapshot beside it does not hold what the report reads ({why}); the run's"
            " files are left as they are",
        ) from None
    for scene, group in results.items():
        if scene == "attrs":
            continue
        lines += [f"## {scene}", "", "| quantity | value |", "|---|---|"]
        lines += [f"| {k} | {_format(v)} |" for k, v in sorted(group["attrs"].items())]
        lines += [""] + [
            f"![{p.stem}](figures/{p.name})" for p in written if _owner(p, results) == scene
        ]
        lines.append("")
    (directory / "summary.md").write_text("\n".join(lines))
    written.append(directory / "summary.md")
    return written
