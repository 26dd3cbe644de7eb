"""``ncf2lammps study``: the same scenes over a grid of numerical knobs; error against run time.

Stages of :func:`study`:

1. the grid: the product of the ``--vary`` value lists (``zip``: their position-wise pairs),
   every point checked as ``build`` checks it before anything runs; the reference is the point
   whose knobs all sit at their conservative end (:data:`KNOBS`: finest, slowest, unscaled);
2. each point runs in ``points/pNN`` like ``ncf2lammps run``; a point whose results are
   complete for the same spec is reused, and one killed while it ran resumes from its
   checkpoint (status ``ok (resumed)``; its wall time counts every segment up to the last
   checkpoint and the resumed part, not the steps lost after that checkpoint); a
   point whose folder holds a finished manufacture of the same model and settings (say, from
   a study run with other compaction settings) keeps it, and each test scene that finished
   with the same table, and runs only the rest; a point whose model and manufacture settings
   equal an earlier point's starts from a copy of that manufactured state and runs only the
   test scenes (wall times still count the scenes reused);
3. the table: each output (:data:`OUTPUTS`), its relative error against the reference, the
   largest error, wall time, steps, whether the tests passed their quasi-static check, the
   Pareto front (no faster point is as accurate) and the fastest quasi-static point within the
   tolerance; where the grid holds seeds (:data:`ENSEMBLE_KNOBS`), settings are compared
   seed by seed instead (:func:`paired_settings`) and the seeds' spread is added:
   ``study.csv``, ``study.md`` and ``study.png``, written last.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import sys
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import product
from pathlib import Path

import numpy as np

from ..analysis.plots import plot_study
from ..analysis.study import pareto_front, relative_errors
from ..engine import EngineError
from ..geometry.size import check_model_size
from ..io.results import ResultsFileError, mark_complete, read_results
from ..io.spectoml import dumps_spec
from ..io.table import write_csv
from ..numerics import prepare
from ..scenes import kinetic_checks, quasi_static
from ..spec import FabricSpec, SpecError
from .build import OutputExistsError, render_decks
from .folder import RunFolderError, abandoned_temporary_folders, temporary_folder
from .report import write_report
from .run import copy_manufactured, run, run_scenes, scenes_to_run

__all__ = [
    "ENSEMBLE_KNOBS",
    "KNOBS",
    "OUTPUTS",
    "StudyPoint",
    "ensemble_spread",
    "paired_settings",
    "parse_vary",
    "study",
    "study_grid",
]

#: Knobs a study may vary, with the end that is the reference: the most conservative numerics,
#: or, for the model options beyond the paper (docs/fidelity.md), the paper's own model; "first"
#: takes the first value listed (a seed, or a constant studied over its physical range).
KNOBS = {
    "discretisation.chain_diameter_um": "min",
    "discretisation.bead_spacing_ratio": "min",
    "numerics.dt_fraction": "min",
    "numerics.mass_scaling": "min",
    "numerics.fibre_stiffness_scaling": "max",
    "numerics.stitch_mass_scaling": "min",
    "manufacture.pretension_strain_rate_per_us": "min",
    "manufacture.damping_time_us": "max",
    "manufacture.relaxation_damping_time_us": "max",
    "manufacture.kinetic_ratio_target": "min",
    "manufacture.stitch_creep_target_per_ms": "min",
    "manufacture.needle_speed_m_s": "min",
    "compaction.inertial_number": "min",
    "compaction.plate_speed_m_s": "min",
    "shear.inertial_number": "min",
    "shear.shear_rate_deg_us": "min",
    "compaction.loading": "first",
    "compaction.max_rate_factor": "min",
    "compaction.kinetic_stress_target": "min",
    "shear.loading": "first",
    "shear.max_rate_factor": "min",
    "shear.kinetic_stress_target": "min",
    "discretisation.chain_internal_fvf": "max",
    "mat.initial_fvf": "max",
    "mat.waviness_amplitude_um": "min",
    "stitch.packing_fraction": "max",
    "contact.bundle_waviness_ratio": "first",
    "manufacture.stitch_tension_N": "first",
    "stitch.E_GPa": "first",
    "stitch.contact_diameter_um": "first",
    "mat.seed": "first",
    "numerics.perturbation_seed": "first",
}

#: The knobs whose points form an ensemble: points equal in every other knob are one model drawn
#: with different random beds (``mat.seed``) or run as replicas of one trajectory
#: (``numerics.perturbation_seed``); study.md reports their mean and spread.
ENSEMBLE_KNOBS = ("mat.seed", "numerics.perturbation_seed")

#: Outputs compared across points: (scene, results.h5 attribute, label).
OUTPUTS = (
    ("manufacture", "stitch_tension_N", "stitch tension (N)"),
    ("manufacture", "thickness_mm", "thickness after manufacture (mm)"),
    ("compaction", "thickness_at_1kPa_mm", "t at 1 kPa (mm)"),
    ("compaction", "thickness_at_18kPa_mm", "t at 18 kPa (mm)"),
    ("compaction", "stiffening_exponent", "b of Vf = a P^b, 1-18 kPa"),
    ("shear", "force_at_45deg_N_per_m", "F_N at 45 deg (N/m)"),
)

#: Scene settings a test scene's point may differ in and still reuse a manufactured state.
TEST_TABLES = ("compaction", "shear")


def parse_vary(text: str) -> tuple[str, list]:
    """``"table.field=v1,v2"`` -> (knob, values); values parsed as TOML scalars."""
    knob, sep, values = text.partition("=")
    knob = knob.strip()
    if not sep or knob not in KNOBS:
        raise SpecError(
            "--vary", text, f"must be KNOB=V1,V2,... with KNOB one of {', '.join(KNOBS)}"
        )
    items = [v.strip() for v in values.split(",")] if values.strip() else []
    if "" in items:
        raise SpecError("--vary", text, "has an empty value between commas: give KNOB=V1,V2,...")
    try:
        parsed = [_knob_value(item) for item in items]
    except tomllib.TOMLDecodeError:
        raise SpecError(
            "--vary", text, "values must be numbers or words (a choice) separated by commas"
        ) from None
    if not parsed:
        raise SpecError("--vary", text, "needs at least one value")
    return knob, parsed


def _knob_value(text: str):
    """One value of ``--vary``: a TOML scalar, or a bare word (a choice, e.g. ``adaptive``)."""
    if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_-]*", text) and text not in (
        "true",
        "false",
        "inf",
        "nan",
    ):
        return text
    return tomllib.loads(f"v = {text}")["v"]


@dataclass(frozen=True)
class StudyPoint:
    """One grid point: its label (``pNN``), knob values and validated spec."""

    label: str
    knobs: dict
    spec: FabricSpec


def study_grid(
    spec: FabricSpec, vary: Sequence[tuple[str, list]], zipped: bool = False
) -> tuple[list[StudyPoint], int]:
    """The grid's points and the index of the reference point. Every point is checked as
    ``build`` checks it (its model, time step and decks: :class:`SpecError` naming the field)
    before anything runs."""
    names = [knob for knob, _ in vary]
    if len(set(names)) != len(names):
        raise SpecError("--vary", names, "each knob at most once")
    lists = [values for _, values in vary]
    if zipped and len({len(v) for v in lists}) > 1:
        raise SpecError("--zip", [len(v) for v in lists], "every --vary needs as many values")
    combos = list(zip(*lists, strict=True)) if zipped else list(product(*lists))
    points = []
    for index, combo in enumerate(combos):
        tables: dict[str, dict] = {}
        for knob, value in zip(names, combo, strict=True):
            table, field_name = knob.split(".")
            tables.setdefault(table, {})[field_name] = value
        point_spec = spec.replace(**tables) if tables else spec
        check_model_size(point_spec)
        render_decks(prepare(point_spec))
        points.append(StudyPoint(f"p{index:02d}", dict(zip(names, combo, strict=True)), point_spec))
    conservative = [_reference_value(KNOBS[knob], values) for knob, values in vary]
    reference = [i for i, c in enumerate(combos) if list(c) == conservative]
    if not reference:
        raise SpecError(
            "--zip", conservative, "no point has every knob at its conservative end (the reference)"
        )
    return points, reference[0]


def _reference_value(end: str, values: list):
    """The reference value of a knob's list: its smallest, largest or first value."""
    given = [v for v in values if v is not None]
    return given[0] if end == "first" else (min if end == "min" else max)(given)


