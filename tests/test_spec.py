"""Spec validation: one-line SpecError naming the field and the range, never another exception."""

from __future__ import annotations

import pytest
from conftest import CASES, ROOT, case_spec, tiny_spec
from hypothesis import example, given, settings
from hypothesis import strategies as st

from ncf2lammps import build_model, load_spec, spec_from_dict
from ncf2lammps.io.spectoml import dumps_spec
from ncf2lammps.spec import SpecError, parse_lapping


@pytest.mark.parametrize("case", CASES)
def test_cases_load_and_resolve_round_trip(case, tmp_path):
    spec = case_spec(case)
    path = tmp_path / "resolved.toml"
    path.write_text(dumps_spec(spec))
    assert load_spec(path) == spec


@pytest.mark.parametrize(
    ("tables", "field", "words"),
    [
        (
            {"discretisation": {"chain_diameter_um": -5.0}},
            "discretisation.chain_diameter_um",
            "[1, 5000] um",
        ),
        ({"contact": {"friction": 3.0}}, "contact.friction", "[0, 2]"),
        ({"contact": {"normal_model": "lj"}}, "contact.normal_model", "hooke, hertz"),
        ({"mat": {"initial_fvf": "0.3"}}, "mat.initial_fvf", "number"),
        ({"mat": {"initial_fvf": True}}, "mat.initial_fvf", "number"),
        ({"mat": {"fvf": 0.3}}, "mat.fvf", "unknown key"),
        ({"stitch": {"pattern": "custom"}}, "stitch.lapping", "must be given"),
        ({"stitch": {"pattern": "custom", "lapping": "1-3/2-1"}}, "stitch.lapping", "one needle"),
        ({"ply": [{"angle_deg": -90.0}]}, "ply[0].angle_deg", "(-90, 90]"),
        ({"ply": []}, "ply", "1 to 8"),
        ({"numerics": {"thermo_every": 10.5}}, "numerics.thermo_every", "whole number"),
        ({"cell": {"length_mm": 5.0}}, "cell.length_mm", "multiple of the repeat"),
        ({"stitch": {"needle_diameter_mm": 4.0}}, "stitch.needle_diameter_mm", "hole spacing"),
        ({"compaction": {"max_pressure_kPa": 10.0}}, "compaction.max_pressure_kPa", "[20, 1e+07]"),
        ({"compaction": {"end": "gap"}}, "compaction.end", "max_pressure, final_fvf"),
        ({"compaction": {"loading": "fast"}}, "compaction.loading", "adaptive, constant"),
        ({"shear": {"loading": 1}}, "shear.loading", "must be a string: one of adaptive, constant"),
        ({"mat": {"seed": 2**31}}, "mat.seed", "allowed [0, 2147483647]"),
        (  # the shear loads at a constant rate by default: no brake to set
            {"shear": {"kinetic_stress_target": 0.01}},
            "shear.kinetic_stress_target",
            "only read with shear.loading = 'adaptive'",
        ),
        (
            {"compaction": {"loading": "constant", "max_rate_factor": 4.0}},
            "compaction.max_rate_factor",
            "only read with compaction.loading = 'adaptive'",
        ),
        ({"compaction": {"max_rate_factor": 0.5}}, "compaction.max_rate_factor", "[1, 10000]"),
        ({"shear": {"max_rate_factor": -2.0}}, "shear.max_rate_factor", "[1, 10000]"),
        (
            {"compaction": {"kinetic_ratio_target": 0.01}},
            "compaction.kinetic_ratio_target",
            "unknown key",
        ),
        (  # fibre Vf of chains of internal Vf 0.6 is at most 0.6 pi / (2 sqrt 3) = 0.544
            {"discretisation": {"chain_diameter_um": 250.0, "chain_internal_fvf": 0.6}},
            "compaction.final_fvf",
            "internal Vf 0.6 (discretisation.chain_internal_fvf) reach at most 0.544",
        ),
    ],
)
def test_bad_values_name_field_and_range(tables, field, words):
    with pytest.raises(SpecError) as info:
        build_model(tiny_spec(**tables))
    assert info.value.field == field
    message = str(info.value)
    assert "\n" not in message and words in message and field in message


def test_unknown_table_and_bad_toml(tmp_path):
    with pytest.raises(SpecError, match="unknown table"):
        spec_from_dict({"ply": [{}], "plates": {}})
    bad = tmp_path / "bad.toml"
    bad.write_text("[mat\ninitial_fvf = ")
    with pytest.raises(SpecError, match="not valid TOML"):
        load_spec(bad)
    with pytest.raises(SpecError, match="cannot be read"):
        load_spec(tmp_path / "missing.toml")


def test_lapping_notation():
    assert parse_lapping("1-0/0-1/1-2/2-1") == ((1, 0), (0, 1), (1, 2), (2, 1))
    assert case_spec("hpt310").stitch.notation == "1-0/0-1/1-2/2-1"
    assert case_spec("hpt310").cell_mm == pytest.approx((11.2, 5.08))


def test_replace_merges_and_validates():
    spec = case_spec("hpt310-coarse")
    finer = spec.replace(discretisation={"chain_diameter_um": 150.0})
    assert finer.discretisation.chain_diameter_um == 150.0
    assert finer.discretisation.bead_spacing_ratio == spec.discretisation.bead_spacing_ratio
    with pytest.raises(SpecError):
        spec.replace(mat={"initial_fvf": 2.0})


json_values = st.recursive(
    st.none() | st.booleans() | st.floats(allow_nan=True) | st.integers() | st.text(max_size=8),
    lambda children: (
        st.lists(children, max_size=3) | st.dictionaries(st.text(max_size=8), children, max_size=3)
    ),
    max_leaves=8,
)
table_names = st.sampled_from(
    [
        "fabric",
        "ply",
        "stitch",
        "cell",
        "discretisation",
        "mat",
        "contact",
        "numerics",
        "shear",
        "x",
    ]
)


@settings(max_examples=300, deadline=None)
@given(st.dictionaries(table_names, json_values, max_size=4))
@example({"ply": [{"\n": None}]})  # an unknown key with a line break (found by hypothesis)
@example({"ply": [{"a\u2028b": 1}]})
def test_random_invalid_specs_only_raise_spec_error(data):
    try:
        spec = spec_from_dict(data)
    except SpecError as err:
        assert len(str(err).splitlines()) == 1  # one line, whatever the keys hold
        return
    build_model(spec) if spec.cell_mm[0] < 100 else None


@settings(max_examples=200, deadline=None)
@given(
    st.sampled_from(["discretisation", "mat", "contact", "numerics", "stitch", "manufacture"]),
    st.sampled_from(
        [
            "chain_diameter_um",
            "initial_fvf",
            "friction",
            "dt_fraction",
            "gauge_mm",
            "stitch_tension_N",
        ]
    ),
    st.one_of(
        st.floats(allow_nan=True, allow_infinity=True),
        st.integers(-(10**6), 10**6),
        st.text(max_size=5),
    ),
)
def test_random_field_values_only_raise_spec_error(table, key, value):
    try:
        spec = tiny_spec(**{table: {key: value}})
        build_model(spec)
    except SpecError as err:
        assert "\n" not in str(err)


def test_runs_folder_has_the_three_cases():
    for case in CASES:
        assert (ROOT / "runs" / case / "spec.toml").is_file()
