"""Manufacture scene on the coarse case, end to end."""

from __future__ import annotations

import h5py
import numpy as np
import pytest
from conftest import case_spec, deck_commands, run_lammps_file, tiny_spec

from ncf2lammps import build, units
from ncf2lammps.analysis.geometry import min_xy_distance
from ncf2lammps.io.datafile import read_data
from ncf2lammps.io.results import read_results
from ncf2lammps.numerics import prepare
from ncf2lammps.scenes.manufacture import deck_values, needle_axes
from ncf2lammps.scenes.stitch import hole_attrs


@pytest.fixture(scope="module")
def manufactured(coarse_manufactured):
    """(spec, run folder, results) of the coarse case after ``run --scene manufacture``."""
    folder = coarse_manufactured
    return case_spec("hpt310-coarse"), folder, read_results(folder / "results.h5")


@pytest.mark.lammps
def test_results_follow_the_contract(manufactured):
    _, folder, results = manufactured
    assert bool(results["attrs"]["complete"])
    group = results["manufacture"]
    for key in ("wall_s", "steps", "thickness_mm", "stitch_tension_N"):
        assert np.isfinite(group["attrs"][key])
    lengths = {
        len(group[k]) for k in ("time_us", "stitch_tension_N", "thickness_mm", "kinetic_ratio")
    }
    assert len(lengths) == 1 and lengths.pop() > 10
    for name in ("manufactured.restart", "manufactured.data", "summary.md"):
        assert (folder / name).is_file()
    for name in ("manufacture_views.png", "manufacture_history.png"):
        assert (folder / "figures" / name).stat().st_size > 10_000
    with h5py.File(folder / "results.h5") as fh:
        assert fh["manufacture/time_us"].dtype == np.float64


@pytest.mark.lammps
def test_stitch_tension_within_5_percent_and_quasi_static(manufactured):
    spec, _, results = manufactured
    attrs = results["manufacture"]["attrs"]
    assert attrs["stitch_tension_N"] == pytest.approx(spec.manufacture.stitch_tension_N, rel=0.05)
    assert attrs["kinetic_ratio"] < spec.manufacture.kinetic_ratio_target
    assert 0.2 < attrs["thickness_mm"] < 1.0


@pytest.mark.lammps
def test_holes_are_measured_against_the_generated_lapping(manufactured):
    """The holes of the manufactured yarn match the generated ones (the width ratio is a
    number in (0, 1.2), the slip finite); the generated state itself reads width 1, slip 0."""
    spec, folder, results = manufactured
    attrs = results["manufacture"]["attrs"]
    assert 0.0 < attrs["stitch_shog_width_ratio"] < 1.2
    assert 0.0 <= attrs["stitch_hole_slip_mm"] < spec.stitch.gauge_mm
    assert "stitch_shog_width_ratio" in (folder / "summary.md").read_text()
    generated = hole_attrs(prepare(spec).model, None, folder / "model.data")
    assert generated["stitch_shog_width_ratio"] == pytest.approx(1.0, rel=1e-9)
    assert generated["stitch_hole_slip_mm"] < 1e-9


@pytest.mark.lammps
def test_pretension_work_is_the_integral_of_tension_over_rest_length(manufactured):
    """The deck's work integral W = L0 integral T dstrain (its denominator of kinetic / work) equals
    the trapezoidal integral of the recorded tension over the recorded stitch strain (one row
    per 100 steps) within 1 %, and kinetic / work is recomputed from its parts."""
    from ncf2lammps import build_model

    spec, _, results = manufactured
    group = results["manufacture"]
    model = build_model(spec)
    stitch = np.array([t.role == "stitch" for t in model.bond_types])[model.bond_type]
    rest_length_m = np.array([t.r0 for t in model.bond_types])[model.bond_type][stitch].sum() * 1e-6
    tension, strain = group["stitch_tension_N"], group["stitch_strain"]
    work = rest_length_m * np.sum(0.5 * (tension[1:] + tension[:-1]) * np.diff(strain))
    assert group["attrs"]["pretension_work_J"] == pytest.approx(work, rel=0.01)
    assert group["pretension_work_J"][-1] == pytest.approx(work, rel=0.01)
    assert work > 0 and strain[-1] > 0
    loaded = group["pretension_work_J"] > 0
    np.testing.assert_allclose(
        group["kinetic_ratio"][loaded],
        group["kinetic_energy_J"][loaded] / group["pretension_work_J"][loaded],
    )
    assert np.all(np.isnan(group["kinetic_ratio"][~loaded]))


@pytest.mark.lammps
def test_channels_open_after_needle_step(manufactured):
    """No fibre bead centre closer to a needle axis than the needle radius (images included)."""
    _, _, results = manufactured
    attrs = results["manufacture"]["attrs"]
    assert attrs["channel_min_distance_um"] >= attrs["needle_radius_um"]
    assert attrs["insertion_max_overlap_d"] <= 0.05


