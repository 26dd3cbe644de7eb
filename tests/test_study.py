"""``study``: a grid of knobs, errors against the reference, the Pareto front."""

from __future__ import annotations

import csv
import shutil
import subprocess
import sys

import numpy as np
import pytest
from conftest import kill_after_checkpoint, tiny_spec

from ncf2lammps import copy_manufactured, load_spec, run_scenes
from ncf2lammps.analysis.study import pareto_front, relative_errors
from ncf2lammps.io.results import read_results, write_root, write_scene
from ncf2lammps.io.spectoml import dumps_spec, write_spec
from ncf2lammps.orchestration.build import OutputExistsError
from ncf2lammps.orchestration.folder import RunFolderError
from ncf2lammps.orchestration.run import scenes_to_run
from ncf2lammps.orchestration.study import (
    KNOBS,
    _write_tables,
    ensemble_spread,
    paired_settings,
    study,
    study_grid,
)
from ncf2lammps.spec import SpecError


def test_pareto_front_keeps_points_no_faster_point_beats():
    wall = np.array([10.0, 20.0, 5.0, 40.0, 30.0, 8.0])
    error = np.array([0.05, 0.01, 0.20, 0.0, 0.02, np.nan])
    # 5 s (0.20) is fastest; 10 s (0.05) better; 20 s (0.01) better; 30 s (0.02) is not;
    # 40 s (0.0) better; a failed point (NaN) never is.
    assert pareto_front(wall, error).tolist() == [True, True, True, True, False, False]


def test_relative_errors_against_the_reference_row():
    values = np.array([[1.0, 10.0], [1.1, 9.0], [np.nan, 10.0]])
    errors = relative_errors(values, 0)
    np.testing.assert_allclose(errors[:2], [[0.0, 0.0], [0.1, 0.1]], rtol=1e-12)
    assert np.isnan(errors[2, 0]) and errors[2, 1] == 0.0


def test_grid_reference_is_every_knob_at_its_conservative_end():
    spec = tiny_spec()
    vary = [
        ("shear.inertial_number", [0.1, 0.025, 0.05]),
        ("numerics.fibre_stiffness_scaling", [0.04, 1.0]),
    ]
    points, reference = study_grid(spec, vary)
    assert len(points) == 6
    assert points[reference].knobs == {
        "shear.inertial_number": 0.025,
        "numerics.fibre_stiffness_scaling": 1.0,
    }
    assert points[reference].spec.shear.inertial_number == 0.025


def test_every_knob_is_a_spec_field_a_grid_can_set():
    spec = tiny_spec()
    for knob in KNOBS:
        table, field_name = knob.split(".")
        value = getattr(getattr(spec, table), field_name)
        if value is None or isinstance(value, str):
            continue  # optional fields and choices: their values are the spec's own checks
        points, _ = study_grid(spec, [(knob, [value])])
        assert getattr(getattr(points[0].spec, table), field_name) == value, knob


@pytest.mark.parametrize(
    ("knob", "values"),
    [
        ("manufacture.stitch_tension_N", [0.1, 0.05, 0.2]),
        ("stitch.E_GPa", [12.0, 4.3, 1.0]),
        ("stitch.contact_diameter_um", [83.0, 42.0, 21.0]),
    ],
)
def test_a_constant_studied_over_its_range_refers_to_its_first_value(knob, values):
    """A physical constant (no conservative end): the reference is the first value listed, and
    each point's spec carries its own value."""
    points, reference = study_grid(tiny_spec(), [(knob, values)])
    assert points[reference].knobs == {knob: values[0]}
    table, field = knob.split(".")
    assert [getattr(getattr(p.spec, table), field) for p in points] == values


@pytest.mark.filterwarnings("error")
def test_a_study_whose_points_all_failed_writes_its_tables_without_warnings(tmp_path):
    spec = tiny_spec()
    points, reference = study_grid(spec, [("mat.seed", [1, 2])])
    rows = [{"point": p.label, **p.knobs, "status": "failed: push-off check"} for p in points]
    for path in _write_tables(tmp_path, spec, points, reference, rows, ["manufacture"], 0.03):
        assert path.stat().st_size > 0
    assert "failed: push-off check" in (tmp_path / "study.md").read_text()


