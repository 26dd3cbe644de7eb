"""Case 5: shear identities of a periodic cell under picture-frame kinematics, in both senses.

Laws (docs/shear.md): the normalised picture-frame force is the power per unit current area per
unit shear rate, from the virial stress (``compute pressure NULL virial``) and membrane forces
``N = -P lz``: for the 0/90 frame (the box tilts, ``xy = s Lb sin g``, ``ly = Lb cos g``)
``F_N = s (Nxy - Nyy xy / ly)``; for the +-45 frame (the box stretches, ``lx = La cos(phi) /
cos(phi0)``, ``ly = Lb sin(phi) / sin(phi0)``, ``phi = phi0 - s g / 2``) ``F_N = s (Nxx tan(phi)
- Nyy cot(phi)) / 2``; s = +1 (positive sense) or -1 (negative). (a) A frictionless cell of
pretensioned straight chains along the frame's fibres keeps every chain length, so F_N = 0
whatever the pretension, in both senses. (b) For a conservative cell the virial F_N equals the
work-based ``F_N = dW / (lx ly dg)``, with ``dW = Nxx ly dlx + Nyy lx dly + Nxy (lx dxy - xy
dlx)`` and, independently, ``dW = dE`` (elastic plus kinetic energy): n chains of tension T
along a line the shear stretches have ``F_N = n T L' / (lx ly)`` (``L' = dL/dg``): the diagonal
a + b (positive) or a - b (negative) of the 0/90 frame, ``F_N = n T / L``; the bisector x
(positive) or y (negative) of the +-45 frame, ``F_N = n T tan(phi) / (2 ly)`` or
``n T cot(phi) / (2 lx)``.

Configuration: carbon chains d = 69 um (E 240 GPa), periodic in x and y, ``fix deform`` of the
frame's recipe with ``remap x flip no`` and ``g(t) = g_max (t/T - sin(2 pi t/T) / 2 pi)`` (zero
rate at both ends), variables rebased at every run; no damping other than the contacts'.
(a) 0/90: 4 chains at 0 deg and 4 at 90 deg (s = d/2), 2.5 d apart, cell 10 d x 10 d,
pretension 1e-3 EA (bond rest length shortened); +-45: 4 closed chains along each diagonal of
the cell (28 beads each), +45 below -45, pretension 1e-3 EA; hooke k_n = 1e5 N/m, mu = 0, the
plies pressed together by frictionless ``wall/harmonic`` planes (force 1e-3 of the pretension
per bead; wall forces act along z and are not in the virial); sheared to 30 deg. The scale is
the pretension membrane force ``N0 = T0 / p`` (p the chains' spacing normal to them).
(b) 3 chains along the stretched line of a 10 d x 10 d cell (28 beads on a diagonal, 20 on a
bisector, pretension 1e-3 EA), no contacts, sheared to 20 deg; F_N from the virial is compared
with the energy derivative ``dE / (lx ly dg)`` per recording interval and with the law.

Tolerance: (a) max |F_N| < 1 % of N0; (b) 2 % between virial and work (and work and energy).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ... import units
from ...analysis.shear import PictureFrame, work_force
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
#: The frames of the case: 0/90 (the box tilts) and +-45 (the box stretches), each sense.
TILT, TILT_NEGATIVE = PictureFrame.tilt(1), PictureFrame.tilt(-1)
STRETCH, STRETCH_NEGATIVE = PictureFrame.stretch(45.0, 1), PictureFrame.stretch(45.0, -1)


def _label(frame: PictureFrame) -> str:
    """``0/90`` or ``+-45`` and the sense, for check names."""
    angles = "0/90" if frame.kind == "tilt" else f"+-{math.degrees(frame.half_angle):g}"
    return f"{angles} {'positive' if frame.sense > 0 else 'negative'}"


def _shear(lmp, chunk: int, chunks: int, frame: PictureFrame) -> dict[str, np.ndarray]:
    """Run the shear in chunks, rebasing the deform variables; returns the records (chunks,)
    (``pxx`` NaN but for a stretch) and the box and energy at the start (``<name>_start``,
    (1,))."""
    names = ("fn", "pxy", "pyy", "pxx")
    keys = (*names, "g", "xy", "lx", "ly", "lz", "energy", "kinetic")
    out = {k: np.full(chunks, np.nan) for k in keys}
    start = {f"{k}_start": np.array([lmp.variable(f"box_{k}")]) for k in ("xy", "lx", "ly")}
    start["energy_start"] = np.array([lmp.variable("energy")])
    width = 4 if frame.kind == "stretch" else 3
    for i in range(chunks):
        lmp.command("variable g0 equal $(v_g:%.17g)")
        lmp.command(f"run {chunk}")
        for name, value in zip(names, lmp.fix_vector("record", width), strict=False):
            out[name][i] = value
        out["g"][i] = lmp.variable("g")
        out["energy"][i] = lmp.variable("energy")
        out["kinetic"][i] = lmp.variable("kinetic")
        for k in ("xy", "lx", "ly", "lz"):
            out[k][i] = lmp.variable(f"box_{k}")
    return out | start


def _pretensioned(name: str, step: float, r0: float):
    """(atom, bond, bead density) of carbon chains of bead spacing ``step`` (um) whose bonds
    rest at ``r0`` (um)."""
    atom, bond, density = fibre(name, D, step, E_CARBON, RHO_CARBON)
    return atom, type(bond)(bond.name, bond.role, bond.k, r0, bond.axial_stiffness), density


def _zero_090(frame: float, n: int) -> tuple[Model, BondType]:
    """Sub-case (a), 0/90: ``n`` closed chains along x at z = 0 and ``n`` along y at z = d,
    ``frame / n`` apart, pretensioned by :data:`PRETENSION` (rest length shortened by T / 2k)."""
    spacing, pitch = D / 2, frame / n
    per_chain = round(frame / spacing)
    atom, bond, _ = fibre("ply", D, spacing, E_CARBON, RHO_CARBON)
    tension = PRETENSION * bond.axial_stiffness
    atom, bond, density = _pretensioned("ply", spacing, spacing - tension / (2 * bond.k))
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
    return chains.model([0.0, 0.0, -3 * D], [frame, frame, 4 * D]), bond


def _lattice_cell(
    name: str, frame: float, plies, n_chains: int, per_chain: int, z_range
) -> tuple[Model, BondType]:
    """Closed chains along lattice vectors of a ``frame`` x ``frame`` (um) cell, pretensioned
    by :data:`PRETENSION` (bond rest length ``step / (1 + PRETENSION)``).

    ``plies``: ((i, j), z) per ply: ``n_chains`` chains of ``per_chain`` beads along
    ``(i, j) frame`` at height z (um), offset along x (along y for chains along x);
    ``z_range``: (lo, hi) of the box in z (um). Returns the model and its bond type.
    """
    (i, j), _ = plies[0]
    step = math.hypot(i, j) * frame / per_chain
    chains = ChainSet()
    _, bond, _ = _pretensioned(name, step, step / (1 + PRETENSION))
    chains.add_type(*_pretensioned(name, step, step / (1 + PRETENSION)))
    t = np.arange(per_chain) / per_chain
    for (i, j), z in plies:
        offset = np.array([0.0, 1.0]) if j == 0 else np.array([1.0, 0.0])
        for c in range(n_chains):
            x = ((c + 0.5) / n_chains * offset[0] + i * t) * frame % frame
            y = ((c + 0.5) / n_chains * offset[1] + j * t) * frame % frame
            chains.add(np.column_stack([x, y, np.full(per_chain, z)]), 0, closed=True)
    return chains.model([0.0, 0.0, z_range[0]], [frame, frame, z_range[1]]), bond


def _zero_force(workdir: Path, full: bool, frame: PictureFrame) -> tuple[Check, tuple]:
    """Sub-case (a): frictionless pretensioned cell along ``frame``'s fibres, F_N must vanish."""
    edge, n = 10 * D, 4
    if frame.kind == "tilt":
        model, bond = _zero_090(edge, n)
        tension = PRETENSION * bond.axial_stiffness
        spacing = edge / n
    else:
        plies = [((1, 1), 0.0), ((1, -1), D)]
        model, bond = _lattice_cell("ply", edge, plies, n, 28, (-3 * D, 4 * D))
        tension = 2 * bond.k * (math.sqrt(2) * edge / 28 - bond.r0)
        spacing = edge / (n * math.sqrt(2))
    mass = float(model.mass[0])
    dt = 0.5 * math.sqrt(mass / (2 * bond.k))
    kn = units.to_micro(1.0e5, "N_m")
    wall_force = 1e-3 * (PRETENSION * bond.axial_stiffness)
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
        "a": edge,
        "b": edge,
        "chunk": chunk,
    }
    with lammps_case(
        workdir, "validation/shear.lmp.j2", model, dt, contact(kn, mass, 0.0), **values
    ) as lmp:
        rec = _shear(lmp, chunk, chunks, frame)
    membrane = tension / spacing
    worst = float(np.max(np.abs(rec["fn"])) / membrane)
    label = _label(frame)
    name = f"{label} frictionless: max |F_N| / N0"
    if frame == TILT:
        name = "0/90 frictionless: max |F_N| / N0"
    check = Check(CASE, name, "F_N = 0", 0.0, worst, 0.01, "absolute")
    return check, (np.degrees(rec["g"]), rec["fn"] / membrane, f"{label}: F_N / N0")


