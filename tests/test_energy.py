"""The energy-balance residual: the dissipation a run implies never decreases."""

from __future__ import annotations

import numpy as np
import pytest

from ncf2lammps.analysis.energy import energy_balance_residual


def test_clean_loading_has_zero_residual():
    """Work 0..10 split into growing dissipation, kinetic and potential energy: D only grows."""
    work = np.linspace(0.0, 10.0, 11)
    kinetic = 0.01 * work
    potential = 0.5 * work
    assert energy_balance_residual(work, kinetic, potential) == 0.0


def test_created_energy_is_the_drop_of_the_implied_dissipation():
    """Work stops at 5; kinetic energy then jumps by 2: D drops by 2, residual 2 / 5."""
    work = np.minimum(np.arange(11.0), 5.0)
    kinetic = np.zeros(11)
    kinetic[8:] = 2.0
    assert energy_balance_residual(work, kinetic, np.zeros(11)) == pytest.approx(2.0 / 5.0)
