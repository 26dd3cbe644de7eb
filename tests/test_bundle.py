"""The bundle law: Gutowski's bed, its Hertz mapping onto chains, and the spec keys that set it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import case_spec

from ncf2lammps.geometry.bundle import (
    FIT_WINDOW_KPA,
    FibreBed,
    bundle_law,
    chain_fill,
    offset_average,
    spec_bundle_law,
)
from ncf2lammps.model import build_model
from ncf2lammps.numerics import contact_law
from ncf2lammps.spec import SpecError

BED = FibreBed(240e6, 350.0, 0.5, 0.785)


def test_bed_law_values_and_inverse():
    """P(V0) = 0, P -> infinity at Va, A_s = 3 pi E / beta^4, fvf() inverts pressure() to 1e-9."""
    assert BED.stiffness == pytest.approx(3 * math.pi * 240e6 / 350.0**4)
    assert BED.pressure(0.5) == 0.0
    assert BED.pressure(0.7849) > 1e6
    pressure = np.geomspace(0.1, 1e4, 9)
    assert BED.pressure(BED.fvf(pressure)) == pytest.approx(pressure, rel=1e-9)


def test_offset_average_starts_quadratic():
    """I(x) = 3 pi sqrt(2) / 8 x^2 for small overlaps (line contact of Hertz beads), to 0.2 %."""
    x = np.array([1e-4, 1e-3])
    assert offset_average(x) / x**2 == pytest.approx(3 * math.pi * math.sqrt(2) / 8, rel=2e-3)


def test_fit_reproduces_the_bed_law_at_its_stated_error():
    """The mapped stack pressure stays within max_error of the bed law over the window, and the
    fitted onset lies between 0.5 V0 and the bed's Vf at the window's low end."""
    law = bundle_law(BED)
    pressure = np.geomspace(*FIT_WINDOW_KPA, 50)
    pitch = law.onset_fvf / BED.fvf(pressure)
    mapped = law.stack_pressure(pitch)
    assert np.max(np.abs(mapped / pressure - 1)) <= law.max_error * 1.01
    assert 0.25 < law.onset_fvf < BED.fvf(FIT_WINDOW_KPA[0])
    assert law.stack_pressure(1 - law.overlap_at(10.0)) == pytest.approx(10.0, rel=1e-6)


def test_bundle_spec_sets_fill_and_law():
    spec = case_spec("hpt310-coarse").replace(
        contact={"normal_model": "bundle"}, mat={"initial_fvf": 0.2}
    )
    law = spec_bundle_law(spec)
    assert chain_fill(spec) == law.onset_fvf
    assert spec_bundle_law(case_spec("hpt310-coarse")) is None
    model = build_model(spec)
    contact = contact_law(spec, model)
    assert contact.model == "hertz" and contact.stitch is not None
    assert contact.stitch.model == "hooke"
    fibre = model.atom_types[0]
    assert fibre.fill == pytest.approx(law.onset_fvf)


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        (
            {"contact": {"normal_model": "bundle", "bundle_free_fvf": 0.8}},
            "contact.bundle_free_fvf",
        ),
        (
            {"contact": {"normal_model": "bundle"}, "discretisation": {"chain_internal_fvf": 0.8}},
            "discretisation.chain_internal_fvf",
        ),
        (
            {"contact": {"normal_model": "bundle", "bundle_waviness_ratio": 10.0}},
            "contact.bundle_waviness_ratio",
        ),
        ({"contact": {"normal_model": "bundle", "bundle_max_fvf": 0.95}}, "contact.bundle_max_fvf"),
    ],
)
def test_bad_bundle_values_name_their_field(changes, field):
    with pytest.raises(SpecError) as err:
        case_spec("hpt310-coarse").replace(**changes)
    assert err.value.field == field
    assert "\n" not in str(err.value)
