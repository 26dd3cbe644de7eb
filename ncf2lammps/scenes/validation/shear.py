"""Case 5: shear identities of a periodic cell under picture-frame kinematics.

Laws (docs/design.md §7): the normalised picture-frame force is the power per unit current area per unit
shear rate, ``F_N = N_xy - N_yy tan g`` with membrane forces from the virial stress:
``F_N = -(Pxy - Pyy xy / ly) lz`` (``compute pressure NULL virial``). (a) A frictionless 0/90
cell of pretensioned straight chains keeps every chain length under ``xy = Lb sin g,
ly = Lb cos g``, so F_N = 0 whatever the pretension. (b) For a conservative cell the virial F_N
equals the work-based ``F_N = dW / (lx ly dg)``, with ``dW = -lx lz (Pxy dxy + Pyy dly)`` and,
independently, ``dW = dE`` (elastic plus kinetic energy): a cell of chains along the diagonal
a + b, stretched by the shear, has ``F_N = n T / L`` (n chains of tension T and length
``L = |a + b|``).

Configuration: carbon chains d = 69 um, s = d/2 (E 240 GPa), periodic in x and y, ``fix deform
... xy variable ... y variable ... remap x flip no`` with ``g(t) = g_max (t/T - sin(2 pi t/T) /
2 pi)`` (zero rate at both ends), variables rebased at every run; no damping other than the
contacts'. (a) 4 chains at 0 deg and 4 at 90 deg, 2.5 d apart, cell 10 d x 10 d, pretension
1e-3 EA (bond rest length shortened), hooke k_n = 1e5 N/m, mu = 0, the plies pressed together
by frictionless ``wall/harmonic`` planes (force 1e-3 of the pretension per bead; wall forces act
along z and are not in the virial); sheared to 30 deg. The scale is the pretension membrane
force ``N0 = T0 n / ly``. (b) 3 chains along the diagonal of a 10 d x 10 d cell (28 beads each,
pretension 1e-3 EA), no contacts, sheared to 20 deg; F_N from the virial is compared with the
energy derivative ``dE / (lx ly dg)`` per recording interval and with ``n T / L``.

Tolerance: (a) max |F_N| < 1 % of N0; (b) 2 % between virial and work (and work and energy).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ... import units
from ...analysis.shear import work_force
from ...model import BondType, Model
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
)
from .plots import line_plot

__all__ = ["run"]

CASE = "5 shear"
PRETENSION = 1e-3


def _shear(lmp, chunk: int, chunks: int) -> dict[str, np.ndarray]:
    """Run the shear in chunks, rebasing the deform variables; returns the records (chunks,)."""
    names = ("fn", "pxy", "pyy")
    out = {k: np.empty(chunks) for k in (*names, "g", "xy", "lx", "ly", "lz", "energy", "kinetic")}
    box0 = {k: lmp.variable(f"box_{k}") for k in ("xy", "ly")}
    energy0 = lmp.variable("energy")
    for i in range(chunks):
        lmp.command("variable g0 equal $(v_g:%.17g)")
        lmp.command(f"run {chunk}")
        for name, value in zip(names, lmp.fix_vector("record", 3), strict=True):
            out[name][i] = value
        out["g"][i] = lmp.variable("g")
        out["energy"][i] = lmp.variable("energy")
        out["kinetic"][i] = lmp.variable("kinetic")
        for k in ("xy", "lx", "ly", "lz"):
            out[k][i] = lmp.variable(f"box_{k}")
    out["xy_start"], out["ly_start"], out["energy_start"] = (
        np.array([box0["xy"]]),
        np.array([box0["ly"]]),
        np.array([energy0]),
    )
    return out


def _zero_force(workdir: Path, full: bool) -> tuple[Check, tuple]:
    """Sub-case (a): frictionless pretensioned 0/90 cell, F_N must vanish."""
    spacing, pitch, n = D / 2, 2.5 * D, 4
    frame = n * pitch
    per_chain = round(frame / spacing)
    atom, bond, density = fibre("ply", D, spacing, E_CARBON, RHO_CARBON)
    tension = PRETENSION * bond.axial_stiffness
    bond = type(bond)(
        bond.name, bond.role, bond.k, spacing - tension / (2 * bond.k), bond.axial_stiffness
    )
    chains = ChainSet()
    chains.add_type(atom, bond, density)
    along = np.arange(per_chain) * spacing
    for j in range(n):
        across = (j + 0.5) * pitch
        chains.add(
            np.column_stack([along, np.full(per_chain, across), np.zeros(per_chain)]),
            0,
            closed=True,
        )
        chains.add(
            np.column_stack([np.full(per_chain, across), along, np.full(per_chain, D)]),
            0,
            closed=True,
        )
    model = chains.model([0.0, 0.0, -3 * D], [frame, frame, 4 * D])
    mass = float(model.mass[0])
    dt = 0.5 * math.sqrt(mass / (2 * bond.k))
    kn = units.to_micro(1.0e5, "N_m")
    wall_force = 1e-3 * tension
    overlap = 0.002 * D
    chunk, chunks = (1000, 100) if full else (1000, 50)
    values = {
        "wall_force": wall_force,
        "wall_lo": -D / 2 + overlap,
        "wall_hi": 1.5 * D - overlap,
        "wall_epsilon": wall_force / (2 * overlap),
        "wall_cutoff": D / 2,
        "angle": math.radians(30.0),
        "duration": chunk * chunks * dt,
        "frame": frame,
        "chunk": chunk,
    }
    with lammps_case(
        workdir, "validation/shear.lmp.j2", model, dt, contact(kn, mass, 0.0), **values
    ) as lmp:
        rec = _shear(lmp, chunk, chunks)
    membrane = tension * n / frame
    worst = float(np.max(np.abs(rec["fn"])) / membrane)
    check = Check(
        CASE, "0/90 frictionless: max |F_N| / N0", "F_N = 0", 0.0, worst, 0.01, "absolute"
    )
    return check, (np.degrees(rec["g"]), rec["fn"] / membrane, "0/90 frictionless: F_N / N0")


def _diagonal_cell(frame: float, n_chains: int, per_chain: int) -> tuple[Model, BondType]:
    """``n_chains`` closed chains of ``per_chain`` beads along the diagonal a + b of a
    ``frame`` x ``frame`` (um) cell, pretensioned by :data:`PRETENSION` (bond rest length
    shortened); returns the model and its bond type."""
    diagonal = math.sqrt(2.0) * frame
    step = diagonal / per_chain
    atom, bond, density = fibre("diagonal", D, step, E_CARBON, RHO_CARBON)
    bond = type(bond)(bond.name, bond.role, bond.k, step / (1 + PRETENSION), bond.axial_stiffness)
    chains = ChainSet()
    chains.add_type(atom, bond, density)
    t = np.arange(per_chain) / per_chain
    for c in range(n_chains):
        x = ((c + 0.5) / n_chains + t) * frame % frame
        chains.add(np.column_stack([x, t * frame, np.zeros(per_chain)]), 0, closed=True)
    return chains.model([0.0, 0.0, -3 * D], [frame, frame, 3 * D]), bond


def _identity(workdir: Path, full: bool) -> tuple[list[Check], tuple, str]:
    """Sub-case (b): diagonal chains, virial F_N against work and energy."""
    frame, n_chains, per_chain = 10 * D, 3, 28
    model, bond = _diagonal_cell(frame, n_chains, per_chain)
    mass = float(model.mass[0])
    dt = 0.5 * math.sqrt(mass / (2 * bond.k))
    chunk, chunks = (500, 100) if full else (500, 60)
    angle = math.radians(20.0)
    values = {
        "wall_force": 0.0,
        "angle": angle,
        "duration": chunk * chunks * dt,
        "frame": frame,
        "chunk": chunk,
    }
    kn = units.to_micro(1.0e5, "N_m")
    with lammps_case(
        workdir, "validation/shear.lmp.j2", model, dt, contact(kn, mass, 0.0), **values
    ) as lmp:
        rec = _shear(lmp, chunk, chunks)
    lx = rec["lx"][0]
    # F_N = n T / L, chain length L = |a + b| and tension T = 2 k (L / per_chain - r0)
    length = np.sqrt(lx**2 + frame**2 + 2 * lx * frame * np.sin(rec["g"]))
    analytic = n_chains * 2 * bond.k * (length / per_chain - bond.r0) / length
    return _judge_identity(rec, analytic)


def _judge_identity(
    rec: dict[str, np.ndarray], analytic: np.ndarray
) -> tuple[list[Check], tuple, str]:
    """Virial F_N against pressure work, energy change and the law ``analytic`` (chunks,) nN/um.

    ``rec`` is the :func:`_shear` record. Returns the checks, the plot curves (angle deg, virial
    F_N, angle deg, energy F_N, law; each (chunks,), F_N in nN/um) and the note.
    """
    g = np.r_[0.0, rec["g"]]
    xy = np.r_[rec["xy_start"], rec["xy"]]
    ly = np.r_[rec["ly_start"], rec["ly"]]
    energy = np.r_[rec["energy_start"], rec["energy"]]
    lx, lz = rec["lx"][0], rec["lz"][0]
    work, fn_work = work_force(g, xy, lx, ly, -rec["pxy"] * lz, -rec["pyy"] * lz)
    fn_energy = np.diff(energy) / (lx * 0.5 * (ly[1:] + ly[:-1]) * np.diff(g))
    loaded = np.abs(rec["fn"]) > 0.1 * np.abs(rec["fn"]).max()
    virial_vs_work = float(np.max(np.abs(fn_work[loaded] / rec["fn"][loaded] - 1)))
    checks = [
        Check(
            CASE,
            "diagonal chains: F_N work / F_N virial, worst interval",
            "F_N = dW / (lx ly dg)",
            1.0,
            1.0 + virial_vs_work,
            0.02,
        ),
        Check(
            CASE,
            "diagonal chains: pressure work W / energy change dE",
            "W = dE (conservative)",
            float(energy[-1] - energy[0]),
            float(work.sum()),
            0.02,
        ),
        Check(
            CASE,
            "diagonal chains: F_N virial at 20 deg",
            "F_N = n T / L",
            float(analytic[-1]),
            float(rec["fn"][-1]),
            0.02,
        ),
    ]
    note = (
        f"(b) worst interval: virial vs pressure work {virial_vs_work:.2e}, virial vs energy"
        f" {float(np.max(np.abs(fn_energy[loaded] / rec['fn'][loaded] - 1))):.2e}; kinetic energy"
        f" / energy change at the end {rec['kinetic'][-1] / (energy[-1] - energy[0]):.1e}."
    )
    curves = (np.degrees(rec["g"]), rec["fn"], np.degrees(rec["g"]), fn_energy, analytic)
    return checks, curves, note


def run(workdir: Path, full: bool = False) -> CaseResult:
    """Run case 5 in ``workdir``; returns its rows and plots."""
    zero, zero_curve = _zero_force(workdir / "frictionless_0_90", full)
    identity, (g, fn, g2, fn_energy, analytic), note = _identity(workdir / "diagonal", full)
    plots = [
        line_plot(
            workdir / "shear_zero.png",
            [zero_curve],
            "shear angle g (deg)",
            "F_N / N0",
            "Case 5a: frictionless pretensioned 0/90 cell",
        ),
        line_plot(
            workdir / "shear_identity.png",
            [
                (g, units.from_micro(fn, "N_m"), "virial -(Pxy - Pyy xy/ly) lz"),
                (g2, units.from_micro(fn_energy, "N_m"), "dE / (lx ly dg)"),
                (g, units.from_micro(analytic, "N_m"), "n T / L"),
            ],
            "shear angle g (deg)",
            "F_N (N/m)",
            "Case 5b: diagonal chains, virial vs work",
            styles=["-", "o", "--"],
        ),
    ]
    return CaseResult(CASE, [zero, *identity], plots, note)
