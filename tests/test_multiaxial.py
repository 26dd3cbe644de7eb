"""Plies at any angle: lattice directions, closure, volume, overlaps; a generated +-45 mat in
the picture frame."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import assert_model_invariants, bond_lengths, frictionless_mat_spec, tiny_spec
from hypothesis import given, settings
from hypothesis import strategies as st

from ncf2lammps import build_model, run
from ncf2lammps.geometry.direction import (
    DIAMETER_TOLERANCE,
    lattice_direction,
    ply_direction,
    spec_ply_direction,
)
from ncf2lammps.geometry.size import model_size
from ncf2lammps.io.lammpslog import read_ave_time
from ncf2lammps.io.results import read_results
from ncf2lammps.scenes.shear import DEFORM_EVERY
from ncf2lammps.spec import SpecError

CELL = (11200.0, 5080.0)  # the tiny tricot-chain cell, um


def _plies(*angles, weight=150.0):
    return [{"angle_deg": a, "areal_weight_g_m2": weight} for a in angles]


def test_paper_plies_are_the_axes_exactly():
    """0 and 90 deg are (1, 0) and (0, 1) with exact unit vectors: the paper's plies."""
    zero, ninety = (ply_direction(a, CELL, 0.25, 0.01, 150.0, "f") for a in (0.0, 90.0))
    assert zero.lattice == (1, 0) and ninety.lattice == (0, 1)
    assert zero.along.tolist() == [1.0, 0.0] and zero.across.tolist() == [0.0, 1.0]
    assert ninety.along.tolist() == [0.0, 1.0] and ninety.across.tolist() == [1.0, 0.0]
    assert (zero.chain_length, zero.period) == CELL


@given(st.floats(-89.9, 90.0), st.floats(0.05, 2.0))
@settings(max_examples=60, deadline=None)
def test_realised_angle_within_tolerance_and_chain_closes(angle, tolerance):
    """The chosen lattice vector (a Lx, b Ly) is a cell translation (the chain closes), its
    angle is within the tolerance of the request (modulo 180 deg), and its images tile the
    cell: strip width x chain length = cell area (1e-12)."""
    try:
        direction = ply_direction(angle, CELL, tolerance, 2e-3, 150.0, "ply[0].angle_deg")
    except SpecError as err:
        assert "nearest achievable angles" in str(err)
        return
    a, b = direction.lattice
    assert math.gcd(a, b) == 1
    closing = direction.along * direction.chain_length
    np.testing.assert_allclose(closing, [a * CELL[0], b * CELL[1]], rtol=1e-12, atol=1e-9)
    miss = abs((direction.angle_deg - angle + 90.0) % 180.0 - 90.0)
    assert miss <= tolerance + 1e-9
    assert direction.period * direction.chain_length == pytest.approx(CELL[0] * CELL[1], 1e-12)
    assert abs(direction.along @ direction.across) < 1e-12


def test_shortest_direction_is_taken():
    """Of the lattice vectors within tolerance the shortest (widest strip) is chosen: at 45 deg
    on a square cell that is the diagonal (1, 1)."""
    direction = ply_direction(45.0, (5080.0, 5080.0), 1.0, 0.01, 150.0, "f")
    assert direction.lattice == (1, 1) and direction.angle_deg == pytest.approx(45.0, abs=1e-12)


def test_unreachable_angle_names_the_nearest():
    with pytest.raises(SpecError, match=r"ply\[1\].angle_deg = 45.*nearest achievable angles"):
        ply_direction(45.0, CELL, 0.25, 1e-3, 2000.0, "ply[1].angle_deg")


@pytest.mark.parametrize(
    "angles",
    [(45.0, -45.0), (0.0, 45.0, 90.0, -45.0), (30.0, -30.0), (-60.0, 60.0)],
    ids=["pm45", "quadriaxial", "pm30", "mp60"],
)
def test_multiaxial_models_keep_invariants(angles):
    """Areal weight and Vf exact, every bond at rest (the boundary bond of each long chain
    included, 1e-9), closed chains, no overlaps at generation; the realised angles are those of
    the direction search, and the bead bound holds."""
    spec = tiny_spec(ply=_plies(*angles), discretisation={"chain_diameter_um": 150.0})
    model = build_model(spec)
    assert_model_invariants(spec, model)
    fibres = [t for t in model.atom_types if t.role == "fibre"]
    for index, kind in enumerate(fibres):
        direction = spec_ply_direction(spec, index)
        assert kind.lattice == direction.lattice and kind.angle_deg == direction.angle_deg
        assert abs(kind.angle_deg - angles[index]) <= spec.mat.angle_tolerance_deg
    assert model_size(spec).beads >= model.n_atoms


