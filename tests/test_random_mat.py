"""The random bed (mat.arrangement = "random"): generation, refusals and the push-off stage."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest
from conftest import bond_lengths, tiny_spec

from ncf2lammps import build, build_model, units
from ncf2lammps.engine import Engine, run_deck
from ncf2lammps.numerics import prepare
from ncf2lammps.scenes import SCENES, render_deck
from ncf2lammps.spec import SpecError

#: A coarse stitched cell with a random bed (chains 150 um, some 7 600 beads).
COARSE = {"discretisation": {"chain_diameter_um": 150.0}}


def random_spec(**mat):
    return tiny_spec(mat={"arrangement": "random", **mat}, **COARSE)


def _ply_slabs(spec) -> np.ndarray:
    """(P, 2) bottom and top of each ply's slab in the homogeneous mat, A / (Vf rho) thick (um)."""
    thickness = [p.areal_weight_g_m2 / p.density_g_cm3 for p in spec.plies]  # (g/m2)/(g/cm3) = um
    tops = np.cumsum(thickness) / spec.mat.initial_fvf
    return np.column_stack([np.concatenate([[0.0], tops[:-1]]), tops])


def assert_random_bed(spec, model):
    """Fibre areal weight and mat Vf equal the spec's (1e-9 relative), every bond at its rest
    length (1e-9, the closing bond of each chain included), every chain inside its ply's slab
    (bead surfaces within the slab faces, 1e-9 um)."""
    expected = sum(p.areal_weight_g_m2 for p in spec.plies)
    assert model.areal_weight("fibre") == pytest.approx(expected, rel=1e-9)
    assert model.fvf(model.mat_thickness) == pytest.approx(spec.mat.initial_fvf, rel=1e-9)
    r0 = np.array([t.r0 for t in model.bond_types])[model.bond_type]
    np.testing.assert_allclose(bond_lengths(model), r0, rtol=1e-9)
    slabs = _ply_slabs(spec)
    for index, (bottom, top) in enumerate(slabs):
        beads = model.type_id == index
        radius = model.diameter[beads] / 2
        assert np.all(model.positions[beads, 2] - radius >= bottom - 1e-9)
        assert np.all(model.positions[beads, 2] + radius <= top + 1e-9)


def test_random_bed_conserves_fibre_and_follows_its_seed():
    spec = random_spec()
    model = build_model(spec)
    assert_random_bed(spec, model)
    rows = build_model(tiny_spec(**COARSE))
    fibre = model.role_mask("fibre")
    assert fibre.sum() == rows.role_mask("fibre").sum()
    assert model.fibre_volume == pytest.approx(rows.fibre_volume, rel=1e-12)
    again = build_model(random_spec())
    other = build_model(random_spec(seed=2))
    assert np.array_equal(model.positions, again.positions)
    assert not np.allclose(model.positions[fibre], other.positions[fibre])
    assert not np.allclose(model.positions[fibre], rows.positions[rows.role_mask("fibre")])


def test_diameter_spread_keeps_vf_and_masses_follow_cross_sections():
    """The chains' fibre cross-sections add up to the ply's (Vf and areal weight exact, 1e-9);
    each bead's mass is rho x its chain's fibre cross-section x its spacing; each chain's bond
    stiffness EA = E x its cross-section."""
    spec = random_spec(diameter_spread=0.2, seed=4)
    model = build_model(spec)
    assert_random_bed(spec, model)
    fibre = model.role_mask("fibre")
    spread = np.std(model.diameter[fibre]) / np.mean(model.diameter[fibre])
    assert 0.1 < spread < 0.25
    ply = spec.plies[0]
    rho = units.to_micro(ply.density_g_cm3, "g_cm3")
    modulus = units.to_micro(ply.E_GPa, "GPa")
    beads = np.flatnonzero(model.type_id == 0)
    area = np.pi * model.diameter[beads] ** 2 / 4
    spacing = float(model.bond_types[model.bond_type[0]].r0)
    np.testing.assert_allclose(model.mass[beads], rho * area * spacing, rtol=1e-9)
    first_bond = model.bond_type[np.searchsorted(model.bonds[:, 0], beads[0])]
    assert model.bond_types[first_bond].axial_stiffness == pytest.approx(modulus * area[0])