def test_the_fastest_point_named_is_within_tolerance_and_quasi_static(tmp_path):
    """Of three points (reference, a fast one that agrees within 3 % but whose test failed its
    kinetic stress check, a slower one that agrees and passed), study.md names the slower one
    as the fastest and says why the faster one is not counted."""
    spec = tiny_spec()
    points, reference = study_grid(spec, [("compaction.inertial_number", [0.025, 0.2, 0.05])])
    rows = [
        {"point": p.label, **p.knobs, "status": "ok", "steps": 1, "max_kinetic_ratio": 0.0}
        for p in points
    ]
    for row, t, wall, stress in zip(
        rows, (0.60, 0.601, 0.602), (400.0, 100.0, 200.0), (0.001, 0.05, 0.008), strict=True
    ):
        outputs = {"thickness_at_1kPa_mm": t, "thickness_at_18kPa_mm": t - 0.1}
        row.update(outputs, stiffening_exponent=0.05, wall_s=wall)
        row.update(max_kinetic_error=stress, quasi_static=stress <= 0.01)
    _write_tables(tmp_path, spec, points, reference, rows, ["compaction"], 0.03)
    text = (tmp_path / "study.md").read_text()
    fastest = next(line for line in text.splitlines() if line.startswith("Fastest point"))
    assert "**p02**" in fastest and "1/2 of the reference" in fastest
    assert "p01 is within 3% in 100 s but failed its quasi-static check" in text
    quasi = [r["quasi_static"] for r in csv.DictReader(open(tmp_path / "study.csv"))]
    assert quasi == ["True", "False", "True"]


@pytest.mark.parametrize("seed_knob", ["mat.seed", "numerics.perturbation_seed"])
def test_seed_points_form_an_ensemble_with_mean_and_sample_spread(seed_knob):
    """Points equal but for a seed (a random bed's, or a replica's perturbation): mean, sample
    std (ddof 1), min and max per output; the reference of a seed list is its first seed;
    failed points are left out."""
    points, reference = study_grid(
        tiny_spec(), [(seed_knob, [3, 1, 2]), ("compaction.inertial_number", [0.05, 0.1])]
    )
    assert points[reference].knobs == {seed_knob: 3, "compaction.inertial_number": 0.05}
    rows = [
        {"point": p.label, **p.knobs, "status": "ok", "t": float(i)} for i, p in enumerate(points)
    ]
    rows[-1]["status"] = "failed: x"
    spreads = ensemble_spread(rows, [seed_knob, "compaction.inertial_number"], [("t", "t")])
    by_rate = {g["knobs"]["compaction.inertial_number"]: g for g in spreads}
    values = [r["t"] for r in rows[:-1] if r["compaction.inertial_number"] == 0.05]
    mean, std, low, high = by_rate[0.05]["t"]
    assert (mean, low, high) == (np.mean(values), min(values), max(values))
    assert std == pytest.approx(np.std(values, ddof=1))
    assert len(by_rate[0.1]["seeds"]) == 2


def test_settings_are_compared_seed_by_seed_where_the_grid_holds_seeds(tmp_path):
    """Replicas 1 and 2 differ by 5 % in F_N(45); a rate moves each replica by 2 % (within
    3 %), another by 2 % on replica 1 and 4 % on replica 2 (not within). Compared point by
    point against replica 1's reference, replica 2's points all read > 3 %; paired by seed,
    the 2 % setting is the fastest within 3 %, at the ratio of the mean wall times over the
    paired seeds. A grid of seeds alone names no fastest point."""
    spec = tiny_spec()
    vary = [
        ("numerics.perturbation_seed", [1, 2, 1, 2, 1, 2]),
        ("shear.inertial_number", [0.025, 0.025, 0.05, 0.05, 0.1, 0.1]),
    ]
    points, reference = study_grid(spec, vary, zipped=True)
    force = {(1, 0.025): 50.0, (2, 0.025): 52.5, (1, 0.05): 51.0, (2, 0.05): 53.55}
    force |= {(1, 0.1): 51.0, (2, 0.1): 54.6}
    wall = {0.025: 400.0, 0.05: 200.0, 0.1: 100.0}
    rows = []
    for p in points:
        seed, rate = p.knobs["numerics.perturbation_seed"], p.knobs["shear.inertial_number"]
        rows.append(
            {"point": p.label, **p.knobs, "status": "ok", "steps": 1, "max_kinetic_ratio": 0.0}
            | {"force_at_45deg_N_per_m": force[seed, rate], "wall_s": wall[rate] + seed}
            | {"max_kinetic_error": 0.001, "quasi_static": True}
        )
    outputs = [("force_at_45deg_N_per_m", "F_N")]
    settings = paired_settings(rows, list(points[0].knobs), outputs, reference)
    by_rate = {s["knobs"]["shear.inertial_number"]: s for s in settings}
    assert set(by_rate) == {0.05, 0.1} and by_rate[0.05]["seeds"] == [1, 2]
    np.testing.assert_allclose(by_rate[0.05]["errors"], [0.02, 0.02], rtol=1e-12)
    np.testing.assert_allclose(by_rate[0.1]["errors"], [0.02, 0.04], rtol=1e-12)
    assert (by_rate[0.05]["wall_s"], by_rate[0.05]["reference_wall_s"]) == (201.5, 401.5)

    _write_tables(tmp_path, spec, points, reference, rows, ["shear"], 0.03)
    text = (tmp_path / "study.md").read_text()
    assert "Fastest point" not in text
    fastest = next(line for line in text.splitlines() if line.startswith("Fastest setting"))
    assert "**shear.inertial_number=0.05** (2 seeds)" in fastest and "1/1.99 of" in fastest

    points, reference = study_grid(spec, [("numerics.perturbation_seed", [1, 2])])
    _write_tables(tmp_path, spec, points, reference, rows[:2], ["shear"], 0.03)
    text = (tmp_path / "study.md").read_text()
    assert "no fastest point is named" in text and "Fastest" not in text