#: Sub-case (b) per frame: the lattice vector (i, j) of the chains (along the line the shear
#: stretches) and their beads per chain.
STRETCHED = {
    TILT: ((1, 1), 28),
    TILT_NEGATIVE: ((1, -1), 28),
    STRETCH: ((1, 0), 20),
    STRETCH_NEGATIVE: ((0, 1), 20),
}


def _identity(workdir: Path, full: bool, frame: PictureFrame) -> tuple[list[Check], tuple, str]:
    """Sub-case (b): chains along the line ``frame`` stretches, virial F_N against work and
    energy and the law ``F_N = n T L' / (lx ly)``."""
    edge, n_chains = 10 * D, 3
    lattice, per_chain = STRETCHED[frame]
    name = "diagonal" if frame.kind == "tilt" else "bisector"
    model, bond = _lattice_cell(name, edge, [(lattice, 0.0)], n_chains, per_chain, (-3 * D, 3 * D))
    mass = float(model.mass[0])
    dt = 0.5 * math.sqrt(mass / (2 * bond.k))
    chunk, chunks = (500, 100) if full else (500, 60)
    values = {
        "wall_force": 0.0,
        "angle": math.radians(20.0),
        "duration": chunk * chunks * dt,
        "frame": frame,
        "a": edge,
        "b": edge,
        "chunk": chunk,
    }
    kn = units.to_micro(1.0e5, "N_m")
    with lammps_case(
        workdir, "validation/shear.lmp.j2", model, dt, contact(kn, mass, 0.0), **values
    ) as lmp:
        rec = _shear(lmp, chunk, chunks, frame)
    return _judge_identity(rec, _law(rec, frame, bond, n_chains, per_chain), frame)


