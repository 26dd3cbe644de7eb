"""Picture-frame shear curves: normalised shear force against shear angle (pure numpy).

Kinematics (docs/design.md §7): edge a = La e_x, edge b = Lb (sin g, cos g), so ``xy = Lb sin g``,
``ly = Lb cos g``. The normalised picture-frame force is the power per unit current area per
unit shear rate, from the virial stress (``compute pressure NULL virial``, kPa):
``F_N = -(Pxy - Pyy xy / ly) lz``; independently, from the work of the box on the cell over a
recording interval, ``dW = -lx lz (Pxy dxy + Pyy dly) = lx (Nxy dxy + Nyy dly)`` with the
membrane forces ``N = -P lz``, and ``F_N = dW / (lx ly dg)``. Inputs and outputs are in LAMMPS
micro units (um, kPa; kPa um = nN/um = 1e-3 N/m).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "EXPERIMENT_FORCE_45DEG_N_PER_M",
    "PAPER_MODEL_FORCE_45DEG_N_PER_M",
    "ShearCurve",
    "work_force",
]

#: Picture-frame experiment of the paper at 45 deg (N/m): frame side 175 mm, 100 mm/min, fibre
#: pretension 22 N/m, mean of 6 samples; "almost 50 times" the paper model's value.
EXPERIMENT_FORCE_45DEG_N_PER_M = 30.0
#: Largest F_N at 45 deg of the paper's digital-chain model (Abaqus/Explicit, 9 deg/s), N/m.
PAPER_MODEL_FORCE_45DEG_N_PER_M = 0.6


def work_force(angle, xy, lx, ly, nxy, nyy) -> tuple[np.ndarray, np.ndarray]:
    """Work of the box on the cell and work-based ``F_N`` per recording interval.

    ``dW = lx (Nxy dxy + Nyy dly)`` with lx and ly the interval means of the edge lengths, and
    ``F_N = dW / (lx ly dg)``.

    Args:
        angle: (N + 1,) shear angle g at the start and at the end of each interval (rad).
        xy, lx, ly: (N + 1,) box tilt and edge lengths at the same instants (um); lx may be a
            scalar (a box that keeps its a edge).
        nxy, nyy: (N,) interval means of the membrane forces ``-Pxy lz``, ``-Pyy lz`` (nN/um).

    Returns:
        (N,) work ``dW`` (pg um^2/us^2) and (N,) ``F_N`` (nN/um).
    """
    angle, xy, ly = (np.asarray(v, dtype=float) for v in (angle, xy, ly))
    lx = np.broadcast_to(np.asarray(lx, dtype=float), angle.shape)
    lx = 0.5 * (lx[1:] + lx[:-1])
    area = lx * 0.5 * (ly[1:] + ly[:-1])
    d_work = lx * (np.asarray(nxy) * np.diff(xy) + np.asarray(nyy) * np.diff(ly))
    return d_work, d_work / (area * np.diff(angle))


class ShearCurve:
    """Loading curve of a picture-frame shear; ``compute()`` then read the attributes.

    Args:
        angle: (N + 1,) shear angle g at the start and at the end of each interval (rad).
        xy, lx, ly: (N + 1,) box tilt and edge lengths at the same instants (um).
        force: (N,) interval means of the virial ``F_N`` (nN/um).
        nxy, nyy: (N,) interval means of the membrane forces ``-Pxy lz``, ``-Pyy lz`` (nN/um).
        kinetic: (N,) interval means of the kinetic energy (pg um^2/us^2).

    After :meth:`compute` (all (N,), at the interval mid-angles): ``mid_angle`` (rad),
    ``force`` (virial, nN/um), ``force_work`` (work-based, nN/um), ``work`` (cumulative external
    work at each interval's end, pg um^2/us^2), ``kinetic_ratio`` (kinetic energy / work).
    """

    def __init__(self, angle, xy, lx, ly, force, nxy, nyy, kinetic):
        self.angle = np.asarray(angle, dtype=float)
        self.xy, self.lx, self.ly = (np.asarray(v, dtype=float) for v in (xy, lx, ly))
        self.force = np.asarray(force, dtype=float)
        self.nxy = np.asarray(nxy, dtype=float)
        self.nyy = np.asarray(nyy, dtype=float)
        self.kinetic = np.asarray(kinetic, dtype=float)

    def compute(self) -> ShearCurve:
        """Work-based force per interval, cumulative work and kinetic ratio."""
        d_work, self.force_work = work_force(
            self.angle, self.xy, self.lx, self.ly, self.nxy, self.nyy
        )
        self.mid_angle = 0.5 * (self.angle[1:] + self.angle[:-1])
        self.work = np.cumsum(d_work)
        with np.errstate(divide="ignore", invalid="ignore"):
            self.kinetic_ratio = self.kinetic / np.abs(self.work)
        return self

    def force_at(self, angle: float) -> float:
        """Virial ``F_N`` (nN/um) interpolated at ``angle`` (rad); NaN outside the record."""
        if len(self.mid_angle) == 0 or not self.angle[0] <= angle <= self.angle[-1]:
            return float("nan")
        return float(np.interp(angle, self.mid_angle, self.force))

    def max_kinetic_ratio(self, from_angle: float) -> float:
        """Largest kinetic energy / external work once the angle has passed ``from_angle`` (rad)."""
        loaded = self.mid_angle >= from_angle
        return float(np.max(self.kinetic_ratio[loaded])) if np.any(loaded) else float("nan")
