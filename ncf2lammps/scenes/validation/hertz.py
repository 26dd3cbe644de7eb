"""Case 2: Hertz contact between two beads of different size.

Law: ``F = 4/3 E* sqrt(R*) delta^1.5`` with ``1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2`` and
``R* = R1 R2 / (R1 + R2)`` (Hertz 1882; Johnson, *Contact Mechanics*, 1985, eq. 4.22). The deck
uses ``pair granular hertz/material E 0 nu=0`` for both beads, so ``E* = E / 2``.

Configuration: a carbon bead (d = 69 um) held fixed and a stitch-size bead (d = 30 um,
1.38 g/cm3) pressed onto it along x by a staircase of 8 loads up to an overlap of ~5 % of the
small diameter; contact modulus 1 GPa (spec default); no contact damping; the mobile bead is
damped by ``fix viscous`` at critical damping for the stiffest contact and held 4000 steps at each
load (quasi-static). At each load the overlap is measured from the bead positions and the applied
load is compared with the law evaluated at that overlap; the exponent is the slope of log F
against log delta.

Tolerance: 0.5 % on the force at every load and on the exponent 1.5.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ... import units
from ...numerics import ContactLaw
from .common import RHO_CARBON, CaseResult, ChainSet, Check, D, fibre, lammps_case
from .plots import line_plot

__all__ = ["run"]

CASE = "2 Hertz"
TOLERANCE = 0.005


def run(workdir: Path, full: bool = False) -> CaseResult:
    """Run case 2 in ``workdir``; returns its rows and plot."""
    d_small = 30.0
    modulus = units.to_micro(1.0, "GPa")
    e_star = modulus / 2.0
    r_star = (D / 2) * (d_small / 2) / (D / 2 + d_small / 2)
    overlap_max = 0.05 * d_small
    load_max = 4.0 / 3.0 * e_star * math.sqrt(r_star) * overlap_max**1.5
    stiffness = 2.0 * e_star * math.sqrt(r_star * overlap_max)
    chains = ChainSet()
    for name, d, rho in (("carbon", D, RHO_CARBON), ("stitch", d_small, 1.38)):
        chains.add_type(*fibre(name, d, d / 2, modulus, rho))
    reach = (D + d_small) / 2
    chains.add(np.zeros((1, 3)), 0)
    chains.add(np.array([[reach, 0.0, 0.0]]), 1)
    model = chains.model([-2 * D, -2 * D, -2 * D], [3 * D, 2 * D, 2 * D])
    mass = float(model.mass[1])
    dt = 0.1 * math.sqrt(mass / stiffness)
    law = ContactLaw("hertz", modulus, stiffness, 0.0, 0.0, 0.0)
    levels, hold = 8, 4000
    values = {
        "gamma": 2.0 * math.sqrt(mass * stiffness),
        "load_max": load_max,
        "hold": hold,
        "levels": levels,
        "reach": reach,
    }
    load, overlap, contact_force = (np.empty(levels) for _ in range(3))
    with lammps_case(workdir, "validation/hertz.lmp.j2", model, dt, law, **values) as lmp:
        for i in range(levels):
            lmp.command(f"run {hold}")
            load[i] = lmp.variable("load")
            overlap[i] = lmp.variable("overlap")
            contact_force[i] = lmp.variable("contact")
    hertz = 4.0 / 3.0 * e_star * math.sqrt(r_star) * overlap**1.5
    worst = int(np.argmax(np.abs(load / hertz - 1.0)))
    exponent = float(np.polyfit(np.log(overlap), np.log(load), 1)[0])
    fine = np.linspace(0.0, overlap.max() * 1.05, 100)
    plot = line_plot(
        workdir / "hertz.png",
        [
            (overlap, units.from_micro(load, "N") * 1e3, "applied load (LAMMPS equilibrium)"),
            (
                fine,
                units.from_micro(4.0 / 3.0 * e_star * math.sqrt(r_star) * fine**1.5, "N") * 1e3,
                "4/3 E* sqrt(R*) delta^1.5",
            ),
        ],
        "overlap delta (um)",
        "contact force (mN)",
        "Case 2: Hertz contact, d = 69 um on d = 30 um, E = 1 GPa",
        styles=["o", "-"],
    )
    checks = [
        Check(
            CASE,
            f"F at delta = {overlap[worst]:.3g} um (worst of {levels})",
            "F = 4/3 E* sqrt(R*) delta^1.5",
            float(hertz[worst]),
            float(load[worst]),
            TOLERANCE,
        ),
        Check(CASE, "exponent d ln F / d ln delta", "1.5", 1.5, exponent, TOLERANCE),
    ]
    note = (
        f"Contact force read on the fixed bead equals the applied load to "
        f"{np.max(np.abs(contact_force / load - 1)):.1e} (equilibrium reached)."
    )
    return CaseResult(CASE, checks, [plot], note)