def _law(rec, frame: PictureFrame, bond: BondType, n_chains: int, per_chain: int) -> np.ndarray:
    """F_N = n T L' / (lx ly) (nN/um) of the stretched chains at the recorded angles, with
    T = 2 k (L / per_chain - r0)."""
    lx, ly, xy = frame.box(rec["g"], rec["lx_start"][0], rec["ly_start"][0])
    if frame.kind == "tilt":  # the diagonal a + s b, L' / (lx ly) = 1 / L
        length = np.hypot(lx + frame.sense * xy, ly)
        per_length = 1.0 / length
    elif frame.sense > 0:  # the bisector x, L = lx, L' = lx tan(phi) / 2
        length = lx
        per_length = np.tan(frame.half_angle - 0.5 * rec["g"]) / (2 * ly)
    else:  # the bisector y, L = ly, L' = ly cot(phi) / 2
        length = ly
        per_length = 1.0 / (2 * lx * np.tan(frame.half_angle + 0.5 * rec["g"]))
    return n_chains * 2 * bond.k * (length / per_chain - bond.r0) * per_length


def _judge_identity(
    rec: dict[str, np.ndarray], analytic: np.ndarray, frame: PictureFrame
) -> tuple[list[Check], tuple, str]:
    """Virial F_N against pressure work, energy change and the law ``analytic`` (chunks,) nN/um.

    ``rec`` is the :func:`_shear` record. Returns the checks, the plot curves (angle deg, virial
    F_N, angle deg, energy F_N, law; each (chunks,), F_N in nN/um) and the note.
    """
    g = np.r_[0.0, rec["g"]]
    xy, lx, ly = (np.r_[rec[f"{k}_start"], rec[k]] for k in ("xy", "lx", "ly"))
    energy = np.r_[rec["energy_start"], rec["energy"]]
    lz = rec["lz"][0]
    nxx = -rec["pxx"] * lz if frame.kind == "stretch" else None
    work, fn_work = work_force(
        g, xy, lx if frame.kind == "stretch" else lx[0], ly, -rec["pxy"] * lz, -rec["pyy"] * lz, nxx
    )
    area = 0.5 * (lx[1:] + lx[:-1]) * 0.5 * (ly[1:] + ly[:-1])
    fn_energy = np.diff(energy) / (area * np.diff(g))
    loaded = np.abs(rec["fn"]) > 0.1 * np.abs(rec["fn"]).max()
    virial_vs_work = float(np.max(np.abs(fn_work[loaded] / rec["fn"][loaded] - 1)))
    chains = "diagonal chains" if frame == TILT else f"{_label(frame)} stretched chains"
    checks = [
        Check(
            CASE,
            f"{chains}: F_N work / F_N virial, worst interval",
            "F_N = dW / (lx ly dg)",
            1.0,
            1.0 + virial_vs_work,
            0.02,
        ),
        Check(
            CASE,
            f"{chains}: pressure work W / energy change dE",
            "W = dE (conservative)",
            float(energy[-1] - energy[0]),
            float(work.sum()),
            0.02,
        ),
        Check(
            CASE,
            f"{chains}: F_N virial at 20 deg",
            "F_N = n T / L" if frame.kind == "tilt" else "F_N = n T L' / (lx ly)",
            float(analytic[-1]),
            float(rec["fn"][-1]),
            0.02,
        ),
    ]
    note = (
        f"(b) {_label(frame)}, worst interval: virial vs pressure work {virial_vs_work:.2e},"
        f" virial vs energy {float(np.max(np.abs(fn_energy[loaded] / rec['fn'][loaded] - 1))):.2e};"
        f" kinetic energy / energy change at the end"
        f" {rec['kinetic'][-1] / (energy[-1] - energy[0]):.1e}."
    )
    curves = (np.degrees(rec["g"]), rec["fn"], np.degrees(rec["g"]), fn_energy, analytic)
    return checks, curves, note