@pytest.mark.lammps
def test_manufactured_state_keeps_the_model(manufactured):
    """Every atom and bond survives; the pretensioned stitch rest lengths are in the file."""
    _, folder, _ = manufactured
    before = read_data(folder / "model.data")
    after = read_data(folder / "manufactured.data")
    assert len(after.positions) == len(before.positions)
    assert np.array_equal(np.sort(after.bond_type), np.sort(before.bond_type))
    stitch = [i for i, name in enumerate(before.bond_labels) if name.startswith("stitch")]
    assert np.all(after.bond_coeffs[stitch, 1] < before.bond_coeffs[stitch, 1])
    fibre = [i for i, name in enumerate(before.bond_labels) if not name.startswith("stitch")]
    # LAMMPS write_data prints coefficients with 6 digits; the test scenes start from the
    # full-precision restart file instead.
    np.testing.assert_allclose(after.bond_coeffs[fibre], before.bond_coeffs[fibre], rtol=1e-5)


CREEP = {"stitch_creep_target_per_ms": 1.0, "creep_window_us": 50.0}


def test_creep_criterion_reads_the_yarns_stiffness_and_whole_windows():
    """The deck's creep is the controller's mean strain increment x EA / (T control_every dt),
    EA = E x linear density / density of the spec's yarn (66.09 N for 76 dtex PES at 12 GPa),
    checked once per window of whole convergence windows covering ``creep_window_us``."""
    from ncf2lammps.numerics import prepare

    spec = tiny_spec(manufacture=CREEP)
    run = prepare(spec)
    creep, dt = deck_values(run)["creep"], run.time_step.dt
    stitch = spec.stitch
    stiffness_N = (
        stitch.E_GPa * 1e9 * stitch.linear_density_dtex * 1e-7 / (stitch.density_g_cm3 * 1e3)
    )
    assert stiffness_N == pytest.approx(66.09, rel=1e-3)
    tension_N = spec.manufacture.stitch_tension_N
    assert creep["scale"] == pytest.approx(stiffness_N / (tension_N * 10 * dt), rel=1e-9)
    assert creep["target"] == pytest.approx(1e-3)  # 1 per ms in 1/us
    assert creep["every"] % 200 == 0
    assert 50.0 <= creep["every"] * dt < 50.0 + 200 * dt
    assert deck_values(prepare(tiny_spec()))["creep"] is None


@pytest.mark.lammps
def test_relaxation_ends_at_a_creep_check_below_its_target(tmp_path):
    """With ``stitch_creep_target_per_ms`` the relaxation ends on one of its creep checks (a
    multiple of the creep window) at which the stitch creeps below the target, with the tension
    within its tolerance; /manufacture records the deck's creep and the target."""
    from ncf2lammps import run
    from ncf2lammps.numerics import prepare

    spec = tiny_spec(manufacture=CREEP)
    run(spec, tmp_path / "run", scenes=["manufacture"])
    attrs = read_results(tmp_path / "run" / "results.h5")["manufacture"]["attrs"]
    assert attrs["stitch_creep_target_per_ms"] == 1.0
    assert 0.0 <= attrs["stitch_creep_per_ms"] < 1.0
    assert abs(attrs["stitch_tension_error"]) < spec.manufacture.tension_tolerance
    assert attrs["steps"] % deck_values(prepare(spec))["creep"]["every"] == 0


def test_needle_axes_include_periodic_images():
    from ncf2lammps import build_model

    # A 2.6 mm needle at x = 1.4 mm reaches past x = 0 (radius 1.3 mm + bead 0.2 mm): its image
    # at x + 11.2 mm must push the beads near the far edge too.
    model = build_model(case_spec("hpt310-coarse").replace(stitch={"needle_diameter_mm": 2.6}))
    axes = needle_axes(model)
    assert len(axes) > len(model.needle_points)
    assert np.any(axes[:, 0] > model.box.lengths[0])