def _settings(rows: list[dict], knobs: Sequence[str]) -> tuple[list, list, dict[tuple, list]]:
    """(the knobs other than :data:`ENSEMBLE_KNOBS`, the ensemble knobs, the finished rows
    grouped by their values of the other knobs)."""
    others = [k for k in knobs if k not in ENSEMBLE_KNOBS]
    seed_knobs = [k for k in knobs if k in ENSEMBLE_KNOBS]
    groups: dict[tuple, list[dict]] = {}
    for row in rows:
        if row["status"].startswith("ok"):
            groups.setdefault(tuple(row[k] for k in others), []).append(row)
    return others, seed_knobs, groups


def ensemble_spread(rows: list[dict], knobs: Sequence[str], outputs) -> list[dict]:
    """Mean and spread over :data:`ENSEMBLE_KNOBS` of every group of finished points equal in
    all other knobs: one dict per group with 2 or more seeds, holding ``knobs`` (the other
    knobs' values), ``seeds`` (each member's seed, a tuple where both ensemble knobs vary),
    and per output attribute ``(mean, sample std, min, max)``."""
    others, seed_knobs, groups = _settings(rows, knobs)
    spreads = []
    for key, members in groups.items():
        if len(members) < 2:
            continue
        stats = {}
        for attr, _ in outputs:
            values = np.array([m.get(attr, np.nan) for m in members], dtype=float)
            stats[attr] = (values.mean(), values.std(ddof=1), values.min(), values.max())
        seeds = [
            m[seed_knobs[0]] if len(seed_knobs) == 1 else tuple(m[k] for k in seed_knobs)
            for m in members
        ]
        spreads.append({"knobs": dict(zip(others, key, strict=True)), "seeds": seeds, **stats})
    return spreads


