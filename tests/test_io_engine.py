"""Data file round trip, deck safety, and LAMMPS itself reading every case."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import CASES

from ncf2lammps import build
from ncf2lammps.engine import Engine
from ncf2lammps.io.datafile import read_data, write_data
from ncf2lammps.io.deck import DeckValueError, render


@pytest.mark.parametrize("case", CASES)
def test_data_file_round_trip_is_exact(case_models, case, tmp_path):
    _, model = case_models[case]
    data = read_data(write_data(tmp_path / "model.data", model))
    for name in ("positions", "diameter", "density", "type_id", "mol_id", "bonds", "bond_type"):
        assert np.array_equal(getattr(data, name), getattr(model, name)), name
    assert data.atom_labels == tuple(t.name for t in model.atom_types)
    np.testing.assert_array_equal(data.bond_coeffs[:, 1], [t.r0 for t in model.bond_types])
    np.testing.assert_array_equal(data.box.hi, model.box.hi)


@pytest.mark.parametrize("case", CASES)
def test_lammps_reads_model_and_agrees(case_models, case, tmp_path):
    """LAMMPS reads model.data, runs 0 steps; counts, positions and masses equal the model's
    (times the spec's mass scaling)."""
    spec, model = case_models[case]
    result = build(spec, tmp_path / "run")
    with Engine(result.directory, log="log.verify.lammps") as engine:
        engine.file("decks/in.verify.lmp")
        assert engine.natoms == model.n_atoms
        assert engine.nbonds == model.n_bonds
        np.testing.assert_allclose(engine.gather("x", 3), model.positions, rtol=0, atol=1e-9)
        np.testing.assert_allclose(
            engine.gather("rmass", 1), model.mass * spec.numerics.mass_scaling, rtol=1e-12
        )
    # LAMMPS write_data -> our reader: the same atoms and bonds come back.
    with Engine(result.directory, log=None) as engine:
        engine.file("decks/in.verify.lmp")
        engine.command("write_data lammps.data")
    back = read_data(result.directory / "lammps.data")
    assert np.array_equal(back.type_id, model.type_id)
    assert np.array_equal(back.mol_id, model.mol_id)
    np.testing.assert_allclose(back.positions, model.positions, atol=1e-9)
    order = np.lexsort(back.bonds.T[::-1])
    expected = np.lexsort(model.bonds.T[::-1])
    assert np.array_equal(back.bonds[order], model.bonds[expected])


@pytest.mark.parametrize(
    "bad", ["model.data\nshell rm -rf /", "x y", "$(v_a)", "../data", "a#b", float("nan")]
)
def test_deck_refuses_unsafe_values(bad):
    with pytest.raises(DeckValueError):
        render("verify.lmp.j2", data_file=bad)


def test_deck_fails_loudly_on_missing_value():
    import jinja2

    with pytest.raises(jinja2.UndefinedError):
        render("verify.lmp.j2", version="x", scene="verify", data_file="model.data")
