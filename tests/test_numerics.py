"""Time-step limits and the numerical scalings (mass, fibre stiffness, stitch mass) reach LAMMPS."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import deck_commands, tiny_spec

from ncf2lammps import build_model
from ncf2lammps.io.datafile import read_data
from ncf2lammps.numerics import (
    PERTURBATION_AMPLITUDE,
    simulated_model,
    stitch_mass_balance,
    time_step,
)
from ncf2lammps.orchestration.build import build


def test_bead_limit_is_the_chain_limit_without_contacts_and_governs_with_them():
    """Gershgorin: a bare chain bead gives sqrt(m/k); with COORDINATION contacts the bead limit
    is below every single-spring limit of that bead."""
    spec = tiny_spec()
    model = build_model(spec)
    step = time_step(spec, model)
    assert step.governing.startswith("bead ")
    singles = [v for k, v in step.limits.items() if not k.startswith("bead ")]
    assert step.critical < min(singles)
    soft = spec.replace(contact={"normal_stiffness_N_m": 1.0})  # contacts negligible
    limits = time_step(soft, model).limits
    fibre = next(t.name for t in model.atom_types if t.role == "fibre")
    bead = next(v for k, v in limits.items() if k.startswith(f"bead {fibre}"))
    assert bead == pytest.approx(limits[f"bond {fibre}"], rel=1e-6)


@pytest.mark.parametrize("mass_scaling, stiffness_scaling", [(1.0, 1.0), (16.0, 1.0), (1.0, 0.04)])
def test_scalings_reach_the_data_file_and_scale_the_limits(
    mass_scaling, stiffness_scaling, tmp_path
):
    """sqrt(m/k) limits: every limit x sqrt(mass_scaling); fibre-bond limits x
    1/sqrt(fibre_stiffness_scaling), bead limits (bonds and contacts together) between x1 and
    that; the data file carries the scaled density and K (relative tolerance 1e-12)."""
    base = tiny_spec()
    spec = base.replace(
        numerics={"mass_scaling": mass_scaling, "fibre_stiffness_scaling": stiffness_scaling}
    )
    model = build_model(spec)
    reference = time_step(base, model).limits
    limits = time_step(spec, model).limits
    for name, limit in limits.items():
        scaled = reference[name] * math.sqrt(mass_scaling)
        if name.startswith("bond ply"):
            assert limit == pytest.approx(scaled / math.sqrt(stiffness_scaling), rel=1e-12), name
        elif name.startswith("bead ply"):
            assert scaled * (1 - 1e-12) <= limit <= scaled / math.sqrt(stiffness_scaling), name
        else:
            assert limit == pytest.approx(scaled, rel=1e-12), name
    data = read_data(build(spec, tmp_path / "run").directory / "model.data")
    np.testing.assert_allclose(data.density, model.density * mass_scaling, rtol=1e-12)
    simulated = simulated_model(spec, model)
    np.testing.assert_allclose(
        data.bond_coeffs[:, 0], [t.k for t in simulated.bond_types], rtol=1e-12
    )
    fibre_k = [t.k for t in simulated.bond_types if t.role == "fibre"]
    physical_k = [t.k for t in model.bond_types if t.role == "fibre"]
    np.testing.assert_allclose(fibre_k, np.multiply(physical_k, stiffness_scaling), rtol=1e-12)


def test_stitch_mass_scaling_scales_only_the_stitch_and_its_balance_lifts_it_to_the_fibres(
    tmp_path,
):
    """stitch_mass_scaling S: the stitch beads' density x S in the data file, the fibre beads'
    unchanged; the stitch's own limits (its beads' bound and bonds) x sqrt(S), every fibre bond
    and bending limit unchanged (1e-12). Its balance factor lifts the smallest stitch limit to
    the smallest fibre limit (1e-9), after which the stitch no longer governs."""
    base = tiny_spec()
    model = build_model(base)
    reference = time_step(base, model)
    balance = stitch_mass_balance(reference)
    assert balance > 1.0 and "stitch" in reference.governing
    spec = base.replace(numerics={"stitch_mass_scaling": balance})
    scaled = time_step(spec, model)
    for name, limit in scaled.limits.items():
        if name.startswith(("bond stitch", "bead stitch")):
            expected = reference.limits[name] * math.sqrt(balance)
            assert limit == pytest.approx(expected, rel=1e-12), name
        elif name.startswith(("bond ply", "bending")):
            assert limit == pytest.approx(reference.limits[name], rel=1e-12), name
    stitch = min(v for k, v in scaled.limits.items() if scaled.roles[k] == "stitch")
    fibre = min(v for k, v in scaled.limits.items() if scaled.roles[k] == "fibre")
    assert stitch == pytest.approx(fibre, rel=1e-9)
    assert scaled.dt > reference.dt
    data = read_data(build(spec, tmp_path / "run").directory / "model.data")
    factor = np.where(model.role_mask("stitch"), balance, 1.0)
    np.testing.assert_allclose(data.density, model.density * factor, rtol=1e-12)


def test_a_model_beyond_max_beads_is_refused_before_allocation():
    """1 um chains on the tiny cell would be 1.2e10 beads: one-line SpecError naming the field."""
    from ncf2lammps.model import MAX_BEADS
    from ncf2lammps.spec import SpecError

    with pytest.raises(SpecError, match="chain_diameter_um") as err:
        build_model(tiny_spec(discretisation={"chain_diameter_um": 1.0}))
    assert f"{MAX_BEADS:,}" in str(err.value) and "\n" not in str(err.value)


def _perturbed_positions(folder, deck: str, monkeypatch, save: str = "") -> np.ndarray:
    """(N, 3) bead positions (um) after the commands of ``deck`` up to its displace_atoms line,
    run in ``folder`` (the deck's relative paths); ``save``: a restart file written then."""
    from ncf2lammps.engine import Engine

    monkeypatch.chdir(folder)
    lines = deck_commands(folder / deck)
    last = next(i for i, line in enumerate(lines) if line.startswith("displace_atoms"))
    with Engine(log=None) as engine:
        for line in lines[: last + 1]:
            engine.command(line)
        if save:
            engine.command("run 0")
            engine.command(f"write_restart {save}")
        return engine.gather("x", 3)


@pytest.mark.lammps
def test_a_replica_moves_each_bead_by_at_most_its_amplitude_and_its_seed_repeats(
    tmp_path, monkeypatch
):
    """numerics.perturbation_seed: in LAMMPS every bead moves by a uniform random amount in
    [-a, a] per axis, a = PERTURBATION_AMPLITUDE x the smallest diameter (the largest of
    3N draws lies within 1 % of a), at the start of a scene from the data file and of one from
    a restart with contact history; the same seed repeats to the last digit and another seed
    moves the beads otherwise; seed 0 (the default) renders no perturbation."""
    plain = build(tiny_spec(), tmp_path / "plain").directory
    assert not any("displace_atoms" in p.read_text() for p in (plain / "decks").glob("*.lmp"))
    data = read_data(plain / "model.data")
    amplitude = PERTURBATION_AMPLITUDE * data.diameter.min()
    moved = {}
    for name, seed in (("a", 5), ("b", 5), ("c", 6)):
        folder = build(tiny_spec(numerics={"perturbation_seed": seed}), tmp_path / name).directory
        before = _perturbed_positions(
            folder, "decks/in.manufacture.lmp", monkeypatch, save="manufactured.restart"
        )
        after = _perturbed_positions(folder, "decks/in.compaction.lmp", monkeypatch)
        moved[name] = (before, after)
    for start, end in ((data.positions, moved["a"][0]), moved["a"]):
        shift = end - start
        shift -= np.round(shift / data.box.lengths) * data.box.lengths  # periodic remaps
        assert np.abs(shift).max() <= amplitude * (1 + 1e-6)
        assert np.abs(shift).max() >= 0.99 * amplitude
        assert np.abs(shift).mean() == pytest.approx(amplitude / 2, rel=0.05)
    np.testing.assert_array_equal(moved["a"][1], moved["b"][1])
    assert np.abs(moved["a"][1] - moved["c"][1]).max() > 0.1 * amplitude