def test_a_copied_manufactured_folder_carries_the_new_spec_and_not_the_scenes_checkpoints(
    tmp_path,
):
    """copy_manufactured: the copy's spec.resolved.toml and results.h5 root hold the spec it will
    run (its summary describes what runs there), the source's checkpoints and results of the
    scenes to run are left behind (a killed copy then resumes them instead of taking the
    source's as its own), the others are copied."""
    old, new = tiny_spec(), tiny_spec().replace(compaction={"inertial_number": 0.0125})
    source = tmp_path / "source"
    source.mkdir()
    write_spec(source / "spec.resolved.toml", old)
    write_root(source / "results.h5", {"spec_toml": dumps_spec(old)})
    write_scene(source / "results.h5", "manufacture", {"steps": 10})
    write_scene(source / "results.h5", "compaction", {"steps": 20})
    write_scene(source / "results.h5", "shear", {"steps": 30})
    for name in ("compaction.checkpoint.json", "compaction.checkpoint.20.restart"):
        (source / name).write_text("")
    (source / "manufacture.checkpoint.json").write_text("")
    copy_manufactured(new, source, tmp_path / "copy", ["compaction"])
    copied = sorted(p.name for p in (tmp_path / "copy").iterdir())
    assert copied == ["manufacture.checkpoint.json", "results.h5", "spec.resolved.toml"]
    assert load_spec(tmp_path / "copy" / "spec.resolved.toml") == new
    results = read_results(tmp_path / "copy" / "results.h5")
    assert results["attrs"]["spec_toml"] == dumps_spec(new) != dumps_spec(old)
    assert results["manufacture"]["attrs"]["steps"] == 10
    assert "compaction" not in results and results["shear"]["attrs"]["steps"] == 30


def test_copy_and_run_scenes_refuse_what_they_cannot_use(tmp_path):
    """copy_manufactured needs a run folder with a finished manufacture and a new target;
    run_scenes a list of the spec's scenes and a built folder: each a one-line error."""
    spec = tiny_spec()
    stranger = tmp_path / "stranger"
    stranger.mkdir()
    (stranger / "notes.txt").write_text("not a run")
    with pytest.raises(RunFolderError, match="not a run folder"):
        copy_manufactured(spec, stranger, tmp_path / "copy", ["shear"])
    unmanufactured = tmp_path / "unmanufactured"
    unmanufactured.mkdir()
    write_root(unmanufactured / "results.h5", {"spec_toml": dumps_spec(spec)})
    with pytest.raises(RunFolderError, match="no finished manufacture"):
        copy_manufactured(spec, unmanufactured, tmp_path / "copy", ["shear"])
    write_scene(unmanufactured / "results.h5", "manufacture", {"steps": 10})
    with pytest.raises(OutputExistsError, match="choose a new folder"):
        copy_manufactured(spec, unmanufactured, stranger, ["shear"])
    assert not (tmp_path / "copy").exists()
    plain = tiny_spec(stitch=None, cell={"length_mm": 2.0, "width_mm": 2.0})  # no stitch:
    # the built folder is the starting state
    (tmp_path / "built").mkdir()
    (tmp_path / "built" / "model.data").write_text("")
    copy_manufactured(plain, tmp_path / "built", tmp_path / "plain-copy", ["compaction"])
    assert load_spec(tmp_path / "plain-copy" / "spec.resolved.toml") == plain
    for scenes in ("shear", ["no-such-scene"]):
        with pytest.raises(SpecError, match="--scene"):
            run_scenes(spec, stranger, scenes)
    with pytest.raises(SpecError, match="--scene"):
        scenes_to_run(spec, [])  # `run` of no scene would write a complete, empty run
    with pytest.raises(RunFolderError, match=r"no model\.data"):
        run_scenes(spec, stranger, ["shear"])