def paired_settings(rows: list[dict], knobs: Sequence[str], outputs, reference: int) -> list[dict]:
    """Every setting of the knobs other than :data:`ENSEMBLE_KNOBS` compared with the
    reference point's setting seed by seed, over the seeds both finished: one dict per other
    setting with ``knobs`` (its values), ``seeds``, ``errors`` (per seed, the largest
    ``|x - x_ref| / |x_ref|`` over the outputs against the reference setting's point of that
    seed), ``wall_s`` and ``reference_wall_s`` (means over those seeds, s) and ``quasi_static``
    (every paired point of the setting passed its check). Settings sharing no seed with the
    reference setting are left out."""
    others, seed_knobs, groups = _settings(rows, knobs)
    by_setting = {
        setting: {tuple(row[k] for k in seed_knobs): row for row in members}
        for setting, members in groups.items()
    }
    reference_setting = tuple(rows[reference][k] for k in others)
    base = by_setting.get(reference_setting, {})
    attrs = [attr for attr, _ in outputs]
    compared = []
    for setting, members in by_setting.items():
        seeds = [seed for seed in members if seed in base]
        if setting == reference_setting or not seeds:
            continue
        errors = []
        for seed in seeds:
            values = [[row.get(a, np.nan) for a in attrs] for row in (base[seed], members[seed])]
            errors.append(float(np.max(relative_errors(values, 0)[1])))
        compared.append(
            {
                "knobs": dict(zip(others, setting, strict=True)),
                "seeds": [seed[0] if len(seed) == 1 else seed for seed in seeds],
                "errors": errors,
                "wall_s": float(np.mean([members[s]["wall_s"] for s in seeds])),
                "reference_wall_s": float(np.mean([base[s]["wall_s"] for s in seeds])),
                "quasi_static": all(members[s]["quasi_static"] for s in seeds),
            }
        )
    return compared


def _split_tables(spec_toml: str) -> tuple[dict, dict]:
    """A spec's TOML text as (everything the manufactured state depends on, test tables).

    Parsed as TOML, not validated: a stored spec may fail a rule added since.
    """
    data = tomllib.loads(spec_toml)
    return data, {table: data.pop(table, None) for table in TEST_TABLES}


def _manufacture_key(spec: FabricSpec) -> str:
    return json.dumps(_split_tables(dumps_spec(spec))[0], sort_keys=True)


def _stored_run(directory: Path) -> tuple[str | None, set[str], bool] | None:
    """A folder's stored run: (its spec TOML, its finished scenes, whether the run is
    complete); None without a readable results.h5 (a point killed while writing it runs
    again)."""
    path = directory / "results.h5"
    if not path.is_file():
        return None
    try:
        content = read_results(path)
    except ResultsFileError:
        return None
    stored = content["attrs"].get("spec_toml")
    if isinstance(stored, bytes):
        stored = stored.decode()
    finished = {k for k, v in content.items() if k != "attrs" and v["attrs"].get("complete")}
    return stored, finished, bool(content["attrs"].get("complete"))


