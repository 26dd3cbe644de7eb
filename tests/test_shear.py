"""Shear scene: picture-frame kinematics on the periodic box, normalised shear force."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest
from conftest import (
    ROOT,
    assert_loading_follows_its_law,
    case_spec,
    copy_run,
    frictionless_mat_spec,
    tiny_spec,
)

from ncf2lammps import build_model, prepare, run, run_scenes
from ncf2lammps.analysis.shear import FORCE_WINDOW, PictureFrame, ShearCurve, work_force
from ncf2lammps.io.datafile import read_data
from ncf2lammps.io.lammpslog import read_ave_time
from ncf2lammps.io.results import read_results
from ncf2lammps.orchestration.report import write_report
from ncf2lammps.scenes import SCENES
from ncf2lammps.scenes.shear import DEFORM_EVERY, shear_rate
from ncf2lammps.scenes.stitch import path_attrs
from ncf2lammps.spec import SpecError, shear_recipe

#: Test rate and final angle on the coarse case (deg/us, deg): I = 0.1, 4 x the default, to
#: 25 deg, about a minute. Faster, or further: at I = 0.1 the overlap guard stopped it near
#: 30 deg (a stitch bead pressed into a fibre bead by 1.13 of its diameter), at I = 0.2 and 0.4
#: earlier. The default rate reaches 45 deg (docs/study.md, point p00).
COARSE_TEST_RATE = 0.02125
COARSE_TEST_ANGLE = 25.0
#: The coarse test shears with adaptive loading (not the default), at most 2 x the test rate.
COARSE_TEST = {
    "shear_rate_deg_us": COARSE_TEST_RATE,
    "final_angle_deg": COARSE_TEST_ANGLE,
    "loading": "adaptive",
    "max_rate_factor": 2.0,
}


def _binned(angle_deg, values, width_deg=1.0):
    """Means of ``values`` over bins of ``width_deg`` of the angle, (B,)."""
    bins = np.floor(angle_deg / width_deg).astype(int)
    return np.bincount(bins, values) / np.maximum(np.bincount(bins), 1)


@pytest.fixture(scope="module")
def frictionless_mat(tmp_path_factory):
    """(spec, folder, /shear group) of the mat without stitch, mu = 0, pretension 22 N/m, 40 deg.

    A checkpoint (every 48,700 steps here: the guard and record cadences) falls inside each of
    the two runs, 0-22.5 and 22.5-40 deg. Each re-initialises fix deform, which once restarted
    the second run's tilt from the first run's start (xy jumped by 1.9 mm in the paper cell).
    """
    spec = case_spec("mat-only").replace(
        contact={"friction": 0.0},
        shear={"final_angle_deg": 40.0, "fibre_pretension_N_m": 22.0, "shear_rate_deg_us": 0.1},
        output={"checkpoint_every_steps": 40_000},
    )
    folder = tmp_path_factory.mktemp("mat") / "run"
    results = read_results(run(spec, folder, scenes=["shear"]))
    return spec, folder, results["shear"]


@pytest.mark.lammps
def test_frictionless_pretensioned_mat_has_no_shear_force(frictionless_mat):
    """Straight chains keep their length under picture-frame kinematics: F_N = 0 (docs/design.md §7).

    Scale: N0 = 22 N/m, the pretension per unit width of each ply (chain tension times chains
    per width); the pretension itself is checked in the virial, N_yy = -Pyy lz = N0 at g = 0.
    """
    spec, folder, group = frictionless_mat
    n0 = spec.shear.fibre_pretension_N_m
    assert np.max(np.abs(group["force_N_per_m"])) < 0.01 * n0
    assert np.max(np.abs(group["force_work_N_per_m"])) < 0.01 * n0
    stress = read_ave_time(folder / "shear.history.txt")
    assert stress["v_nyy"][0] * 1e-3 == pytest.approx(n0, rel=0.01)  # kPa um = 1e-3 N/m
    assert group["attrs"]["final_angle_deg"] == pytest.approx(40.0, abs=0.05)


@pytest.mark.lammps
def test_box_follows_picture_frame_kinematics(frictionless_mat):
    """xy = Lb sin g and ly = Lb cos g through every chunk and run: each record holds the box
    of its own step, to 1e-3 of one box update's increment (the box moves every DEFORM_EVERY
    steps; recorded after the update)."""
    _, folder, _ = frictionless_mat
    box = read_ave_time(folder / "shear.box.txt")
    lb = box["v_box_ly"][0]
    per_step = np.max(np.abs(np.diff(box["v_box_xy"]))) / np.diff(box["TimeStep"]).max()
    update = DEFORM_EVERY * per_step
    assert np.max(np.abs(box["v_box_xy"] - lb * np.sin(box["v_g"]))) < 1e-3 * update
    assert np.max(np.abs(box["v_box_ly"] - lb * np.cos(box["v_g"]))) < 1e-3 * update
    assert np.all(box["v_box_lx"] == box["v_box_lx"][0])


@pytest.fixture(scope="module")
def coarse_sheared(coarse_manufactured, tmp_path_factory):
    """(folder, results) of the manufactured coarse case sheared at the test rate and angle."""
    folder = copy_run(coarse_manufactured, tmp_path_factory.mktemp("shear") / "run")
    spec = case_spec("hpt310-coarse").replace(shear=COARSE_TEST)
    run_scenes(spec, folder, ["shear"])
    write_report(folder)
    return folder, read_results(folder / "results.h5")


@pytest.mark.lammps
def test_results_follow_the_contract(coarse_sheared):
    folder, results = coarse_sheared
    group = results["shear"]
    for key in ("force_at_final_N_per_m", "wall_s", "steps", "max_kinetic_ratio"):
        assert np.isfinite(group["attrs"][key])
    # the holes since manufacture: matched, within one gauge of where they were
    assert 0.0 <= group["attrs"]["stitch_hole_slip_mm"] < 5.08
    assert 0.0 < group["attrs"]["stitch_shog_width_ratio"] < 1.2
    # the stitch's length since manufacture: the recorded strains are those of the state files
    # (1e-12), and the affine one lies within the frame map's principal stretches
    final = folder / "shear_25deg.data"
    model = prepare(case_spec("hpt310-coarse")).model
    recomputed = path_attrs(model, folder / "manufactured.data", final)
    for key, value in recomputed.items():
        assert group["attrs"][key] == pytest.approx(value, abs=1e-12)
    g = np.radians(COARSE_TEST_ANGLE)
    stretches = np.linalg.svd([[1.0, np.sin(g)], [0.0, np.cos(g)]], compute_uv=False)
    assert stretches[1] - 1 <= recomputed["stitch_path_affine_strain"] <= stretches[0] - 1
    names = ("angle_deg", "force_N_per_m", "force_work_N_per_m", "kinetic_ratio", "work_J")
    assert len({len(group[k]) for k in names}) == 1 and len(group["angle_deg"]) > 100
    assert group["angle_deg"][-1] == pytest.approx(COARSE_TEST_ANGLE, abs=0.2)
    for name in ("shear_22.5deg.data", "shear_25deg.data"):
        assert (folder / name).is_file()
    for name in ("shear_force.png", "shear_views_22.5deg.png"):  # views at the paper's angles
        assert (folder / "figures" / name).stat().st_size > 10_000


@pytest.mark.lammps
def test_shear_follows_the_adaptive_loading_law(coarse_sheared):
    """Adaptive loading: every record's shear rate follows the controller's law from the
    interval's shear stress and kinetic stress ratio, and the angle grows by the integral of the
    rate."""
    folder, results = coarse_sheared
    spec = case_spec("hpt310-coarse").replace(shear=COARSE_TEST)
    prepared = prepare(spec)
    control = SCENES["shear"].deck_values(prepared)["control"]
    box = read_ave_time(folder / "shear.box.txt")
    assert control.adaptive
    assert_loading_follows_its_law(box, "v_g", control, prepared.time_step.dt, 1)
    attrs = results["shear"]["attrs"]
    assert attrs["max_shear_rate_deg_us"] >= attrs["shear_rate_deg_us"]


@pytest.mark.lammps
def test_virial_and_work_forces_agree(coarse_sheared):
    """F_N from the virial and from the box work agree within 2 % (1-degree means, loaded)."""
    _, results = coarse_sheared
    group = results["shear"]
    virial = _binned(group["angle_deg"], group["force_N_per_m"])
    work = _binned(group["angle_deg"], group["force_work_N_per_m"])
    loaded = np.abs(virial) > 0.1 * np.abs(virial).max()
    assert np.max(np.abs(work[loaded] / virial[loaded] - 1)) < 0.02
    total_virial = np.trapezoid(group["force_N_per_m"], group["angle_deg"])
    total_work = np.trapezoid(group["force_work_N_per_m"], group["angle_deg"])
    assert total_work == pytest.approx(total_virial, rel=0.02)


@pytest.mark.lammps
def test_shear_of_a_stitched_cell_starts_from_the_manufactured_state(coarse_sheared):
    folder, _ = coarse_sheared
    deck = (folder / "decks" / "in.shear.lmp").read_text()
    assert "read_restart    manufactured.restart" in deck
    # No fibre pretension asked: no pretension bonds.
    assert "fix             pretension" not in deck


@pytest.mark.lammps
def test_the_locked_coarse_cell_keeps_its_stitch_tensioned(coarse_sheared):
    """runs/stitch_in_shear.py on the paper's model: its locked cell keeps the stitch at >= 90 %
    of the manufactured tension through the test shear (measured 100-187 % to 22.5 deg on four
    rates of the same cell), each dump frame's path and affine path start at 0, and every frame
    gives each bead type's z percentiles (p1 <= p50 <= p99) with the plies in their stacking
    order (the median of ply k below that of ply k + 1: the shear does not swap the plies).
    Each ply's packing lies between 0 and the densest packing of parallel rods,
    pi / (2 sqrt 3) = 0.907, and the locked cell densifies in plane as the frame's area falls
    (cos g): each ply's packing at the last frame is at least its packing at the first (a
    replica of this case: 0.323 -> 0.349 and 0.312 -> 0.345 from 0 to 25 deg)."""
    folder, results = coarse_sheared
    script = ROOT / "runs" / "stitch_in_shear.py"
    output = subprocess.run(
        [sys.executable, str(script), str(folder), "--angles", "1", "5", "10", "20"],
        capture_output=True,
        text=True,
        check=True,
    )
    report = json.loads(output.stdout)[str(folder)]
    made = results["manufacture"]["attrs"]["stitch_tension_N"]
    assert report["manufactured_tension_N"] == pytest.approx(made)
    assert min(report["retained"].values()) >= 0.9
    frames = report["path"]
    assert len(frames) >= 2 and frames[0]["path_change"] == frames[0]["affine_change"] == 0.0
    assert 0.0 < frames[-1]["box_tilt_deg"] <= COARSE_TEST_ANGLE + 0.2
    labels = read_data(folder / "model.data").atom_labels
    plies = [label for label in labels if label != "stitch"]
    for frame in frames:
        z = frame["z_percentiles_um"]
        assert list(z) == list(labels)
        assert all(p1 <= p50 <= p99 for p1, p50, p99 in z.values())
        medians = [z[label][1] for label in plies]
        assert medians == sorted(medians)
        assert list(frame["ply_packing"]) == plies
        assert all(0.0 < p < np.pi / (2 * np.sqrt(3)) for p in frame["ply_packing"].values())
    for label in plies:
        assert frames[-1]["ply_packing"][label] >= frames[0]["ply_packing"][label]


@pytest.mark.lammps
@pytest.mark.slow
def test_halving_the_rate_moves_the_force_less_than_3_percent(coarse_manufactured, tmp_path):
    """Quasi-static at the case's rate (I = 0.1): F_N(45 deg), the 2-deg trailing line of the
    records, moves < 3 % at half the rate (measured: 1.3 %)."""
    spec = case_spec("hpt310-coarse")
    default = math.degrees(shear_rate(spec, build_model(spec)))
    forces = []
    for name, rate in (("default", default), ("half", default / 2)):
        folder = copy_run(coarse_manufactured, tmp_path / name)
        run_scenes(spec.replace(shear={"shear_rate_deg_us": rate}), folder, ["shear"])
        attrs = read_results(folder / "results.h5")["shear"]["attrs"]
        forces.append(attrs["force_at_45deg_N_per_m"])
    assert forces[1] == pytest.approx(forces[0], rel=0.03)


def test_shear_rate_is_derived_or_given():
    spec = case_spec("hpt310-coarse")
    model = build_model(spec)
    derived = shear_rate(spec, model)
    half = spec.shear.inertial_number / 2
    quieter = shear_rate(spec.replace(shear={"inertial_number": half}), model)
    assert quieter == pytest.approx(derived / 2)
    given = spec.replace(shear={"shear_rate_deg_us": 0.01})
    assert shear_rate(given, model) == pytest.approx(math.radians(0.01))


def test_bad_shear_input_names_the_field():
    with pytest.raises(SpecError, match=r"shear.final_angle_deg"):
        case_spec("mat-only").replace(shear={"final_angle_deg": 75.0})
    with pytest.raises(SpecError, match=r"shear.fibre_pretension_N_m"):
        case_spec("mat-only").replace(shear={"fibre_pretension_N_m": -1.0})


def test_work_force_of_constant_membrane_forces():
    """Picture frame La x Lb under constant Nxy, Nyy: ``F_N = Nxy - Nyy tan g``.

    The work telescopes exactly, ``W = La Lb (Nxy sin g + Nyy (cos g - 1))`` (to rounding); per
    interval of dg = 0.225 deg the mid-point law holds to O(dg^2) (1e-5 here).
    """
    la, lb, nxy, nyy = 3.0, 2.0, 5.0, -1.5
    angle = np.linspace(0.0, math.pi / 4, 201)
    mid = 0.5 * (angle[1:] + angle[:-1])
    args = (angle, lb * np.sin(angle), la, lb * np.cos(angle))
    d_work, force = work_force(*args, np.full(200, nxy), np.full(200, nyy))
    g = angle[-1]
    assert d_work.sum() == pytest.approx(la * lb * (nxy * np.sin(g) + nyy * (np.cos(g) - 1)))
    assert force == pytest.approx(nxy - nyy * np.tan(mid), rel=1e-5)
    _, same = work_force(angle, args[1], np.full(201, la), args[3], [nxy] * 200, [nyy] * 200)
    assert np.array_equal(same, force)  # a scalar lx is the constant edge


def test_force_at_an_angle_is_the_trailing_line_of_the_records():
    """F_N at an angle is the least-squares line through the records of the trailing window.

    A straight curve comes back exactly (1e-9); a stick-slip of +-10 % alternating record by
    record (20 records in the window) comes out below 2 % of the line's value; with fewer than
    3 records in the window it interpolates.
    """
    angle = np.linspace(0.0, math.pi / 4, 451)
    mid = 0.5 * (angle[1:] + angle[:-1])
    line = 3.0 + 60.0 * mid
    zeros, box = np.zeros(450), (angle, np.zeros(451), 1.0, np.ones(451))
    curve = ShearCurve(*box, line, zeros, zeros, zeros).compute()
    assert curve.force_at(math.pi / 4) == pytest.approx(3.0 + 60.0 * math.pi / 4, rel=1e-9)
    swing = line * (1.0 + 0.1 * (-1.0) ** np.arange(450))
    noisy = ShearCurve(*box, swing, zeros, zeros, zeros).compute()
    assert noisy.force_at(math.pi / 4) == pytest.approx(3.0 + 60.0 * math.pi / 4, rel=0.02)
    assert curve.force_at(mid[1]) == pytest.approx(np.interp(mid[1], mid, line))
    assert math.isnan(curve.force_at(math.pi / 3))
    assert FORCE_WINDOW > 2 * (mid[1] - mid[0])  # the window holds more than 2 records


def test_frame_and_senses_are_checked_with_one_line_errors():
    spec = tiny_spec()
    assert spec.shear.frame(spec.plies) == (90.0, 0.0)  # the first two distinct ply angles
    assert spec.shear.senses == ("positive",)
    bad = [
        ("frame_deg", [0.0, 45.0], r"shear.frame_deg = \[0.0, 45.0\]: 45 is no ply's angle_deg"),
        ("frame_deg", [0.0], r"shear.frame_deg = \[0.0\]: must name two ply angles"),
        ("frame_deg", [90.0, 90.0], r"shear.frame_deg .*must be 0 and 90 .* or two angles"),
        ("senses", ["sideways"], r"shear.senses\[0\] = 'sideways': must be one of positive"),
        ("senses", ["negative", "negative"], r"shear.senses .*at most once"),
        ("senses", [], r"shear.senses = \[\]: must hold"),
    ]
    for key, value, message in bad:
        with pytest.raises(SpecError, match=message) as err:
            tiny_spec(shear={key: value})
        assert "\n" not in str(err.value)


def test_recipe_kinds_of_frames():
    assert shear_recipe((0.0, 90.0)) == shear_recipe((90.0, 0.0)) == "tilt"
    assert shear_recipe((45.06, -45.06)) == shear_recipe((-30.0, 30.0)) == "stretch"
    for frame in ((0.0, 45.0), (45.0, -45.1), (0.0, 0.0), (90.0, -90.0), (60.0, 90.0)):
        assert shear_recipe(frame) is None, frame


def test_tilt_recipe_is_the_paper_picture_frame():
    """Tilt, positive: xy = Lb sin g, ly = Lb cos g, lx fixed (exactly); negative: xy mirrored."""
    g = np.linspace(0.0, math.radians(60.0), 61)
    lx, ly, xy = PictureFrame.tilt(1).box(g, 3.0, 2.0)
    assert np.array_equal(xy, 2.0 * np.sin(g)) and np.array_equal(ly, 2.0 * np.cos(g))
    assert np.all(lx == 3.0)
    _, ly_n, xy_n = PictureFrame.tilt(-1).box(g, 3.0, 2.0)
    assert np.array_equal(xy_n, -xy) and np.array_equal(ly_n, ly)


@pytest.mark.parametrize("sense", [1, -1])
def test_frame_fibres_keep_their_length(sense):
    """Inextensibility: the fibres of the frame keep their lengths to 1e-12 (relative) along g,
    for a realised +-45.06 deg frame (lattice vectors (a Lx, +-b Ly) of a non-square cell) and
    for 0/90 (edge vectors); the angle between the fibres containing x changes by -s g."""
    g = np.linspace(0.0, math.radians(50.0), 51)
    lx0, ly0 = 1000.0, 1003.3  # um
    phi0 = math.degrees(math.atan2(ly0, lx0))
    frame = PictureFrame.stretch(phi0, sense)
    lx, ly, xy = frame.box(g, lx0, ly0)
    assert np.all(xy == 0.0)
    for a, b in ((1, 1), (1, -1), (3, 3)):
        length = np.hypot(a * lx, b * ly)
        assert np.max(np.abs(length / length[0] - 1)) < 1e-12
    between = 2 * np.arctan2(ly, lx)  # angle between +phi and -phi, containing x
    assert np.allclose(between - between[0], -sense * g, atol=1e-12)
    lx, ly, xy = PictureFrame.tilt(sense).box(g, lx0, ly0)
    assert np.max(np.abs(np.hypot(xy, ly) / ly0 - 1)) < 1e-12  # edge b
    assert np.all(lx == lx0)  # edge a
    diagonal = np.hypot(lx + xy, ly)  # the +45 diagonal lengthens in the positive sense
    assert np.all(sense * np.diff(diagonal) > 0)


@pytest.mark.parametrize(
    "frame", [PictureFrame.tilt(1), PictureFrame.tilt(-1), PictureFrame.stretch(45.06, -1)]
)
def test_virial_force_is_the_power_and_the_work(frame):
    """F_N = power / (area shear rate): the closed forms of the deck (tilt s (Nxy - Nyy xy/ly),
    stretch s (Nxx tan(phi) - Nyy cot(phi)) / 2) equal the general L = hdot h^-1 form to 1e-12,
    and the work-based F_N of constant membrane forces over small intervals equals it to 1e-5."""
    g = np.linspace(0.0, math.radians(45.0), 4501)
    nxx, nyy, nxy = 3.0, -1.5, 0.7
    lx, ly, xy = frame.box(g, 900.0, 1100.0)
    general = frame.force(g, 900.0, 1100.0, nxx, nyy, nxy)
    if frame.kind == "tilt":
        closed = frame.sense * (nxy - nyy * xy / ly)
    else:
        phi = frame.half_angle - 0.5 * frame.sense * g
        closed = frame.sense * (nxx * np.tan(phi) - nyy / np.tan(phi)) / 2
    assert np.allclose(general, closed, rtol=1e-12, atol=1e-12)
    n = len(g) - 1
    _, by_work = work_force(g, xy, lx, ly, np.full(n, nxy), np.full(n, nyy), np.full(n, nxx))
    mid = frame.force(0.5 * (g[1:] + g[:-1]), 900.0, 1100.0, nxx, nyy, nxy)
    assert np.max(np.abs(by_work - mid)) < 1e-5 * np.max(np.abs(mid))


def test_work_of_a_stretching_box_needs_nxx():
    g = np.linspace(0.0, 0.1, 3)
    lx, ly, xy = PictureFrame.stretch(45.0).box(g, 1.0, 1.0)
    with pytest.raises(ValueError, match="give nxx"):
        work_force(g, xy, lx, ly, np.zeros(2), np.zeros(2))


@pytest.mark.lammps
def test_both_senses_of_a_tiny_frictionless_mat(tmp_path):
    """One run, both senses from the same start: /shear (positive, xy = Lb sin g) and
    /shear_negative (xy = -Lb sin g, ly = Lb cos g, to 1e-3 of a box update); pretensioned
    frictionless straight chains keep their lengths, so |F_N| < 1 % of N0 = 22 N/m in both;
    summary.md gives F_N at 45 deg per sense and their ratio, one figure holds both curves."""
    spec = frictionless_mat_spec(46.0)
    results = read_results(run(spec, tmp_path / "run", scenes=["shear", "shear_negative"]))
    for group, sense in (("shear", "positive"), ("shear_negative", "negative")):
        attrs = results[group]["attrs"]
        assert (attrs["sense"], attrs["recipe"]) == (sense, "tilt")
        assert list(attrs["frame_deg"]) == [90.0, 0.0]
        assert np.max(np.abs(results[group]["force_N_per_m"])) < 0.01 * 22.0
    box = read_ave_time(tmp_path / "run" / "shear_negative.box.txt")
    lb = box["v_box_ly"][0]
    update = (
        DEFORM_EVERY * np.max(np.abs(np.diff(box["v_box_xy"]))) / np.diff(box["TimeStep"]).max()
    )
    assert np.max(np.abs(box["v_box_xy"] + lb * np.sin(box["v_g"]))) < 1e-3 * update
    assert np.max(np.abs(box["v_box_ly"] - lb * np.cos(box["v_g"]))) < 1e-3 * update
    summary = (tmp_path / "run" / "summary.md").read_text()
    assert "| asymmetry F_N+(45) / F_N-(45) |" in summary
    assert (tmp_path / "run" / "figures" / "shear_force.png").is_file()
    assert (tmp_path / "run" / "shear_negative_45deg.data").is_file()


@pytest.mark.lammps
def test_confined_shear_reads_the_records_and_adds_frictionless_plates(coarse_sheared, tmp_path):
    """runs/confined_shear.py. `report` on a free shear: F_N at an angle is the mean of the
    history's records (nN/um x 1e-3 = N/m) whose angle lies within +-0.5 deg, to rounding.
    `prepare`: the shear deck gains, before its shear stage, two plates with the compaction's
    plate law at friction 0, their record aligned with the shear history, and a squeeze of
    ceil((thickness - gap) / speed / dt) steps plus 20 % hold; a gap not below the manufactured
    thickness is one line on stderr, exit 2, and no folder."""
    folder, results = coarse_sheared
    script = ROOT / "runs" / "confined_shear.py"

    def confined(*args):
        return subprocess.run(
            [sys.executable, str(script), *map(str, args)], capture_output=True, text=True
        )

    report = json.loads(confined("report", folder, "--angles", "10", "20").stdout)[0]
    history = read_ave_time(folder / "shear.history.txt")
    box = read_ave_time(folder / "shear.box.txt")
    angle_at = dict(zip(box["TimeStep"], np.degrees(box["v_g"]), strict=True))
    angle = np.array([angle_at.get(step, np.nan) for step in history["TimeStep"]])
    for at in (10, 20):
        inside = np.abs(angle - at) <= 0.5
        expected = history["v_fn"][inside].mean() * 1e-3
        assert report["fn_window_mean_N_per_m"][str(at)] == pytest.approx(expected, rel=1e-12)

    thickness = results["manufacture"]["attrs"]["thickness_mm"] * 1e3
    refused = confined("prepare", folder, tmp_path / "thick", "--gap-um", thickness + 1)
    assert refused.returncode == 2 and len(refused.stderr.strip().splitlines()) == 1
    assert "--gap-um" in refused.stderr and not (tmp_path / "thick").exists()

    gap, speed = 0.9 * thickness, 0.17
    made = confined("prepare", folder, tmp_path / "conf", "--gap-um", gap)
    assert made.returncode == 0, made.stderr
    deck = (tmp_path / "conf" / "in.shear.lmp").read_text()
    before, after = deck.split("# stage: shear\n")
    walls = [ln for ln in before.splitlines() if "wall/gran/region" in ln]
    assert len(walls) == 2 and all("linear_history" in ln for ln in walls)
    tangential = [ln.split("tangential")[1].split()[:4] for ln in walls]
    assert all(float(mu) == 0.0 for _, _, _, mu in tangential)
    dt = float(before.split("\ntimestep")[1].split()[0])
    descent = math.ceil((thickness - gap) / speed / dt)
    assert f"run             {descent + math.ceil(0.2 * descent)}\n" in before
    period = deck.split("fix             history all ave/time 1 ")[1].split()[:2]
    assert f"plates all ave/time 1 {period[0]} {period[1]} " in after