def run(workdir: Path, full: bool = False) -> CaseResult:
    """Run case 5 in ``workdir``; returns its rows and plots."""
    folders = {TILT: "0_90", STRETCH: "45_positive", STRETCH_NEGATIVE: "45_negative"}
    zero = [_zero_force(workdir / f"frictionless_{f}", full, frame) for frame, f in folders.items()]
    folders = {
        TILT: "diagonal",
        TILT_NEGATIVE: "diagonal_negative",
        STRETCH: "bisector_45_positive",
        STRETCH_NEGATIVE: "bisector_45_negative",
    }
    identity = {frame: _identity(workdir / f, full, frame) for frame, f in folders.items()}
    g, fn, g2, fn_energy, analytic = identity[TILT][1]
    plots = [
        line_plot(
            workdir / "shear_zero.png",
            [curve for _, curve in zero],
            "shear angle g (deg)",
            "F_N / N0",
            "Case 5a: frictionless pretensioned cells",
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
        line_plot(
            workdir / "shear_senses.png",
            [
                (c[0], units.from_micro(y, "N_m"), f"{_label(frame)}: {what}")
                for frame, (_, c, _) in identity.items()
                for y, what in ((c[1], "virial"), (c[4], "law"))
            ],
            "shear angle g (deg)",
            "F_N (N/m)",
            "Case 5b: stretched chains, both senses of the 0/90 and +-45 frames",
            styles=["-", "--"] * len(identity),
        ),
    ]
    checks = [check for check, _ in zero] + [
        c for checks, _, _ in identity.values() for c in checks
    ]
    note = " ".join(note for _, _, note in identity.values())
    return CaseResult(CASE, checks, plots, note)