@pytest.mark.lammps
def test_needle_walls_on_their_reach_push_as_on_every_fibre_bead(tmp_path):
    """The needle walls act on a dynamic group of the fibre beads within reach of a needle
    (rebuilt every ``needle_reach.every`` steps). Law: a wall of range r_c only pushes beads
    within r_c of its surface, so the needle and insertion stages give bit-identical positions
    (tolerance 0) whether the walls act on that group or on every fibre bead; the group at the
    end of the stages is a nonempty strict subset of the fibre beads, and the needles moved some
    bead by more than a quarter diameter. Fast needles and short damping keep the run short."""
    spec = tiny_spec(manufacture={"needle_speed_m_s": 50.0, "damping_time_us": 5.0})
    folder = build(spec, tmp_path / "run").directory
    deck = (folder / "decks" / "in.manufacture.lmp").read_text().split("# stage: pretension")[0]
    assert " needle_near wall/region " in deck
    ends = {
        "reach": 'print "$(count(needle_near)) $(count(fibre))" file counts.txt\n',
        "every": "",
    }
    for name, end in ends.items():
        text = (
            deck
            if name == "reach"
            else deck.replace(" needle_near wall/region ", " fibre wall/region ")
        )
        (folder / f"in.{name}.lmp").write_text(f"{text}{end}write_data {name}.data nocoeff\n")
        run_lammps_file(folder, f"in.{name}.lmp")
    reach, every = (read_data(folder / f"{name}.data") for name in ends)
    np.testing.assert_array_equal(reach.positions, every.positions)
    start = read_data(folder / "model.data").positions
    moved = np.linalg.norm(reach.box.minimum_image(reach.positions - start), axis=1)
    assert 0.25 * spec.discretisation.chain_diameter_um < moved.max()
    near, fibre = map(float, (folder / "counts.txt").read_text().split())
    assert 0 < near < fibre


@pytest.mark.lammps
def test_needles_part_a_dense_row_of_bundle_chains(tmp_path):
    """Under the bundle law the needle walls take the rigid ``contact.normal_stiffness_N_m``,
    not the bundle contact's (its onset stiffness, 42 N/m on this cell: there a bead of the
    tiny cell's rows, 37 chains of contact diameter 251 um across 11.2 mm, crossed a needle's
    wall at step 2,488 and LAMMPS stopped, at every needle speed and time step tried). Law: the
    harmonic walls keep the fibre beads out of the needles, so after the needle stage no fibre
    bead centre lies closer to a needle axis (images included) than the needle radius, the
    manufacture's channel check (tolerance 0). Fast needles and short damping keep the run
    short: the old walls fail at these too."""
    spec = tiny_spec(
        contact={"normal_model": "bundle"},
        manufacture={"needle_speed_m_s": 50.0, "damping_time_us": 5.0},
    )
    built = build(spec, tmp_path / "run")
    folder, model = built.directory, built.model
    deck = (folder / "decks" / "in.manufacture.lmp").read_text().split("# stage: insertion")[0]
    rigid = units.to_micro(spec.contact.normal_stiffness_N_m, "N_m")
    epsilon = float(deck.split(" wall/region needle1 harmonic ")[1].split()[0])
    assert epsilon == pytest.approx(rigid / 2, rel=1e-12)
    (folder / "in.needles.lmp").write_text(f"{deck}write_data needles.data nocoeff\n")
    run_lammps_file(folder, "in.needles.lmp")
    fibre = read_data(folder / "needles.data").positions[model.role_mask("fibre")]
    nearest = min_xy_distance(fibre, needle_axes(model), model.box.lengths)
    assert nearest.min() >= model.needle_diameter / 2


def _needle_stage_z(folder, monkeypatch) -> tuple[np.ndarray, np.ndarray]:
    """(N,) bead z (um) after the manufacture deck's displace_atoms and at the end of its needle
    stage, run in ``folder`` by one LAMMPS process."""
    from ncf2lammps.engine import Engine

    monkeypatch.chdir(folder)
    lines = deck_commands(folder / "decks" / "in.manufacture.lmp")
    moved = next(i for i, line in enumerate(lines) if line.startswith("displace_atoms"))
    needles = next(i for i, line in enumerate(lines) if line.startswith("run ") and i > moved)
    with Engine(log=None) as engine:
        for line in lines[: moved + 1]:
            engine.command(line)
        start = engine.gather("x", 3)[:, 2]
        for line in lines[moved + 1 : needles + 1]:
            engine.command(line)
        return start, engine.gather("x", 3)[:, 2]


@pytest.mark.lammps
def test_the_plane_hold_keeps_the_fibres_flat_while_the_needles_part_them(tmp_path, monkeypatch):
    """A replica (perturbed out of plane) of the tiny cell: without manufacture.needle_plane_hold
    the fibre beads move in z during the needle stage; with it no fibre bead's z changes (fix
    setforce zeroes the z force, the beads start at rest), so the stage stays in the plane of
    each layer as the unperturbed regular mat's does."""
    moved = {}
    for hold in (False, True):
        spec = tiny_spec(numerics={"perturbation_seed": 3}, manufacture={"needle_plane_hold": hold})
        folder = build(spec, tmp_path / f"hold-{hold}").directory
        start, end = _needle_stage_z(folder, monkeypatch)
        types = read_data(folder / "model.data").type_id
        fibre = types < types.max()
        moved[hold] = np.abs(end - start)[fibre].max()
    assert moved[False] > 0.0
    assert moved[True] == 0.0