def test_off_axis_chain_follows_its_direction():
    """Every bond of a straight +45 deg ply is parallel to the ply's direction (1e-9)."""
    spec = tiny_spec(ply=_plies(45.0, -45.0), discretisation={"chain_diameter_um": 150.0})
    model = build_model(spec)
    kind = model.atom_types[0]
    t = lattice_direction(kind.lattice, tuple(model.box.lengths[:2])).along
    in_ply = model.type_id[model.bonds[:, 0]] == 0
    ends = model.positions[model.bonds[in_ply]]
    step = ends[:, 1, :2] - ends[:, 0, :2]
    step -= np.rint(step / model.box.lengths[:2]) * model.box.lengths[:2]
    cross = step[:, 0] * t[1] - step[:, 1] * t[0]
    assert np.abs(cross).max() < 1e-9 * np.abs(step).max()
    assert np.all(step @ t > 0)
    np.testing.assert_allclose(bond_lengths(model)[in_ply], model.bond_types[0].r0, rtol=1e-9)


@pytest.mark.parametrize("plane", ["in-plane", "out-of-plane"])
def test_wavy_and_bent_plies_at_any_angle(plane):
    """Waviness (both planes) and bending at +-45 deg keep the generation invariants."""
    spec = tiny_spec(
        ply=_plies(45.0, -45.0),
        discretisation={"chain_diameter_um": 150.0, "bending": "harmonic"},
        mat={"waviness_amplitude_um": 30.0, "waviness_plane": plane, "initial_fvf": 0.2},
    )
    model = build_model(spec)
    assert_model_invariants(spec, model)
    assert len(model.angles) == model.role_mask("fibre").sum()


def test_bundle_law_at_any_angle():
    """Bundle chains (fill below 1) at +-45 deg keep the generation invariants."""
    spec = tiny_spec(
        ply=_plies(45.0, -45.0),
        discretisation={"chain_diameter_um": 150.0},
        contact={"normal_model": "bundle", "normal_stiffness_N_m": 1e5},
        mat={"initial_fvf": 0.2},
    )
    model = build_model(spec)
    assert_model_invariants(spec, model)
    assert model.atom_types[0].fill < 1.0


def test_random_bed_at_any_angle():
    """A random +-45 bed keeps the fibre volume (1e-9) and puts each chain inside its slab."""
    spec = tiny_spec(
        ply=_plies(45.0, -45.0),
        discretisation={"chain_diameter_um": 150.0},
        mat={"arrangement": "random", "initial_fvf": 0.25},
    )
    model = build_model(spec)
    assert model.areal_weight("fibre") == pytest.approx(300.0, rel=1e-9)


def test_diameter_stays_within_tolerance_of_nominal():
    """A strip never forces the chain diameter more than DIAMETER_TOLERANCE off the nominal."""
    spec = tiny_spec(
        ply=_plies(45.0, -45.0, 0.0, 30.0), discretisation={"chain_diameter_um": 150.0}
    )
    model = build_model(spec)
    for kind in model.atom_types[:4]:
        assert abs(kind.diameter / 150.0 - 1.0) <= DIAMETER_TOLERANCE + 1e-12


@pytest.mark.parametrize(
    ("angle", "message"),
    [(-90.0, r"ply\[0\].angle_deg"), (90.5, r"ply\[0\].angle_deg")],
)
def test_angle_outside_range_is_refused(angle, message):
    with pytest.raises(SpecError, match=message):
        tiny_spec(ply=_plies(angle, 0.0))


def test_tolerance_key_is_validated():
    with pytest.raises(SpecError, match=r"mat.angle_tolerance_deg"):
        tiny_spec(mat={"angle_tolerance_deg": 0.0})


@pytest.mark.lammps
def test_generated_pm45_mat_sheared_both_ways_keeps_zero_force(tmp_path):
    """End to end from the generator: a +-45 mat of pretensioned frictionless straight chains
    (no stitch) sheared by the stretch recipe in both senses keeps every chain length, so
    |F_N| < 1 % of the pretension N0 = 22 N/m (the frictionless identity); the box follows
    ``lx = Lx cos(phi) / cos(phi0)``, ``ly = Ly sin(phi) / sin(phi0)``, ``phi = phi0 -+ g/2``,
    to 1e-3 of a box update."""
    spec = frictionless_mat_spec(
        30.0, ply=_plies(45.0, -45.0), discretisation={"chain_diameter_um": 150.0}
    )
    results = read_results(run(spec, tmp_path / "run", scenes=["shear", "shear_negative"]))
    phi0 = math.radians(45.0)
    for group, sign in (("shear", 1.0), ("shear_negative", -1.0)):
        attrs = results[group]["attrs"]
        assert attrs["recipe"] == "stretch"
        assert np.max(np.abs(results[group]["force_N_per_m"])) < 0.01 * 22.0
        box = read_ave_time(tmp_path / "run" / f"{group}.box.txt")
        phi = phi0 - sign * box["v_g"] / 2
        update = (
            DEFORM_EVERY * np.abs(np.diff(box["v_box_lx"])).max() / np.diff(box["TimeStep"]).max()
        )
        assert np.abs(box["v_box_lx"] - 2000.0 * np.cos(phi) / np.cos(phi0)).max() < 1e-3 * update
        assert np.abs(box["v_box_ly"] - 2000.0 * np.sin(phi) / np.sin(phi0)).max() < 1e-3 * update
