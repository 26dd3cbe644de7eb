"""Validation cases run in LAMMPS and judged against their laws (docs/design.md §9).

The fast forms run in CI; ``full`` forms (all angles, spacings, longer records) are ``slow``.
Each test asserts the law with the tolerance stated in the case's docstring.
"""

from __future__ import annotations

import hashlib
import math

import numpy as np
import pytest
from conftest import GOLDEN, compare_or_update

from ncf2lammps.scenes.validation import CASES
from ncf2lammps.scenes.validation import run_case as _run_case
from ncf2lammps.scenes.validation.crossover import analytic_fn
from ncf2lammps.scenes.validation.sliding import roughness_estimate
from ncf2lammps.scenes.validation.udbed import (
    exponent,
    largest_drop,
    largest_jump,
    stack_exponent,
    steepest_rise,
)


def run_case(name, output):
    """Run the fast form of case ``name``; its decks and data files must equal their golden files.

    A deck reads its data file by absolute path: the absolute path of the deck's own folder
    plus ``/`` is removed from the deck's text before the comparison; every other byte counts.
    """
    result = _run_case(name, output)
    folder = output / name
    decks = {
        str(p.relative_to(folder)): p.read_text().replace(f"{p.parent.resolve()}/", "")
        for p in folder.rglob("*.lmp")
    }
    decks |= {
        f"{p.relative_to(folder)}.sha256": hashlib.sha256(p.read_bytes()).hexdigest() + "\n"
        for p in folder.rglob("model.data")
    }
    compare_or_update(decks, GOLDEN / "validation" / name)
    return result


def _rows(result):
    return {c.name: c for c in result.checks}


@pytest.mark.lammps
def test_waves(tmp_path):
    rows = _rows(run_case("waves", tmp_path))
    speed = rows["wave speed c (m/s)"]
    assert speed.expected == pytest.approx(math.sqrt(240e6 / 1.8))
    assert abs(speed.measured / speed.expected - 1) <= 0.005
    for n in (1, 2, 3):
        mode = rows[f"mode {n} omega (rad/us)"]
        assert abs(mode.measured / mode.expected - 1) <= 0.005, mode
    drift = next(c for c in rows.values() if c.name.startswith("energy drift"))
    assert drift.measured <= 1e-4


@pytest.mark.lammps
def test_hertz(tmp_path):
    result = run_case("hertz", tmp_path)
    force, exponent = result.checks
    assert abs(force.measured / force.expected - 1) <= 0.005
    assert exponent.measured == pytest.approx(1.5, rel=0.005)


@pytest.mark.lammps
def test_coulomb_sliding(tmp_path):
    rows = _rows(run_case("sliding", tmp_path))
    assert rows["wall, F/N at mu = 0.3"].measured == pytest.approx(0.3, rel=0.005)
    assert rows["wall, |F/N| at mu = 0"].measured < 1e-3
    for name in ("crossing chain, s = d/2: F/(mu N)", "parallel chain, s = d/2: F/(mu N)"):
        assert 1.0 <= rows[name].measured <= 1.05, rows[name]


@pytest.mark.lammps
def test_capstan_half_turn(tmp_path):
    (check,) = run_case("capstan", tmp_path).checks
    assert check.expected == pytest.approx(math.exp(0.3 * math.pi))
    assert abs(check.measured / check.expected - 1) <= 0.01


@pytest.mark.lammps
def test_shear_identities(tmp_path):
    """Case 5, both senses of the 0/90 and +-45 frames: frictionless pretensioned cells have
    |F_N| below 1 % of N0; virial F_N, pressure work, energy change and the law agree within
    2 %."""
    checks = run_case("shear", tmp_path).checks
    zero = [c for c in checks if c.law == "F_N = 0"]
    assert {c.name.split(":")[0] for c in zero} == {
        "0/90 frictionless",
        "+-45 positive frictionless",
        "+-45 negative frictionless",
    }
    for check in zero:
        assert check.measured < 0.01, check  # |F_N| / N0
    identities = [c for c in checks if c.law != "F_N = 0"]
    assert len(identities) == 12  # 3 per frame and sense
    for check in identities:
        assert abs(check.measured / check.expected - 1) <= 0.02, check