def _is_complete(directory: Path, spec: FabricSpec, scenes: Sequence[str]) -> bool:
    """Whether ``directory`` is a finished run of ``spec`` holding every one of ``scenes``."""
    stored = _stored_run(directory)
    if stored is None:
        return False
    spec_toml, finished, complete = stored
    return complete and spec_toml == dumps_spec(spec) and set(scenes) <= finished


def _reusable_scenes(directory: Path, spec: FabricSpec, scenes: Sequence[str]) -> set[str]:
    """Scenes of ``scenes`` finished in ``directory`` whose result ``spec`` would not change.

    Empty unless the folder's manufacture (or, without stitch, its model) is ``spec``'s: then
    the manufacture is reusable, and each test scene that finished with the same table too
    (compaction and shear each start from the manufactured state, not from one another).
    """
    stored = _stored_run(directory)
    if stored is None:
        return set()
    spec_toml, finished, _ = stored
    try:
        old, old_tests = _split_tables(spec_toml)
    except (TypeError, tomllib.TOMLDecodeError):
        return set()
    new, new_tests = _split_tables(dumps_spec(spec))
    if old != new:
        return set()
    if "manufacture" in scenes and "manufacture" not in finished:
        return set()
    same = {"manufacture"} | {t for t in TEST_TABLES if old_tests[t] == new_tests[t]}
    return set(scenes) & finished & same


def _is_killed_run(directory: Path, spec: FabricSpec) -> bool:
    """Whether ``directory`` holds a run of ``spec`` that stopped before it was complete."""
    stored = _stored_run(directory)
    return stored is not None and not stored[2] and stored[0] == dumps_spec(spec)


def _killed_partial(directory: Path, spec: FabricSpec) -> Path | None:
    """The newest temporary folder of ``directory`` left by a killed study while running
    ``spec``; the other temporary folders of killed studies are removed."""
    found = None
    for path in abandoned_temporary_folders(directory):
        if found is None and _is_killed_run(path, spec):
            found = path
        else:
            shutil.rmtree(path, ignore_errors=True)
    return found


def _run_from_manufactured(
    point: StudyPoint,
    source: Path,
    directory: Path,
    scenes: Sequence[str],
    ranks: int = 1,
    keep: Sequence[str] = ("manufacture",),
) -> bool:
    """Copy ``source`` (manufactured) to ``directory`` and run the ``scenes`` not in ``keep``
    there, on ``ranks`` MPI ranks (``directory`` may be ``source``: replaced when done).

    A temporary folder that a killed study left while running this point is taken up instead
    of the copy: each scene to run resumes from its own checkpoint there, if it wrote one (the
    copy drops the source's checkpoints of those scenes). Returns whether it was.
    """
    partial = temporary_folder(directory)
    shutil.rmtree(partial, ignore_errors=True)
    todo = [s for s in scenes if s not in keep]
    killed = _killed_partial(directory, point.spec)
    if killed is not None:
        killed.rename(partial)
    try:
        if killed is None:  # never a moment with the source's checkpoints of the scenes to run
            copy_manufactured(point.spec, source, partial, todo)
        results = run_scenes(point.spec, partial, todo, ranks=ranks, resume=killed is not None)
        mark_complete(results)
        shutil.rmtree(directory, ignore_errors=True)
        partial.rename(directory)
    except BaseException:
        shutil.rmtree(partial, ignore_errors=True)
        raise
    write_report(directory)  # a run folder by now: report refuses temporary build folders
    return killed is not None


def _point_row(directory: Path, scenes: Sequence[str]) -> dict:
    """Outputs, wall time, steps, the largest kinetic ratio, the largest kinetic error of the
    tests' quasi-static checks (``max_kinetic_error``) and whether all pass (``quasi_static``)
    of a finished point."""
    results = read_results(directory / "results.h5")
    row: dict = {}
    for scene, attr, _ in OUTPUTS:
        if scene in scenes:
            row[attr] = float(results[scene]["attrs"].get(attr, np.nan))
    groups = [results[s]["attrs"] for s in scenes]
    row["wall_s"] = float(sum(g["wall_s"] for g in groups))
    row["steps"] = int(sum(g["steps"] for g in groups))
    ratios = [g.get("max_kinetic_ratio", g.get("kinetic_ratio", np.nan)) for g in groups]
    row["max_kinetic_ratio"] = float(np.nanmax(ratios))
    checked = [value for g in groups for value, _ in kinetic_checks(g)]
    row["max_kinetic_error"] = float(np.nanmax(checked)) if np.any(np.isfinite(checked)) else np.nan
    row["quasi_static"] = all(quasi_static(g) for g in groups)
    return row


