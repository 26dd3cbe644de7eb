"""Picture-frame shear: the frame's box as a function of the shear angle, and the normalised
shear force against shear angle (pure numpy).

Kinematics (docs/shear.md): the box ``h = [[lx, xy], [0, ly]]`` follows one of two recipes
(:class:`PictureFrame`) of the shear angle g >= 0 in the sense s = +1 or -1. The normalised
picture-frame force is the power per unit current area per unit shear rate. From the virial
stress (``compute pressure NULL virial``, kPa) and the velocity gradient ``L = hdot h^-1``,
with the membrane forces ``N = -P lz`` and ``'`` = d/dg::

    F_N = Nxx lx'/lx + Nyy ly'/ly + Nxy (xy' - xy lx'/lx) / ly

Independently, from the work of the box on the cell over a recording interval,
``dW = Nxx ly dlx + Nyy lx dly + Nxy (lx dxy - xy dlx)`` and ``F_N = dW / (lx ly dg)``. Inputs
and outputs are in LAMMPS micro units (um, kPa; kPa um = nN/um = 1e-3 N/m).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "EXPERIMENT_FORCE_45DEG_N_PER_M",
    "FORCE_WINDOW",
    "PAPER_MODEL_FORCE_45DEG_N_PER_M",
    "SENSE_GROUPS",
    "PictureFrame",
    "ShearCurve",
    "work_force",
]

#: The results group (and scene) of each shear sense.
SENSE_GROUPS = {"positive": "shear", "negative": "shear_negative"}

#: Picture-frame experiment of the paper at 45 deg (N/m): frame side 175 mm, 100 mm/min, fibre
#: pretension 22 N/m, mean of 6 samples; "almost 50 times" the paper model's value.
EXPERIMENT_FORCE_45DEG_N_PER_M = 30.0
#: Largest F_N at 45 deg of the paper's digital-chain model (Abaqus/Explicit, 9 deg/s), N/m.
PAPER_MODEL_FORCE_45DEG_N_PER_M = 0.6


@dataclass(frozen=True)
class PictureFrame:
    """The box of a picture-frame shear as a function of the shear angle g (rad, >= 0).

    ``kind``: ``"tilt"`` (frame 0/90: edge a of length A stays along x, edge b of length B
    turns by s g: ``lx = A``, ``xy = s B sin g``, ``ly = B cos g``) or ``"stretch"`` (frame
    +phi0/-phi0: the box stays orthogonal and its fibres keep their lengths,
    ``lx = A cos(phi) / cos(phi0)``, ``ly = B sin(phi) / sin(phi0)``, ``phi = phi0 - s g / 2``).
    ``sense`` s = +1 (positive: the frame diagonal nearest x lengthens) or -1. ``half_angle``
    phi0 (rad): half the angle between the frame's fibres that contains x (pi/4 for 0/90).
    ``angles_deg``: the realised fibre angles of the frame.
    """

    kind: str
    sense: int
    half_angle: float
    angles_deg: tuple[float, float]

    @classmethod
    def tilt(cls, sense: int = 1) -> PictureFrame:
        """The 0/90 frame (the box tilts) in ``sense``."""
        return cls("tilt", sense, math.pi / 4, (0.0, 90.0))

    @classmethod
    def stretch(cls, half_angle_deg: float, sense: int = 1) -> PictureFrame:
        """The frame +phi0/-phi0 (deg; the box stretches) in ``sense``."""
        return cls(
            "stretch", sense, math.radians(half_angle_deg), (half_angle_deg, -half_angle_deg)
        )

    def box(self, g, a: float, b: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(lx, ly, xy) (um), each shaped like ``g``, of a box that starts as ``a`` x ``b``."""
        g = np.asarray(g, dtype=float)
        if self.kind == "tilt":
            return np.full_like(g, a), b * np.cos(g), self.sense * b * np.sin(g)
        phi, phi0 = self.half_angle - 0.5 * self.sense * g, self.half_angle
        return a * np.cos(phi) / math.cos(phi0), b * np.sin(phi) / math.sin(phi0), np.zeros_like(g)

    def box_rate(self, g, a: float, b: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(lx', ly', xy') = d(lx, ly, xy)/dg (um/rad), shaped like ``g``."""
        g = np.asarray(g, dtype=float)
        if self.kind == "tilt":
            return np.zeros_like(g), -b * np.sin(g), self.sense * b * np.cos(g)
        phi, phi0, half = self.half_angle - 0.5 * self.sense * g, self.half_angle, 0.5 * self.sense
        return (
            half * a * np.sin(phi) / math.cos(phi0),
            -half * b * np.cos(phi) / math.sin(phi0),
            (np.zeros_like(g)),
        )

    def force(self, g, a: float, b: float, nxx, nyy, nxy) -> np.ndarray:
        """Virial ``F_N`` (nN/um) from the membrane forces ``N = -P lz`` (nN/um) at angle g:
        the power per current area per shear rate, ``Nxx lx'/lx + Nyy ly'/ly + Nxy (xy' -
        xy lx'/lx) / ly``."""
        lx, ly, xy = self.box(g, a, b)
        dlx, dly, dxy = self.box_rate(g, a, b)
        return nxx * dlx / lx + nyy * dly / ly + nxy * (dxy - xy * dlx / lx) / ly


def work_force(angle, xy, lx, ly, nxy, nyy, nxx=None) -> tuple[np.ndarray, np.ndarray]:
    """Work of the box on the cell and work-based ``F_N`` per recording interval.

    ``dW = Nxx ly dlx + Nyy lx dly + Nxy (lx dxy - xy dlx)`` with lx, ly and xy the interval
    means of the box, and ``F_N = dW / (lx ly dg)``.

    Args:
        angle: (N + 1,) shear angle g at the start and at the end of each interval (rad).
        xy, lx, ly: (N + 1,) box tilt and edge lengths at the same instants (um); lx may be a
            scalar (a box that keeps its a edge).
        nxy, nyy: (N,) interval means of the membrane forces ``-Pxy lz``, ``-Pyy lz`` (nN/um).
        nxx: (N,) interval means of ``-Pxx lz`` (nN/um); needed when lx changes.

    Returns:
        (N,) work ``dW`` (pg um^2/us^2) and (N,) ``F_N`` (nN/um).
    """
    angle, xy, ly = (np.asarray(v, dtype=float) for v in (angle, xy, ly))
    lx = np.broadcast_to(np.asarray(lx, dtype=float), angle.shape)
    d_lx = np.diff(lx)
    if nxx is None and np.any(d_lx != 0.0):
        raise ValueError("work_force: lx changes, give nxx")
    lx, xy_mean = 0.5 * (lx[1:] + lx[:-1]), 0.5 * (xy[1:] + xy[:-1])
    ly_mean = 0.5 * (ly[1:] + ly[:-1])
    d_work = lx * (np.asarray(nxy) * np.diff(xy) + np.asarray(nyy) * np.diff(ly))
    if nxx is not None:
        d_work = d_work + (np.asarray(nxx) * ly_mean - np.asarray(nxy) * xy_mean) * d_lx
    return d_work, d_work / (lx * ly_mean * np.diff(angle))


FORCE_WINDOW = math.radians(2.0)
"""Width (rad) of the trailing window through which :meth:`ShearCurve.force_at` fits its line.
Past the lock the interval means (0.1 deg each at the default loading) swing by stick-slip:
on the coarse HPT 310 cell, single records near 45 deg moved F_N(45) by 8 % between loading
rates whose 2-deg lines agree within 1.6 % (docs/shear.md). On a convex curve the line is low by
``F'' window^2 / 12`` (0.2 % at 45 deg on that cell)."""


class ShearCurve:
    """Loading curve of a picture-frame shear; ``compute()`` then read the attributes.

    Args:
        angle: (N + 1,) shear angle g at the start and at the end of each interval (rad).
        xy, lx, ly: (N + 1,) box tilt and edge lengths at the same instants (um).
        force: (N,) interval means of the virial ``F_N`` (nN/um).
        nxy, nyy: (N,) interval means of the membrane forces ``-Pxy lz``, ``-Pyy lz`` (nN/um).
        kinetic: (N,) interval means of the kinetic energy (pg um^2/us^2).
        nxx: (N,) interval means of ``-Pxx lz`` (nN/um), for a box whose lx changes.

    After :meth:`compute` (all (N,), at the interval mid-angles): ``mid_angle`` (rad),
    ``force`` (virial, nN/um), ``force_work`` (work-based, nN/um), ``work`` (cumulative external
    work at each interval's end, pg um^2/us^2), ``kinetic_ratio`` (kinetic energy / work).
    """

    def __init__(self, angle, xy, lx, ly, force, nxy, nyy, kinetic, nxx=None):
        self.angle = np.asarray(angle, dtype=float)
        self.xy, self.lx, self.ly = (np.asarray(v, dtype=float) for v in (xy, lx, ly))
        self.force = np.asarray(force, dtype=float)
        self.nxy = np.asarray(nxy, dtype=float)
        self.nyy = np.asarray(nyy, dtype=float)
        self.kinetic = np.asarray(kinetic, dtype=float)
        self.nxx = None if nxx is None else np.asarray(nxx, dtype=float)

    def compute(self) -> ShearCurve:
        """Work-based force per interval, cumulative work and kinetic ratio."""
        d_work, self.force_work = work_force(
            self.angle, self.xy, self.lx, self.ly, self.nxy, self.nyy, self.nxx
        )
        self.mid_angle = 0.5 * (self.angle[1:] + self.angle[:-1])
        self.work = np.cumsum(d_work)
        with np.errstate(divide="ignore", invalid="ignore"):
            self.kinetic_ratio = self.kinetic / np.abs(self.work)
        return self

    def force_at(self, angle: float) -> float:
        """Virial ``F_N`` (nN/um) at ``angle`` (rad): the least-squares line through the interval
        means whose mid-angles lie in ``[angle - FORCE_WINDOW, angle]``, evaluated at ``angle``
        (linear interpolation where fewer than 3 lie there); NaN outside the record."""
        if len(self.mid_angle) == 0 or not self.angle[0] <= angle <= self.angle[-1]:
            return float("nan")
        inside = (self.mid_angle >= angle - FORCE_WINDOW) & (self.mid_angle <= angle)
        if np.count_nonzero(inside) < 3:
            return float(np.interp(angle, self.mid_angle, self.force))
        line = np.polyfit(self.mid_angle[inside] - angle, self.force[inside], 1)
        return float(line[1])

    def max_kinetic_ratio(self, from_angle: float) -> float:
        """Largest kinetic energy / external work once the angle has passed ``from_angle`` (rad)."""
        loaded = self.mid_angle >= from_angle
        return float(np.max(self.kinetic_ratio[loaded])) if np.any(loaded) else float("nan")