@pytest.mark.lammps
def test_shear_crossover_springs(tmp_path):
    """Case 5c: F_N = 2 K g / (p^2 cos g) within 1 %, virial and work agree within 2 %."""
    result = run_case("crossover", tmp_path)
    rows = _rows(result)
    for angle in (10, 20, 30, 40):
        for what in ("virial", "work"):
            check = rows[f"F_N {what} at {angle} deg"]
            assert abs(check.measured / check.expected - 1) <= 0.01, check
    assert rows["F_N work / F_N virial, worst interval"].measured <= 1.02
    assert all(c.passed for c in result.checks)


def test_crossover_law_is_the_energy_derivative():
    """F_N = dW / (lx ly dg) with W = n K g^2, lx ly = n p^2 cos g (finite difference)."""
    k, p, n, g, h = 3.0, 2.0, 9, 0.5, 1e-6
    energy = n * k * np.array([g - h, g + h]) ** 2
    expected = (energy[1] - energy[0]) / (2 * h) / (n * p**2 * math.cos(g))
    assert analytic_fn(g, k, p) == pytest.approx(expected, rel=1e-8)


@pytest.mark.lammps
def test_packing_limit(tmp_path):
    side, nested = run_case("packing", tmp_path).checks
    assert side.measured == pytest.approx(math.pi / (2 * math.sqrt(3)), rel=0.01)
    assert nested.measured == pytest.approx(0.9328, rel=0.01)


@pytest.mark.lammps
def test_random_ud_bed(tmp_path):
    """Case 7: the bed of bundle chains with bending compacts progressively and smoothly; the
    rigid bed of free pins locks (its pressure rises threefold within 2 % of Vf)."""
    rows = _rows(run_case("udbed", tmp_path))
    exponent = rows["bundle law + bending: b of Vf = a P^b, 1-18 kPa"]
    assert exponent.expected == pytest.approx(stack_exponent())
    assert stack_exponent() <= exponent.measured <= stack_exponent() + 0.25, exponent
    jump = rows["bundle law + bending: largest P ratio of successive records, 1-18 kPa"]
    assert jump.measured <= 1.25, jump
    lock = rows["rigid, free pins: steepest threefold rise of P, ln(Vf2/Vf1)"]
    assert 0.0 <= lock.measured <= 0.02, lock


def test_udbed_exponent_of_a_power_law():
    """b of Vf = a P^b read back from a sampled power law; the stack exponent from the law."""
    pressure = np.geomspace(0.1, 50.0, 400)
    assert exponent(0.3 * pressure**0.1, pressure) == pytest.approx(0.1, rel=1e-3)
    assert largest_jump(pressure) == pytest.approx((50.0 / 0.1) ** (1 / 399), rel=1e-9)
    assert 0.0 < stack_exponent() < 0.1
    fvf = np.array([0.20, 0.21, 0.211, 0.212, 0.30])
    assert steepest_rise(fvf, np.array([1.0, 2.0, 5.0, 21.0, 30.0])) == pytest.approx(
        math.log(0.212 / 0.21)
    )
    assert largest_drop(np.array([1.0, 40.0, 20.0, 50.0])) == pytest.approx(2.0)


def test_roughness_estimate_matches_design():
    """docs/design.md §6: 1 + (1 + mu^2) s^2 / (12 d^2) at s = d/2, mu = 0.3."""
    assert roughness_estimate(69.0 / 2) == pytest.approx(1 + 1.09 / 48)


@pytest.mark.lammps
@pytest.mark.slow
@pytest.mark.parametrize("name", list(CASES))
def test_full_case(name, tmp_path):
    """The full set: every check of every case within its tolerance."""
    result = _run_case(name, tmp_path, full=True)
    failed = [c.row() for c in result.checks if not c.passed]
    assert not failed, failed


@pytest.mark.lammps
def test_bundle_law(tmp_path):
    """Case 7: the stack returns its mapped bed law within 5 % over 1-100 kPa; F = mu N within
    1 % on a wall under the bundle law."""
    rows = _rows(run_case("bundle", tmp_path))
    stack = next(c for n, c in rows.items() if n.startswith("stack P at"))
    assert abs(stack.measured / stack.expected - 1) <= 0.05, stack
    wall = rows["wall, F/N at mu = 0.3 (10 kPa)"]
    assert wall.measured == pytest.approx(0.3, rel=0.01)