def study(
    spec: FabricSpec,
    directory: str | os.PathLike,
    vary: Sequence[tuple[str, list]],
    scenes: Sequence[str] | None = None,
    zipped: bool = False,
    tolerance: float = 0.03,
    ranks: int = 1,
) -> list[Path]:
    """Run the grid (see the module docstring) on ``ranks`` MPI ranks; returns the files
    written."""
    points, reference = study_grid(spec, vary, zipped)
    wanted = scenes_to_run(spec, scenes)
    directory = Path(directory)
    if directory.exists() and any(directory.iterdir()) and not (directory / "points").is_dir():
        raise OutputExistsError(f"{directory}: exists and is not a study folder")
    try:
        (directory / "points").mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise RunFolderError(
            directory, f"cannot be made ({err.strerror}): choose another -o"
        ) from None
    manufactured: dict[str, Path] = {}
    rows = []
    for number, point in enumerate(points, start=1):
        folder = directory / "points" / point.label
        knobs = ", ".join(f"{k}={v}" for k, v in point.knobs.items())
        print(f"study {point.label} ({number}/{len(points)}): {knobs}", file=sys.stderr)
        status = "ok"
        try:
            if _is_complete(folder, point.spec, wanted):
                status = "ok (reused)"
            elif _is_killed_run(folder, point.spec):
                run(point.spec, folder, wanted, ranks=ranks, resume=True)
                status = "ok (resumed)"
            elif keep := _reusable_scenes(folder, point.spec, wanted):
                resumed = _run_from_manufactured(point, folder, folder, wanted, ranks, sorted(keep))
                reused = ", ".join(s for s in wanted if s in keep)
                status = f"ok (reused {reused}{', resumed' if resumed else ''})"
            elif (key := _manufacture_key(point.spec)) in manufactured and "manufacture" in wanted:
                if _run_from_manufactured(point, manufactured[key], folder, wanted, ranks):
                    status = "ok (resumed)"
            else:
                run(point.spec, folder, wanted, force=True, ranks=ranks)
            row = _point_row(folder, wanted)
            if "manufacture" in wanted:
                manufactured.setdefault(_manufacture_key(point.spec), folder)
        except EngineError as err:
            status = f"failed: {str(err).splitlines()[0]}"
            row = {}
        rows.append({"point": point.label, **point.knobs, "status": status, **row})
    return _write_tables(directory, spec, points, reference, rows, wanted, tolerance)


@dataclass(frozen=True)
class _Table:
    """The study's numbers: outputs (attr, label), values and their relative errors (P, O), the
    largest error, wall time and Pareto membership (P,), and the CSV columns."""

    outputs: list[tuple[str, str]]
    knobs: list[str]
    values: np.ndarray
    errors: np.ndarray
    worst: np.ndarray
    wall: np.ndarray
    front: np.ndarray
    columns: dict[str, list]


def _table(points, reference: int, rows: list[dict], scenes) -> _Table:
    """Errors against the reference point, the largest per point and the Pareto front."""
    outputs = [(attr, label) for scene, attr, label in OUTPUTS if scene in scenes]
    values = np.array([[row.get(attr, np.nan) for attr, _ in outputs] for row in rows])
    errors = relative_errors(values, reference)
    largest = np.max(np.where(np.isnan(errors), -np.inf, errors), axis=1, initial=-np.inf)
    worst = np.where(np.isneginf(largest), np.nan, largest)
    worst[np.any(np.isnan(values), axis=1)] = np.nan
    wall = np.array([row.get("wall_s", np.nan) for row in rows])
    front = pareto_front(wall, worst)
    knobs = list(points[0].knobs)
    columns: dict[str, list] = {"point": [r["point"] for r in rows]}
    columns.update({k: [r[k] for r in rows] for k in knobs})
    columns["status"] = [r["status"] for r in rows]
    for j, (attr, _) in enumerate(outputs):
        columns[attr] = list(values[:, j])
        columns[f"error_{attr}"] = list(errors[:, j])
    columns["max_error"] = list(worst)
    columns["wall_s"] = list(wall)
    columns["steps"] = [r.get("steps", 0) for r in rows]
    columns["max_kinetic_ratio"] = [r.get("max_kinetic_ratio", np.nan) for r in rows]
    columns["max_kinetic_error"] = [r.get("max_kinetic_error", np.nan) for r in rows]
    columns["quasi_static"] = [r.get("quasi_static", False) for r in rows]
    columns["pareto"] = [bool(f) for f in front]
    columns["reference"] = [i == reference for i in range(len(rows))]
    return _Table(outputs, knobs, values, errors, worst, wall, front, columns)