def test_bad_knob_or_value_is_one_line_exit_2(tmp_path):
    spec_file = tmp_path / "spec.toml"
    write_spec(spec_file, tiny_spec())
    for vary, field in (
        ("numerics.warp=1,2", "--vary"),
        ("numerics.dt_fraction=0.5,7", "numerics.dt_fraction"),
    ):
        out = subprocess.run(
            [
                sys.executable,
                "-m",
                "ncf2lammps.cli",
                "study",
                str(spec_file),
                "-o",
                str(tmp_path / "s"),
                "--vary",
                vary,
            ],
            capture_output=True,
            text=True,
        )
        assert out.returncode == 2, out.stderr
        assert len(out.stderr.strip().splitlines()) == 1 and field in out.stderr
        assert "Traceback" not in out.stderr
    assert not (tmp_path / "s").exists()


@pytest.fixture(scope="module")
def compaction_study(tmp_path_factory):
    """A two-point study of the compaction rate on the tiny cell. The plates stop at Vf 0.35,
    past 18 kPa (the tiny cell passes it near Vf 0.29): both reported thicknesses are on the
    curve, and the test of a changed compaction table runs again to Vf 0.33, a wider gap."""
    spec = tiny_spec(compaction={"final_fvf": 0.35, "end": "final_fvf"})
    folder = tmp_path_factory.mktemp("study") / "study"
    study(spec, folder, [("compaction.inertial_number", [0.8, 0.4])], ["compaction"])
    return spec, folder


@pytest.mark.lammps
def test_study_writes_table_plot_and_errors(compaction_study):
    """Reference = the slower rate (0.4): its errors are 0; the other point's error is
    |x - x_ref| / x_ref of its own outputs, to the CSV's rounding: 7 significant digits put up
    to 5e-7 |x| on each value, so the recomputed error is good to 5e-7 (|x| + |x_ref|) / x_ref."""
    _, folder = compaction_study
    rows = list(csv.DictReader(open(folder / "study.csv")))
    assert [r["compaction.inertial_number"] for r in rows] == ["0.8", "0.4"]
    fast, ref = rows
    assert ref["reference"] == "True" and float(ref["max_error"]) == 0.0
    for key in ("thickness_at_1kPa_mm", "thickness_at_18kPa_mm"):
        x, x_ref = float(fast[key]), float(ref[key])
        expected = abs(x - x_ref) / x_ref
        rounding = 5e-7 * (abs(x) + abs(x_ref)) / x_ref
        assert float(fast[f"error_{key}"]) == pytest.approx(expected, rel=1e-5, abs=rounding)
    # Both points share one manufactured state: equal manufacture outputs, error exactly 0.
    assert fast["stitch_tension_N"] == ref["stitch_tension_N"]
    assert float(fast["wall_s"]) > 0 and int(fast["steps"]) < int(ref["steps"])
    assert (folder / "study.png").stat().st_size > 10_000
    assert "Pareto" in (folder / "study.md").read_text()


@pytest.mark.lammps
def test_study_resumes_by_reusing_complete_points(compaction_study):
    spec, folder = compaction_study
    before = (folder / "study.csv").read_text()
    study(spec, folder, [("compaction.inertial_number", [0.8, 0.4])], ["compaction"])
    rows = list(csv.DictReader(open(folder / "study.csv")))
    assert [r["status"] for r in rows] == ["ok (reused)", "ok (reused)"]
    assert [r["max_error"] for r in rows] == [
        r["max_error"] for r in csv.DictReader(before.splitlines())
    ]


@pytest.mark.lammps
def test_study_keeps_a_folder_manufacture_and_reruns_only_changed_scenes(
    compaction_study, tmp_path
):
    """Same model and manufacture, other test settings: each point keeps its folder's
    manufacture (identical outputs); a compaction whose table is unchanged is kept too
    (a shear setting changed), one whose table changed runs again."""
    spec, source = compaction_study
    folder = tmp_path / "study"
    shutil.copytree(source, folder)
    vary = [("compaction.inertial_number", [0.8, 0.4])]
    before = list(csv.DictReader(open(folder / "study.csv")))

    study(spec.replace(shear={"inertial_number": 0.2}), folder, vary, ["compaction"])
    kept = list(csv.DictReader(open(folder / "study.csv")))
    assert [r["status"] for r in kept] == ["ok (reused manufacture, compaction)"] * 2
    for old, new in zip(before, kept, strict=True):
        assert new["thickness_at_1kPa_mm"] == old["thickness_at_1kPa_mm"]
        assert new["steps"] == old["steps"]

    study(spec.replace(compaction={"final_fvf": 0.33}), folder, vary, ["compaction"])
    rerun = list(csv.DictReader(open(folder / "study.csv")))
    assert [r["status"] for r in rerun] == ["ok (reused manufacture)"] * 2
    for old, new in zip(before, rerun, strict=True):
        assert new["stitch_tension_N"] == old["stitch_tension_N"]
        assert int(new["steps"]) < int(old["steps"])  # the plates stop at a wider gap
    stored = read_results(folder / "points" / "p00" / "results.h5")["attrs"]["spec_toml"]
    assert "final_fvf = 0.33" in (stored.decode() if isinstance(stored, bytes) else stored)