@pytest.mark.parametrize("plane", ["in-plane", "out-of-plane"])
def test_wavy_random_chains_close_and_stay_in_their_slab(plane):
    spec = random_spec(waviness_amplitude_um=20.0, waviness_plane=plane, waviness_waves_per_cell=2)
    assert_random_bed(spec, build_model(spec))


@pytest.mark.parametrize(
    ("mat", "tables", "field", "words"),
    [
        ({"arrangement": "rows", "diameter_spread": 0.1}, {}, "mat.diameter_spread", "'random'"),
        ({"max_pushoff_steps": 10}, {}, "mat.max_pushoff_steps", "only read"),
        ({"arrangement": "random", "diameter_spread": 0.5}, {}, "mat.diameter_spread", "[0, 0.3]"),
        (
            {"arrangement": "random", "pushoff_overlap_tolerance": 0.0},
            {},
            "mat.pushoff_overlap_tolerance",
            "[0.001, 0.5] d",
        ),
        ({"arrangement": "lattice"}, {}, "mat.arrangement", "rows, random"),
        (  # random discs jam at area fraction 0.547: chains of internal Vf 0.8 at bed Vf 0.44
            {"arrangement": "random", "initial_fvf": 0.5},
            {"discretisation": {"chain_diameter_um": 100.0, "chain_internal_fvf": 0.8}},
            "mat.initial_fvf",
            "allowed [0.01, 0.438]",
        ),
        ({"arrangement": "random"}, {"stitch": None}, "mat.arrangement", "[stitch]"),
        (
            {"arrangement": "random", "diameter_spread": 0.3},
            {"discretisation": {"chain_diameter_um": 250.0}},
            "mat.diameter_spread",
            "does not fit",
        ),
    ],
)
def test_random_bed_refusals_name_field_and_remedy(mat, tables, field, words):
    data = {"cell": {"length_mm": 11.2, "width_mm": 5.08}} if "stitch" in tables else {}
    with pytest.raises(SpecError) as info:
        build_model(tiny_spec(mat=mat, **{**COARSE, **data, **tables}))
    assert info.value.field == field
    message = str(info.value)
    assert "\n" not in message and words in message and field in message


def test_rows_deck_has_no_pushoff_and_random_deck_starts_with_it():
    rows = render_deck(prepare(tiny_spec(**COARSE)), "manufacture").text
    deck = render_deck(prepare(random_spec()), "manufacture").text
    assert "push-off" not in rows and "nve/limit" not in rows
    stages = [line for line in deck.splitlines() if line.startswith("# stage:")]
    assert stages[0] == "# stage: push-off" and stages[1] == "# stage: needles"
    pushoff = deck.split("# stage: push-off")[1].split("# stage: needles")[0]
    assert "unfix           guard_overlap" in pushoff and "fix             guard_overlap" in pushoff


@pytest.mark.lammps
def test_pushoff_removes_the_overlaps_of_a_random_bed(tmp_path, monkeypatch):
    """The push-off stage alone (the manufacture deck up to the needles) leaves no two fibre
    beads of different chains overlapping by more than mat.pushoff_overlap_tolerance x the
    smallest chain diameter, measured geometrically by the needles' stage check. The bed stays
    in its generated slab, so its chains wave out of the plane and part sideways (chains waving
    in the plane of a thin slab cannot pass each other inside it)."""
    spec = random_spec(
        waviness_amplitude_um=20.0, waviness_waves_per_cell=2, waviness_plane="out-of-plane"
    )
    result = build(spec, tmp_path / "run")
    folder = result.directory
    deck = (folder / "decks" / "in.manufacture.lmp").read_text()
    head = deck.split("# stage: needles")[0] + "# stage: needles\n"
    Path(folder / "decks" / "in.pushoff.lmp").write_text(head)
    monkeypatch.chdir(folder)
    run = prepare(spec)
    checks: dict = {}
    scene = SCENES["manufacture"]
    start = time.perf_counter()
    with Engine(log="log.pushoff.lammps") as engine:
        run_deck(
            engine,
            "decks/in.pushoff.lmp",
            chunk=scene.chunk,
            on_stage=lambda stage: checks.update(scene.stage_checks(engine, run, stage)),
        )
    wall = time.perf_counter() - start
    print(f"push-off: {checks} in {wall:.1f} s")
    assert checks["pushoff_initial_max_overlap_d"] > 0.2
    assert checks["pushoff_max_overlap_d"] <= spec.mat.pushoff_overlap_tolerance
    assert 0 < checks["pushoff_steps"] <= spec.mat.max_pushoff_steps