def _markdown(spec, table: _Table, rows, reference: int, scenes, tolerance: float) -> str:
    """study.md: the table of every point and the fastest point within the tolerance."""
    knobs, outputs, values, errors = table.knobs, table.outputs, table.values, table.errors
    worst, wall = table.worst, table.wall
    lines = [
        f"# Study: {spec.name}",
        "",
        f"Scenes: {', '.join(scenes)}. Knobs: {', '.join(knobs)}. Reference (every knob at its"
        f" conservative end): {rows[reference]['point']}. Error = |x - x_ref| / |x_ref|;"
        f" tolerance {tolerance:.0%}. Wall time sums the scenes of each point (a reused"
        " manufacture counts its own wall time).",
        "",
        "| point | "
        + " | ".join(knobs)
        + " | "
        + " | ".join(label for _, label in outputs)
        + " | max error | wall (s) | steps | max KE ratio | max kinetic error | quasi-static"
        " | Pareto |",
        "|" + "---|" * (len(knobs) + len(outputs) + 8),
    ]
    for i, row in enumerate(rows):
        cells = [row["point"] + (" (ref)" if i == reference else "")]
        cells += [f"{row[k]}" for k in knobs]
        if row["status"].startswith("failed"):
            cells += [row["status"]] + [""] * (len(outputs) + 6)
        else:
            cells += [f"{values[i, j]:.5g} ({errors[i, j]:.2%})" for j in range(len(outputs))]
            cells += [
                f"{worst[i]:.2%}",
                f"{wall[i]:.0f}",
                f"{row['steps']}",
                f"{row['max_kinetic_ratio']:.2g}",
                f"{row.get('max_kinetic_error', np.nan):.2g}",
                "yes" if row["quasi_static"] else "**no**",
                "yes" if table.front[i] else "",
            ]
        lines.append("| " + " | ".join(cells) + " |")
    if not set(ENSEMBLE_KNOBS) & set(knobs):
        lines += ["", *_fastest_lines(table, rows, reference, tolerance)]
    else:
        lines += ["", *_paired_lines(rows, knobs, outputs, reference, tolerance)]
        lines += ["", *_ensemble_lines(rows, knobs, outputs)]
    return "\n".join([*lines, "", "![error against wall time](study.png)", ""])


def _fastest_lines(table: _Table, rows, reference: int, tolerance: float) -> list[str]:
    """The fastest point within the tolerance on every output among those whose tests passed
    their quasi-static check (an output can agree by chance along a path that was not
    quasi-static), and any faster point that agrees but failed the check."""
    wall, knobs = table.wall, table.knobs
    agree = table.worst <= tolerance
    quasi_static = np.array(table.columns["quasi_static"], dtype=bool)
    lines = []
    if np.any(within := agree & quasi_static):
        best = int(np.flatnonzero(within)[np.argmin(wall[within])])
        lines.append(
            f"Fastest point within {tolerance:.0%} on every output and quasi-static (every test's"
            f" kinetic error within its limit): **{rows[best]['point']}**"
            f" ({_setting_label({k: rows[best][k] for k in knobs})}), {wall[best]:.0f} s ="
            f" 1/{wall[reference] / wall[best]:.3g} of the reference's {wall[reference]:.0f} s."
        )
        faster = agree & ~quasi_static & (wall < wall[best])
    else:
        lines.append(
            f"No quasi-static point is within {tolerance:.0%} of the reference on every output."
        )
        faster = agree & ~quasi_static
    for i in np.flatnonzero(faster):
        lines += [
            "",
            f"{rows[i]['point']} is within {tolerance:.0%} in {wall[i]:.0f} s but failed its"
            f" quasi-static check (max kinetic error {rows[i]['max_kinetic_error']:.2g}):"
            " not counted.",
        ]
    return lines