@pytest.mark.lammps
def test_study_asked_for_more_scenes_runs_them_on_the_kept_manufacture(compaction_study, tmp_path):
    """A point finished with fewer scenes than asked for is not reused whole: its manufacture
    is kept and the missing test scene runs."""
    spec, _ = compaction_study
    folder = tmp_path / "study"
    vary = [("compaction.inertial_number", [0.8])]
    study(spec, folder, vary, ["manufacture"])
    first = list(csv.DictReader(open(folder / "study.csv")))
    assert first[0]["status"] == "ok" and "thickness_at_1kPa_mm" not in first[0]

    study(spec, folder, vary, ["manufacture", "compaction"])
    (row,) = list(csv.DictReader(open(folder / "study.csv")))
    assert row["status"] == "ok (reused manufacture)"
    assert row["stitch_tension_N"] == first[0]["stitch_tension_N"]
    assert float(row["thickness_at_1kPa_mm"]) > 0


KILL_TOO_LATE = "the study ended before it could be killed"


@pytest.fixture(scope="module")
def killed_study(tmp_path_factory):
    """A two-point study of the compaction rate on the tiny cell, checkpointing every 2,000
    steps, killed (SIGKILL) twice, each time after a checkpoint: in the first point's
    manufacture (its own folder), then in the second point's compaction (a temporary copy of
    the first point's manufactured state); then run again to the end."""
    tmp = tmp_path_factory.mktemp("killed_study")
    spec = tiny_spec(
        compaction={"final_fvf": 0.35, "end": "final_fvf"},
        output={"checkpoint_every_steps": 2000},
    )
    write_spec(tmp / "spec.toml", spec)
    folder = tmp / "study"
    command = [sys.executable, "-m", "ncf2lammps.cli", "study", str(tmp / "spec.toml")]
    command += ["-o", str(folder), "--vary", "compaction.inertial_number=0.8,0.4"]
    command += ["--scene", "manufacture", "--scene", "compaction"]
    assert kill_after_checkpoint(command, folder, "points/p00", "manufacture"), KILL_TOO_LATE
    killed_in_own_folder = read_results(folder / "points" / "p00" / "results.h5")
    assert kill_after_checkpoint(command, folder, "points/p01.partial-*", "compaction"), (
        KILL_TOO_LATE
    )
    partials = sorted(p.name for p in (folder / "points").glob("p01.partial-*"))
    out = subprocess.run(command, capture_output=True, text=True)
    return folder, killed_in_own_folder, partials, out


@pytest.mark.lammps
def test_a_killed_study_resumes_each_killed_point_from_its_checkpoint(killed_study):
    """Killed in a point's own folder or in a point's temporary folder, the point continues
    from its checkpoint (`resumed` in its scene's attributes; status `ok (resumed)` in the run
    that finishes it); no temporary folder is left."""
    folder, killed, partials, out = killed_study
    assert out.returncode == 0, out.stderr
    assert not killed["attrs"]["complete"] and "manufacture" not in killed
    assert len(partials) == 1  # the second kill left the temporary folder
    rows = list(csv.DictReader(open(folder / "study.csv")))
    # The first point finished in the second run: the third reuses it.
    assert [r["status"] for r in rows] == ["ok (reused)", "ok (resumed)"]
    first = read_results(folder / "points" / "p00" / "results.h5")
    second = read_results(folder / "points" / "p01" / "results.h5")
    assert first["manufacture"]["attrs"]["resumed"] and second["compaction"]["attrs"]["resumed"]
    # The second point's own compaction (at half the first's rate), not the copied one.
    assert second["compaction"]["attrs"]["steps"] > first["compaction"]["attrs"]["steps"]
    assert bool(first["attrs"]["complete"]) and bool(second["attrs"]["complete"])
    assert not list((folder / "points").glob("*.partial-*"))
