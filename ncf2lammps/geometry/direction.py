"""Ply directions in the periodic cell: lattice vectors and the strip their chains tile (numpy).

A straight line closes on itself in the periodic cell ``Lx x Ly`` when its direction is a lattice
vector ``v = (a Lx, b Ly)`` with coprime integers ``a >= 0`` and ``b`` (``b = 1`` when ``a = 0``).
Its periodic images then repeat across the cell every ``w = Lx Ly / |v|`` along the normal
``n``: the cell is tiled by one strip of width ``w`` and length ``|v|``, in which a ply's chains
are laid as in a cell of edge ``|v|`` along the fibres and ``w`` across (:mod:`.mat`). The
realised angles ``atan(b Ly / (a Lx))`` are dense, so most requested angles are met within a
small tolerance by a short lattice vector; the shortest one is taken (the widest strip).

0 deg is ``(1, 0)`` (along x, ``n`` = +y) and 90 deg is ``(0, 1)`` (along y, ``n`` = +x): the
paper's plies, computed without rounding.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import units
from ..spec import SpecError
from .bundle import chain_fill

__all__ = [
    "DIAMETER_TOLERANCE",
    "PlyDirection",
    "lattice_direction",
    "ply_direction",
    "spec_ply_direction",
]


@dataclass(frozen=True)
class PlyDirection:
    """A ply's chain direction in the cell (lengths um).

    Attributes:
        lattice: (a, b), the direction ``(a Lx, b Ly)``.
        angle_deg: realised angle from x, in (-90, 90].
        along: (2,) unit vector of the chains, ``t``.
        across: (2,) unit normal ``n``: ``(-t_y, t_x)``, (1, 0) at 90 deg.
        chain_length: ``|v|``, the length of one closed straight chain.
        period: ``w = Lx Ly / |v|``, the spacing of the chain's periodic images along ``n``.
    """

    lattice: tuple[int, int]
    angle_deg: float
    along: np.ndarray
    across: np.ndarray
    chain_length: float
    period: float

    @property
    def edges_crossed(self) -> int:
        """Cell edges one chain crosses before it closes, ``a + |b|``: its waviness carries
        that many times ``mat.waviness_waves_per_cell`` waves."""
        return self.lattice[0] + abs(self.lattice[1])

    def place(self, along: np.ndarray, across: np.ndarray) -> np.ndarray:
        """(..., 2) in-plane positions ``along t + across n`` (um) of strip coordinates."""
        along, across = np.asarray(along, dtype=float), np.asarray(across, dtype=float)
        return along[..., None] * self.along + across[..., None] * self.across


def lattice_direction(lattice: tuple[int, int], cell: tuple[float, float]) -> PlyDirection:
    """The :class:`PlyDirection` of lattice vector ``(a, b)`` in a cell ``(Lx, Ly)`` (um)."""
    a, b = lattice
    vector = np.array([a * cell[0], b * cell[1]], dtype=float)
    length = float(np.hypot(*vector))
    along = vector / length
    across = np.array([1.0, 0.0]) if a == 0 else np.array([-along[1], along[0]])
    angle = float(np.degrees(np.arctan2(vector[1], vector[0])))
    return PlyDirection((a, b), angle, along, across, length, cell[0] * cell[1] / length)


def _candidates(cell: tuple[float, float], min_period: float, angle_deg: float) -> np.ndarray:
    """(K, 2) coprime lattice pairs (a >= 0) near ``angle_deg`` whose strip is at least
    ``min_period`` (um) wide, i.e. ``|v| <= Lx Ly / min_period``: for every a the two b on
    either side of the line at the angle, and for every b the two a (O(cell / min_period))."""
    longest = cell[0] * cell[1] / min_period
    a_max, b_max = int(longest // cell[0]), int(longest // cell[1])
    slope = np.tan(np.radians(angle_deg)) * cell[0] / cell[1]  # b / a on the line
    a = np.arange(a_max + 1)
    b = np.arange(-b_max, b_max + 1)
    b_of_a = np.clip(np.floor(a * slope), -b_max - 1, b_max)[:, None] + np.array([0.0, 1.0])
    with np.errstate(over="ignore", divide="ignore"):
        a_of_b = np.clip(np.floor(b / slope), -1, a_max)[:, None] + np.array([0.0, 1.0])
    pairs = np.vstack(
        [
            np.column_stack([np.repeat(a, 2), b_of_a.ravel()]),
            np.column_stack([a_of_b.ravel(), np.repeat(b, 2)]),
        ]
    ).astype(np.int64)
    a, b = pairs.T
    keep = (a >= 0) & (np.abs(b) <= b_max) & (np.gcd(a, b) == 1) & ((a > 0) | (b == 1))
    keep &= np.hypot(a * cell[0], b * cell[1]) <= longest
    return np.unique(pairs[keep], axis=0)


#: Largest change of a ply's chain diameter from the nominal one that its strip may force: the
#: strip holds a whole number of chains of the ply's fibre cross-section (docs/manufacture.md).
DIAMETER_TOLERANCE = 0.05


def ply_direction(
    angle_deg: float,
    cell: tuple[float, float],
    tolerance_deg: float,
    chains_per_width: float,
    diameter: float,
    field: str,
) -> PlyDirection:
    """The shortest lattice direction within ``tolerance_deg`` of ``angle_deg`` whose strip
    holds whole chains; a SpecError on ``field`` naming the nearest achievable angles if none.

    A strip of width ``w`` (um) carries ``n = chains_per_width w`` nominal chains of diameter
    ``diameter`` (um); it is accepted when ``round(n) >= 1`` chains of the same fibre
    cross-section, of diameter ``diameter sqrt(n / round(n))``, differ from the nominal by at
    most :data:`DIAMETER_TOLERANCE` and fit across the strip.
    """
    if angle_deg == 0.0:
        return lattice_direction((1, 0), cell)
    if angle_deg == 90.0:
        return lattice_direction((0, 1), cell)
    pairs = _candidates(cell, diameter, angle_deg)
    lengths = np.hypot(pairs[:, 0] * cell[0], pairs[:, 1] * cell[1])
    period = cell[0] * cell[1] / lengths
    exact = chains_per_width * period
    scale = np.sqrt(exact / np.maximum(1.0, np.rint(exact)))
    whole = (np.abs(scale - 1.0) <= DIAMETER_TOLERANCE) & (period >= scale * diameter)
    pairs, lengths = pairs[whole], lengths[whole]
    angles = np.degrees(np.arctan2(pairs[:, 1] * cell[1], pairs[:, 0] * cell[0]))
    miss = np.abs((angles - angle_deg + 90.0) % 180.0 - 90.0)
    within = np.flatnonzero(miss <= tolerance_deg)
    if len(within) == 0:
        offers = ", ".join(f"{a:.4g}" for a in angles[np.argsort(miss, kind="stable")[:3]])
        raise SpecError(
            field,
            angle_deg,
            f"no chain direction closing in the {cell[0] / 1e3:g} x {cell[1] / 1e3:g} mm cell"
            f" lies within mat.angle_tolerance_deg {tolerance_deg:g} with a strip of whole"
            f" chains ({100 * DIAMETER_TOLERANCE:g} % on the diameter); nearest achievable"
            f" angles (deg): {offers or 'none'} (raise mat.angle_tolerance_deg, change"
            " discretisation.chain_diameter_um, or make the cell a multiple of the repeat)",
        )
    best = within[np.lexsort((miss[within], lengths[within]))[0]]
    return lattice_direction((int(pairs[best, 0]), int(pairs[best, 1])), cell)


def spec_ply_direction(spec, index: int) -> PlyDirection:
    """The :class:`PlyDirection` of ply ``index`` of a :class:`~ncf2lammps.spec.FabricSpec`."""
    ply = spec.plies[index]
    cell = tuple(units.to_micro(v, "mm") for v in spec.cell_mm)
    diameter = spec.discretisation.chain_diameter_um
    fibre_per_width = units.to_micro(ply.areal_weight_g_m2, "g_m2") / units.to_micro(
        ply.density_g_cm3, "g_cm3"
    )
    nominal = chain_fill(spec) * np.pi * diameter**2 / 4.0
    return ply_direction(
        ply.angle_deg,
        cell,
        spec.mat.angle_tolerance_deg,
        fibre_per_width / nominal,
        diameter,
        f"ply[{index}].angle_deg",
    )
