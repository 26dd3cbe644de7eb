"""Case 6: packing limit of a frictionless hexagonal bundle of chains.

Law: parallel cylinders of diameter d pack at most hexagonally, ``Vf = pi / (2 sqrt 3) = 0.9069``
(Lagrange 1773 / Thue 1910 for circles in the plane); a frictionless bundle compressed
laterally locks there (docs/design.md §9). Vf uses the cylinder-equivalent volume. Beads of neighbouring
chains that are not side by side nest: with the three sublattices of the hexagonal lattice
shifted by s/3 along the chains, touching axes sit ``d sqrt(1 - (s / 3d)^2)`` apart and the
bundle locks at ``0.9069 / (1 - (s / 3d)^2)`` = 0.9328 at s = d/2 (geometric).

Configuration: 36 periodic chains (6 x 6, lattice rows along y) of 8 carbon beads, d = 69 um,
s = d/2, in a fully periodic box; hexagonal lattice at Vf 0.80 with random (seeded) offsets of
3 % d across the chains; frictionless hooke k_n = 1e5 N/m; ``fix viscous`` at 0.3 of critical for
one contact; the box is shrunk in y and z at constant speed (``fix deform ... vel ... remap x``)
to Vf 0.95 over 60 000 steps. The lateral virial pressure ``(Pyy + Pzz) / 2`` rises linearly
with Vf once the bundle is locked; the locking Vf is where that line reaches zero (fit over
pressures above 20 % of the final one). (a) beads side by side (cylinders); (b) sublattices
shifted by s/3 (nesting).

Tolerance: 1 % on the locking Vf.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ... import units
from ...spec import HEXAGONAL_PACKING
from .common import (
    E_CARBON,
    RHO_CARBON,
    CaseResult,
    ChainSet,
    Check,
    D,
    contact,
    fibre,
    lammps_case,
    record,
)
from .plots import line_plot

__all__ = ["run"]

CASE = "6 packing"
TOLERANCE = 0.01


def _bundle(workdir: Path, shift: bool, full: bool) -> tuple[float, np.ndarray, np.ndarray]:
    """Compress one bundle; returns (locking Vf, Vf record, lateral pressure record kPa)."""
    spacing, n_side, per_chain = D / 2, 6, 8
    vf_start, vf_end = 0.80, 0.95
    pitch = D * math.sqrt(HEXAGONAL_PACKING / vf_start)
    atom, bond, density = fibre("chain", D, spacing, E_CARBON, RHO_CARBON)
    chains = ChainSet()
    chains.add_type(atom, bond, density)
    rng = np.random.default_rng(7)
    along = np.arange(per_chain) * spacing
    for row in range(n_side):
        for i in range(n_side):
            m = i - row // 2  # lattice coordinate along y: site = m a1 + row a2
            offset = ((m - row) % 3) * spacing / 3 if shift else 0.0
            y = (i + 0.5 * (row % 2) + 0.25) * pitch
            z = (row + 0.5) * pitch * math.sqrt(3) / 2
            jitter = rng.uniform(-0.03, 0.03, 2) * D
            beads = np.column_stack(
                [
                    along + offset,
                    np.full(per_chain, y + jitter[0]),
                    np.full(per_chain, z + jitter[1]),
                ]
            )
            chains.add(beads, 0, closed=True)
    ly, lz = n_side * pitch, n_side * pitch * math.sqrt(3) / 2
    model = chains.model([0.0, 0.0, 0.0], [per_chain * spacing, ly, lz])
    mass = float(model.mass[0])
    kn = units.to_micro(1.0e5, "N_m")
    dt = 0.5 * math.sqrt(mass / (2 * bond.k))
    chunk, chunks = 500, 240 if full else 120
    duration = chunk * chunks * dt
    factor = math.sqrt(vf_start / vf_end)
    values = {
        "gamma": 0.3 * 2 * math.sqrt(kn * mass),
        "speed_y": ly * (1 - factor) / duration,
        "speed_z": lz * (1 - factor) / duration,
        "chunk": chunk,
    }
    with lammps_case(
        workdir, "validation/packing.lmp.j2", model, dt, contact(kn, mass, 0.0), **values
    ) as lmp:
        rows = record(lmp, "record", 2, chunk, chunks)
    area = np.pi * D**2 / 4 * n_side**2
    vf = area / rows[:, 1]
    pressure = rows[:, 0]
    loaded = pressure > 0.2 * pressure[-1]
    slope, intercept = np.polyfit(vf[loaded], pressure[loaded], 1)
    return float(-intercept / slope), vf, pressure


def run(workdir: Path, full: bool = False) -> CaseResult:
    """Run case 6 in ``workdir``; returns its rows and plot."""
    nested = HEXAGONAL_PACKING / (1 - (0.5 / 3) ** 2)
    side, vf_a, p_a = _bundle(workdir / "side_by_side", False, full)
    checks = [
        Check(
            CASE,
            "locking Vf, beads side by side",
            "Vf = pi / (2 sqrt 3)",
            HEXAGONAL_PACKING,
            side,
            TOLERANCE,
        )
    ]
    curves = [(vf_a, units.from_micro(p_a, "MPa"), f"side by side: lock {side:.4f}")]
    shifted, vf_b, p_b = _bundle(workdir / "nested", True, full)
    checks.append(
        Check(
            CASE,
            "locking Vf, sublattices shifted s/3",
            "Vf = 0.9069 / (1 - (s/3d)^2)",
            nested,
            shifted,
            TOLERANCE,
        )
    )
    curves.append((vf_b, units.from_micro(p_b, "MPa"), f"shifted s/3: lock {shifted:.4f}"))
    plot = line_plot(
        workdir / "packing.png",
        curves,
        "fibre volume fraction Vf (cylinder-equivalent)",
        "lateral pressure (MPa)",
        "Case 6: frictionless hexagonal bundle, 36 chains",
    )
    return CaseResult(CASE, checks, [plot])
