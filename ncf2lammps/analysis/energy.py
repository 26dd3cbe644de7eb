"""Energy balance of a loaded run: the dissipation it implies must never decrease."""

from __future__ import annotations

import numpy as np

__all__ = ["energy_balance_residual"]


def energy_balance_residual(work, kinetic, potential) -> float:
    """Largest drop of the implied dissipation, relative to the final external work.

    ``work``, ``kinetic``, ``potential``: (N,) cumulative external work, kinetic and potential
    energy at the same records (any one energy unit). LAMMPS tallies no energy lost in contact
    damping and friction (lammps/lammps#3928), so the balance is closed by its remainder
    ``D = W - (K - K0) - (U - U0)``: damping and friction can only make it grow. A drop of D
    is energy that the integrator created (or, as LAMMPS's granular contacts report no
    potential energy, elastic contact energy given back); 0 for a clean loading run. Like every
    ratio to the work, it means little when the work is tiny (a loose mat without stitch
    sheared: 1.27 measured, against 2.4e-7 for the same mat compacted).
    """
    work = np.asarray(work, dtype=float)
    implied = work - (np.asarray(kinetic) - kinetic[0]) - (np.asarray(potential) - potential[0])
    if len(implied) == 0 or work[-1] == 0:
        return float("nan")
    drop = np.maximum.accumulate(implied) - implied
    return float(drop.max() / abs(work[-1]))
