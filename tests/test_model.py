"""Invariants of the generated mat and stitch (docs/design.md §5)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import assert_model_invariants, tiny_spec
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from ncf2lammps import build_model
from ncf2lammps.spec import SpecError


def assert_invariants(spec, model):
    """The shared generation invariants, and mass per length equal to the cylinder's
    (rho pi d^2 / 4 per um of straight chain, 1e-9 relative)."""
    assert_model_invariants(spec, model)
    for index, t in enumerate(model.atom_types):
        if t.role != "fibre":
            continue
        in_type = model.type_id == index
        chain_length = model.count(t.name)[0] * (
            model.box.lengths[0] if t.name.endswith("_0deg") else model.box.lengths[1]
        )
        assert model.mass[in_type].sum() == pytest.approx(
            t.density * np.pi * t.diameter**2 / 4 * chain_length, rel=1e-9
        )


def test_hpt310_paper_cell(case_models):
    spec, model = case_models["hpt310"]
    np.testing.assert_allclose(model.box.lengths[:2], [11200.0, 5080.0])
    assert model.areal_weight("fibre") == pytest.approx(300.0, rel=0.01)
    assert model.mat_thickness == pytest.approx(300.0 / (0.3 * 1.8), rel=1e-9)  # 555.6 um
    assert len(model.needle_points) == 4
    assert_invariants(spec, model)


@pytest.mark.parametrize("case", ["hpt310-coarse", "mat-only"])
def test_cases_invariants(case_models, case):
    spec, model = case_models[case]
    assert_invariants(spec, model)


def test_stitch_passes_through_every_needle_point(case_models):
    """Each needle hole holds one vertical leg of the yarn spanning the whole mat thickness."""
    _, model = case_models["hpt310"]
    stitch = model.role_mask("stitch")
    xy = model.positions[stitch, :2]
    z = model.positions[stitch, 2]
    for hole in model.needle_points:
        delta = xy - hole
        delta -= np.rint(delta / model.box.lengths[:2]) * model.box.lengths[:2]
        inside = np.linalg.norm(delta, axis=1) < model.needle_diameter / 2
        assert z[inside].min() < model.faces_z[0] + 1e-6
        assert z[inside].max() > model.faces_z[1] - 1e-6
        middle = inside & (np.abs(z - model.mat_thickness / 2) < model.mat_thickness / 4)
        np.testing.assert_allclose(delta[middle], 0.0, atol=1e-9)  # one leg, on the hole axis


@pytest.mark.parametrize(
    ("pattern", "needles_per_repeat"), [("chain", 2), ("tricot", 2), ("tricot-chain", 4)]
)
def test_patterns_have_one_hole_per_course(pattern, needles_per_repeat):
    model = build_model(tiny_spec(stitch={"pattern": pattern}))
    assert len(model.needle_points) == needles_per_repeat
    assert model.box.lengths[0] == pytest.approx(needles_per_repeat * 2800.0)


def test_tricot_chain_loops_along_wales_underlaps_zigzag(case_models):
    """Tricot-chain (needles A A B B): loop-face segments run along a wale (constant y, mod the
    gauge); underlap-face segments cross one gauge diagonally (the zigzag)."""
    _, model = case_models["hpt310"]
    stitch = model.role_mask("stitch")
    position = model.positions[stitch]
    gauge = model.box.lengths[1]
    top = np.isclose(position[:, 2], model.faces_z[1])
    bottom = np.isclose(position[:, 2], model.faces_z[0])
    np.testing.assert_allclose(position[top, 1] % gauge, gauge / 2)
    assert np.ptp(position[bottom, 1]) > 0.9 * gauge
    assert top.sum() > 0 and bottom.sum() > top.sum()


def test_model_arrays_are_read_only(case_models):
    _, model = case_models["mat-only"]
    with pytest.raises(ValueError):
        model.positions[0, 0] = 1.0


def test_too_dense_mat_is_a_spec_error():
    with pytest.raises(SpecError, match=r"mat.initial_fvf"):
        build_model(
            tiny_spec(mat={"initial_fvf": 0.78}, discretisation={"chain_diameter_um": 100.0})
        )


valid_specs = st.builds(
    lambda d, ratio, fvf, aw0, aw1, pattern, stitched: tiny_spec(
        discretisation={"chain_diameter_um": d, "bead_spacing_ratio": ratio},
        mat={"initial_fvf": fvf},
        ply=[
            {"angle_deg": 90.0, "areal_weight_g_m2": aw0},
            {"angle_deg": 0.0, "areal_weight_g_m2": aw1},
        ],
        stitch={"pattern": pattern, "needle_diameter_mm": 1.2} if stitched else None,
        cell=None if stitched else {"length_mm": 3.0, "width_mm": 2.5},
    ),
    d=st.floats(100.0, 400.0),
    ratio=st.floats(0.25, 1.0),
    fvf=st.floats(0.1, 0.5),
    aw0=st.floats(50.0, 400.0),
    aw1=st.floats(50.0, 400.0),
    pattern=st.sampled_from(["chain", "tricot", "tricot-chain"]),
    stitched=st.booleans(),
)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(valid_specs)
def test_random_valid_specs_keep_invariants(spec):
    try:
        model = build_model(spec)
    except SpecError as err:  # a dense mat or a needle that cannot fit is refused, by field
        assert err.field in (
            "mat.initial_fvf",
            "stitch.needle_diameter_mm",
            "discretisation.chain_diameter_um",
        )
        return
    assert_invariants(spec, model)


@settings(max_examples=30, deadline=None)
@given(
    st.lists(st.floats(-400.0, 400.0), min_size=6, max_size=15).filter(lambda v: len(v) % 3 == 0),
    st.floats(3.0, 60.0),
    st.integers(1, 3),
)
def test_open_polyline_keeps_its_vertices_and_even_bonds(coords, spacing, min_bonds):
    """Every vertex is a bead, the ends are exact, each segment's bonds are equal and sum to the
    segment (1e-9 um), and no segment has fewer than ``min_bonds`` bonds."""
    from ncf2lammps.geometry import sample_open_polyline

    vertices = np.cumsum(np.reshape(coords, (-1, 3)), axis=0)
    assume(np.linalg.norm(np.diff(vertices, axis=0), axis=1).min() > 1.0)
    beads, lengths = sample_open_polyline(vertices, spacing, min_bonds)
    steps = np.linalg.norm(np.diff(beads, axis=0), axis=1)
    np.testing.assert_allclose(steps, lengths, atol=1e-9)
    np.testing.assert_array_equal(beads[[0, -1]], vertices[[0, -1]])
    at_vertex = [np.linalg.norm(beads - v, axis=1).min() for v in vertices]
    assert max(at_vertex) < 1e-9
    segments = np.linalg.norm(np.diff(vertices, axis=0), axis=1)
    assert len(lengths) >= min_bonds * len(segments)
    assert abs(lengths.sum() - segments.sum()) < 1e-9 * max(1.0, segments.sum())


def test_minimum_image_is_the_nearest_periodic_copy():
    """In a tilted box periodic in x and y, the minimum image of a difference differs from it by
    whole in-plane edge vectors, has in-plane fractional coordinates in [-1/2, 1/2], and for a
    difference shorter than half the cell's narrowest height is its nearest copy (brute force
    over -5..5 images; 1e-9 um)."""
    from ncf2lammps.model.core import Box

    box = Box(np.zeros(3), np.array([50.0, 80.0, 30.0]), np.array([25.0, 4.0, 2.0]))
    rng = np.random.default_rng(7)
    delta = rng.uniform(-150.0, 150.0, size=(400, 3))
    image = box.minimum_image(delta)
    shift = np.linalg.solve(box.matrix, (image - delta).T).T
    np.testing.assert_allclose(shift, np.rint(shift), atol=1e-9)
    np.testing.assert_allclose(shift[:, 2], 0.0, atol=1e-9)
    assert np.abs(box.fractional(image + box.lo)[:, :2]).max() <= 0.5 + 1e-12
    height = min(box.lengths[1], box.lengths[0] * box.lengths[1] / np.hypot(*box.matrix[:2, 1]))
    short = delta[np.linalg.norm(image[:, :2], axis=1) < 0.5 * height]
    shifts = np.array([[i, j, 0] for i in range(-5, 6) for j in range(-5, 6)]) @ box.matrix.T
    copies = short[:, None, :] + shifts[None, :, :]
    nearest = copies[np.arange(len(short)), np.linalg.norm(copies, axis=2).argmin(axis=1)]
    assert len(short) > 20
    np.testing.assert_allclose(box.minimum_image(short), nearest, atol=1e-9)
