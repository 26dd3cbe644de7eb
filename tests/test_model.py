"""Invariants of the generated mat and stitch (docs/design.md §5)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import assert_model_invariants, tiny_spec
from hypothesis import HealthCheck, given, settings
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
