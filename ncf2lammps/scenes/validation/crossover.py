"""Case 5, crossover springs: picture-frame shear of a 0/90 cell with torsional crossovers.

Law (docs/design.md §7): F_N is the power per unit current area per unit shear rate. A cell of ``n``
crossings, each a torsional spring ``E = K (theta - theta0)^2`` on the angle between its two
chains (theta0 = 90 deg), follows ``theta = 90 deg - g`` under ``a = La e_x, b = Lb (sin g,
cos g)``, so the stored energy is ``W = n K g^2``, the moment per crossing ``M = 2 K g`` and
``dW = n M dg``; dividing by the current area ``lx ly = La Lb cos g``:
``F_N = n M / (La Lb cos g) = 2 K g / (p^2 cos g)`` (``p^2 = La Lb / n``, area per crossing at
g = 0). Chain tension adds nothing (case 5a: the chains keep their lengths).

Configuration: a 3 x 3 lattice of closed carbon chains (d = 69 um, s = d/2, E 240 GPa, no
pretension), 0-deg chains along x and 90-deg chains along y in one plane, pitch p = 5 s, cell
3p x 3p; each crossing is one bead shared by both chains (the 90-deg chains are bonded through
it). Each crossing carries one ``angle_style harmonic`` angle (atom_style ``hybrid sphere
angle``; angles made in the deck with ``create_bonds single/angle``) from the next crossing
along +a, through the crossing, to the next crossing along +b, so it measures the angle between
the chains and its arms are the straight chain segments; ``K = 5e-8 J/rad^2`` (torsional
stiffness ``2K = 1e-7 N m/rad``). Every crossing is equivalent under the lattice translations,
so the angle forces cancel on every bead and the cell shears exactly affinely (no kinetic
energy, no contacts: ``pair_style zero``), so a constant shear rate from rest is harmless.
Sheared to 40.5 deg in recording intervals of 0.5 deg (0.25 deg in the full form) of 100 time
steps each, ``fix deform ... remap x``. The virial F_N at 10, 20, 30, 40 deg is read after a
``run 0`` (the forces of a time step are computed before fix deform moves the box, so they lag
it by one step) and compared with the law at the angle of the box, ``atan2(xy, ly)``. The work
F_N there is the pressure work ``-lx lz (Pxy dxy + Pyy dly)`` over the two intervals around the
angle divided by ``lx ly 2 dg`` (pressures averaged over each interval, so lagging the box by
one time step: about -1e-4 at 10 deg). Table values are in nN/um (1 N/m = 1000 nN/um).

Tolerance: 1 % on the virial and the work F_N against the law at each angle and on the angle
energy at 40 deg; 2 % between virial and work F_N on every interval (as case 5b).
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np

from ... import units
from ...analysis.shear import PictureFrame, work_force
from ...model import Model
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

__all__ = ["analytic_fn", "lattice", "run"]

CASE = "5 shear, crossover springs"
#: Crossover torsional stiffness 2K (N m/rad) and the angles judged (deg).
TORSION = 1.0e-7
ANGLES = (10.0, 20.0, 30.0, 40.0)


def analytic_fn(g: np.ndarray, angle_k: float, pitch: float) -> np.ndarray:
    """Law: ``F_N = 2 K g / (p^2 cos g)`` (nN/um) for K (fJ/rad^2), pitch p (um), g (rad)."""
    g = np.asarray(g, dtype=float)
    return 2.0 * angle_k * g / (pitch**2 * np.cos(g))


def lattice(n: int, per_pitch: int, spacing: float) -> tuple[Model, list[tuple[int, int, int]]]:
    """The n x n crossing lattice of closed 0/90 chains and its angles (1-based atom ids).

    ``per_pitch`` bonds of length ``spacing`` (um) join consecutive crossings; crossing (j, k)
    sits at ``((k + 1/2) p, (j + 1/2) p)`` and is bead ``per_pitch k`` of 0-deg chain j.
    Returns the model and one (end +a, crossing, end +b) triple per crossing.
    """
    pitch = per_pitch * spacing
    frame = n * pitch
    atom, bond, density = fibre("ply", D, spacing, E_CARBON, RHO_CARBON)
    chains = ChainSet()
    chains.add_type(atom, bond, density)
    along = (np.arange(n * per_pitch) + 0.5 * per_pitch) * spacing % frame
    rows = [
        chains.add(
            np.column_stack([along, np.full_like(along, (j + 0.5) * pitch), 0 * along]), 0, True
        )
        for j in range(n)
    ]
    crossing = np.stack([r[::per_pitch] for r in rows])  # (j, k) -> 0-based bead index
    inner = along[np.arange(len(along)) % per_pitch != 0]
    segments = []
    for k in range(n):
        x = (k + 0.5) * pitch
        for j in range(n):
            y = inner[j * (per_pitch - 1) : (j + 1) * (per_pitch - 1)]
            seg = chains.add(np.column_stack([np.full_like(y, x), y, 0 * y]), 0, False)
            # bond crossing (j, k) -> first inner bead, last inner bead -> crossing (j + 1, k)
            segments.append([[crossing[j, k], seg[0]], [seg[-1], crossing[(j + 1) % n, k]]])
    model = chains.model([0.0, 0.0, -3 * D], [frame, frame, 3 * D])
    extra = np.asarray(segments, dtype=np.int64).reshape(-1, 2)
    bonds = np.concatenate([model.bonds, extra])
    model = replace(model, bonds=bonds, bond_type=np.zeros(len(bonds), dtype=np.int64))
    j, k = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    triples = np.stack([crossing[j, (k + 1) % n], crossing[j, k], crossing[(j + 1) % n, k]], -1)
    return model, [tuple(int(i) + 1 for i in t) for t in triples.reshape(-1, 3)]


def _shear(
    workdir: Path,
    model: Model,
    angles: list[tuple[int, int, int]],
    angle_k: float,
    pitch: float,
    frame: float,
    step_deg: float,
) -> tuple[dict[str, float], dict[str, np.ndarray]]:
    """Shear the cell to ``ANGLES[-1] + step_deg`` in intervals of ``step_deg`` (deg).

    ``angle_k`` is K (fJ/rad^2), ``pitch`` and ``frame`` (um) the crossing pitch and cell edge.
    Returns the box at rest (``xy``, ``ly``, ``lx``, ``lz``, um) and the (chunks,) records per
    interval: ``fn_avg``, ``pxy``, ``pyy`` (interval averages: F_N nN/um, pressures kPa), and at
    its end ``fn`` (virial F_N after ``run 0``), ``xy``, ``ly`` (um), ``pe``, ``ke`` (angle and
    kinetic energy, pg um^2/us^2).
    """
    mass = float(model.mass[0])
    k_bond = model.bond_types[0].k
    dt = 0.5 * math.sqrt(mass / (2 * k_bond))
    chunk = 100
    chunks = round((ANGLES[-1] + step_deg) / step_deg)
    rate = math.radians(step_deg) / (chunk * dt)
    values = {
        "angles": angles,
        "angle_k": angle_k,
        "ghost_cutoff": 1.3 * pitch,
        "rate": rate,
        "frame": PictureFrame.tilt(),
        "edge": frame,
        "chunk": chunk,
    }
    law = contact(units.to_micro(1.0e5, "N_m"), mass, 0.0)
    rec = {k: np.empty(chunks) for k in ("fn_avg", "pxy", "pyy", "fn", "xy", "ly", "pe", "ke")}
    with lammps_case(workdir, "validation/crossover.lmp.j2", model, dt, law, **values) as lmp:
        start = {k: lmp.variable(f"box_{k}") for k in ("xy", "ly", "lx", "lz")}
        for i in range(chunks):
            lmp.command("variable g0 equal $(v_g:%.17g)")
            lmp.command(f"run {chunk}")
            rec["fn_avg"][i], rec["pxy"][i], rec["pyy"][i] = lmp.fix_vector("record", 3)
            lmp.command("run 0")  # forces of the step lag the box by one step: recompute them
            rec["fn"][i] = lmp.variable("fn")
            rec["xy"][i], rec["ly"][i] = lmp.variable("box_xy"), lmp.variable("box_ly")
            rec["pe"][i] = lmp.variable("energy") - lmp.variable("kinetic")
            rec["ke"][i] = lmp.variable("kinetic")
    return start, rec


def _angle_checks(
    g: np.ndarray,
    lx: float,
    ly: np.ndarray,
    work: np.ndarray,
    fn: np.ndarray,
    angle_k: float,
    pitch: float,
    step_deg: float,
) -> tuple[list[Check], list[tuple[float, float, float, float]]]:
    """Virial and work F_N against the law at each of :data:`ANGLES`.

    ``g`` (chunks + 1,) rad and ``ly`` (chunks + 1,) um are the box angle and height at rest and
    at each interval end, ``lx`` (um) the box length, ``work`` (chunks,) the pressure work per
    interval (pg um^2/us^2), ``fn`` (chunks,) the virial F_N at each interval end (nN/um).
    Returns the checks and one row (angle deg, law, virial, work F_N, nN/um) per angle.
    """
    checks = []
    table = []
    for angle in ANGLES:
        i = round(angle / step_deg)  # step end i sits at the angle (index into g)
        expected = float(analytic_fn(g[i], angle_k, pitch))
        virial = float(fn[i - 1])
        fn_work = float((work[i - 1] + work[i]) / (lx * ly[i] * (g[i + 1] - g[i - 1])))
        table.append((math.degrees(g[i]), expected, virial, fn_work))
        for what, value in (("virial", virial), ("work", fn_work)):
            checks.append(
                Check(
                    CASE,
                    f"F_N {what} at {angle:g} deg",
                    "F_N = 2 K g / (p^2 cos g)",
                    expected,
                    value,
                    0.01,
                )
            )
    return checks, table


def _plot(
    workdir: Path,
    g: np.ndarray,
    fn: np.ndarray,
    fn_work_step: np.ndarray,
    angle_k: float,
    pitch: float,
) -> Path:
    """Plot virial F_N (chunks,) at the interval ends and work F_N (chunks,) at their middles
    (nN/um, drawn in N/m) against the box angle ``g`` (chunks + 1,) rad, with the law."""
    to_n_m = units.from_micro(1.0, "N_m")
    deg = np.degrees(g[1:])
    mid = np.degrees(0.5 * (g[1:] + g[:-1]))
    return line_plot(
        workdir / "shear_crossover.png",
        [
            (deg, fn * to_n_m, "virial -(Pxy - Pyy xy/ly) lz"),
            (mid, fn_work_step * to_n_m, "dW / (lx ly dg)"),
            (deg, analytic_fn(g[1:], angle_k, pitch) * to_n_m, "2 K g / (p^2 cos g)"),
        ],
        "shear angle g (deg)",
        "F_N (N/m)",
        "Case 5c: 0/90 cell with torsional crossover springs",
        styles=["-", "o", "--"],
    )


def run(workdir: Path, full: bool = False) -> CaseResult:
    """Run the crossover-spring shear in ``workdir``; returns its rows and plot."""
    n, per_pitch, spacing = 3, 5, D / 2
    pitch, frame = per_pitch * spacing, n * per_pitch * spacing
    model, angles = lattice(n, per_pitch, spacing)
    angle_k = units.to_micro(TORSION / 2.0, "J")
    step_deg = 0.25 if full else 0.5
    start, rec = _shear(workdir, model, angles, angle_k, pitch, frame, step_deg)
    lx, lz = start["lx"], start["lz"]
    xy, ly = np.r_[start["xy"], rec["xy"]], np.r_[start["ly"], rec["ly"]]
    g = np.arctan2(xy, ly)  # box angle at 0 and at each step end
    work, fn_work_step = work_force(g, xy, lx, ly, -rec["pxy"] * lz, -rec["pyy"] * lz)
    loaded = np.abs(rec["fn_avg"]) > 0.1 * np.abs(rec["fn_avg"]).max()
    worst = float(np.max(np.abs(fn_work_step[loaded] / rec["fn_avg"][loaded] - 1)))
    checks, table = _angle_checks(g, lx, ly, work, rec["fn"], angle_k, pitch, step_deg)
    i_end = round(ANGLES[-1] / step_deg)
    checks.append(
        Check(
            CASE,
            f"angle energy at {ANGLES[-1]:g} deg",
            "E = n K g^2",
            float(len(angles) * angle_k * g[i_end] ** 2),
            float(rec["pe"][i_end - 1]),
            0.01,
        )
    )
    checks.append(
        Check(
            CASE,
            "F_N work / F_N virial, worst interval",
            "F_N = dW / (lx ly dg)",
            1.0,
            1.0 + worst,
            0.02,
        )
    )
    to_n_m = units.from_micro(1.0, "N_m")
    note = (
        "F_N (N/m) at angle (deg): analytic / virial / work: "
        + "; ".join(
            f"{a:.2f}: {e * to_n_m:.5g} / {v * to_n_m:.5g} / {w * to_n_m:.5g}"
            for a, e, v, w in table
        )
        + f". Worst interval virial vs work {worst:.1e}; max kinetic / angle energy"
        f" {float(np.max(rec['ke']) / rec['pe'][-1]):.1e}."
    )
    plot = _plot(workdir, g, rec["fn"], fn_work_step, angle_k, pitch)
    return CaseResult(CASE, checks, [plot], note)
