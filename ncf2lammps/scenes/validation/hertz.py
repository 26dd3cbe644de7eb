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
from ...model import Model
from ...numerics import ContactLaw
from .common import RHO_CARBON, CaseResult, ChainSet, Check, D, fibre, lammps_case
from .plots import line_plot

__all__ = ["run"]

CASE = "2 Hertz"
TOLERANCE = 0.005


def _bead_pair(d_small: float, modulus: float) -> tuple[Model, float]:
    """A carbon bead (d = D) at the origin and a stitch-size bead (``d_small``, um) touching it
    along +x, both of contact modulus ``modulus`` (kPa); returns the model and the centre
    distance at first contact (um)."""
    chains = ChainSet()
    for name, d, rho in (("carbon", D, RHO_CARBON), ("stitch", d_small, 1.38)):
        chains.add_type(*fibre(name, d, d / 2, modulus, rho))
    reach = (D + d_small) / 2
    chains.add(np.zeros((1, 3)), 0)
    chains.add(np.array([[reach, 0.0, 0.0]]), 1)
    return chains.model([-2 * D, -2 * D, -2 * D], [3 * D, 2 * D, 2 * D]), reach


def _staircase(
    workdir: Path,
    model: Model,
    reach: float,
    modulus: float,
    stiffness: float,
    load_max: float,
    levels: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Press the small bead on with ``levels`` loads up to ``load_max`` (nN), each held.

    ``stiffness`` (nN/um) is the contact stiffness at the largest overlap, which sets the time
    step and the critical damping. Returns (levels,) arrays: the applied load (nN), the overlap
    (um) and the contact force on the fixed bead (nN) at the end of each hold.
    """
    mass = float(model.mass[1])
    dt = 0.1 * math.sqrt(mass / stiffness)
    law = ContactLaw("hertz", modulus, stiffness, 0.0, 0.0, 0.0)
    hold = 4000
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
    return load, overlap, contact_force


def _plot(
    workdir: Path, overlap: np.ndarray, load: np.ndarray, e_star: float, r_star: float
) -> Path:
    """Plot the (levels,) loads (nN, drawn in mN) against the overlaps (um) with the law for
    ``e_star`` (kPa) and ``r_star`` (um)."""
    fine = np.linspace(0.0, overlap.max() * 1.05, 100)
    return line_plot(
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


def run(workdir: Path, full: bool = False) -> CaseResult:
    """Run case 2 in ``workdir``; returns its rows and plot."""
    d_small = 30.0
    modulus = units.to_micro(1.0, "GPa")
    e_star = modulus / 2.0
    r_star = (D / 2) * (d_small / 2) / (D / 2 + d_small / 2)
    overlap_max = 0.05 * d_small
    load_max = 4.0 / 3.0 * e_star * math.sqrt(r_star) * overlap_max**1.5
    stiffness = 2.0 * e_star * math.sqrt(r_star * overlap_max)
    model, reach = _bead_pair(d_small, modulus)
    levels = 8
    load, overlap, contact_force = _staircase(
        workdir, model, reach, modulus, stiffness, load_max, levels
    )
    hertz = 4.0 / 3.0 * e_star * math.sqrt(r_star) * overlap**1.5
    worst = int(np.argmax(np.abs(load / hertz - 1.0)))
    exponent = float(np.polyfit(np.log(overlap), np.log(load), 1)[0])
    plot = _plot(workdir, overlap, load, e_star, r_star)
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