def _paired_lines(rows, knobs, outputs, reference: int, tolerance: float) -> list[str]:
    """study.md's comparison of settings where the grid holds seeds: each setting against the
    reference setting replica by replica (:func:`paired_settings`), and the fastest setting
    within the tolerance on every output of every paired seed whose tests were all
    quasi-static; a grid of seeds alone compares nothing."""
    if all(k in ENSEMBLE_KNOBS for k in knobs):
        return [
            "Every point is one setting with another seed: their differences from the reference"
            " are the ensemble's scatter (below), not an error, so no fastest point is named."
        ]
    settings = paired_settings(rows, knobs, outputs, reference)
    lines = [
        "## Settings paired by seed",
        "",
        "Each setting against the reference setting's point of the same seed (the errors of"
        " the table above also hold the scatter between seeds); wall times are means over the"
        " paired seeds.",
        "",
        "| setting | paired seeds | largest error per seed | mean wall (s) | reference's mean"
        " wall (s) | quasi-static |",
        "|---|---|---|---|---|---|",
    ]
    for s in settings:
        lines.append(
            f"| {_setting_label(s['knobs'])} | {', '.join(str(x) for x in s['seeds'])} |"
            f" {', '.join(f'{e:.2%}' for e in s['errors'])} | {s['wall_s']:.0f} |"
            f" {s['reference_wall_s']:.0f} | {'yes' if s['quasi_static'] else '**no**'} |"
        )
    within = [s for s in settings if s["quasi_static"] and max(s["errors"]) <= tolerance]
    lines.append("")
    if not within:
        lines.append(
            f"No quasi-static setting is within {tolerance:.0%} of the reference setting on every"
            " output of every paired seed."
        )
        return lines
    best = min(within, key=lambda s: s["wall_s"] / s["reference_wall_s"])
    lines.append(
        f"Fastest setting within {tolerance:.0%} on every output of every paired seed and"
        f" quasi-static: **{_setting_label(best['knobs'])}** ({len(best['seeds'])} seeds),"
        f" {best['wall_s']:.0f} s = 1/{best['reference_wall_s'] / best['wall_s']:.3g} of the"
        f" reference setting's {best['reference_wall_s']:.0f} s over the same seeds."
    )
    return lines


def _setting_label(setting: dict) -> str:
    """``knob=value`` pairs of a setting, comma-separated."""
    return ", ".join(f"{k}={v}" for k, v in setting.items())


def _ensemble_lines(rows, knobs, outputs) -> list[str]:
    """study.md's seed-spread table: mean, sample standard deviation (also as a fraction of the
    mean) and range of every output over the seeds of each group."""
    lines = [
        "## Spread over seeds",
        "",
        f"Points equal in every knob but {' and '.join(f'`{k}`' for k in ENSEMBLE_KNOBS if k in knobs)}:"
        " mean +- sample standard deviation (relative), [min, max].",
        "",
    ]
    for group in ensemble_spread(rows, knobs, outputs):
        named = _setting_label(group["knobs"]) or "all points"
        lines += [f"{named}; seeds {', '.join(str(s) for s in group['seeds'])}:", ""]
        lines += ["| output | mean | std | std / mean | min | max |", "|---|---|---|---|---|---|"]
        for attr, label in outputs:
            mean, std, low, high = group[attr]
            lines.append(
                f"| {label} | {mean:.5g} | {std:.3g} | {std / abs(mean):.1%} | {low:.5g} |"
                f" {high:.5g} |"
            )
        lines.append("")
    return lines


def _write_tables(directory, spec, points, reference, rows, scenes, tolerance) -> list[Path]:
    """study.csv, study.md and study.png from the rows of every point."""
    table = _table(points, reference, rows, scenes)
    write_csv(directory / "study.csv.tmp", table.columns)
    (directory / "study.csv.tmp").replace(directory / "study.csv")
    fig = plot_study(
        table.wall, table.worst, table.front, table.columns["point"], tolerance, reference
    )
    fig.savefig(directory / "study.png", dpi=120)
    (directory / "study.md").write_text(_markdown(spec, table, rows, reference, scenes, tolerance))
    return [directory / "study.csv", directory / "study.md", directory / "study.png"]
