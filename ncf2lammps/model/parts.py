"""Parts of a bead model and the one join that assembles them into a :class:`Model`.

A part is a group of chains with its own type tables; its indices (beads, molecules, types) are
local and count from 0. :func:`join` offsets them and concatenates the parts in order.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .core import AngleType, AtomType, BondType, Box, Model

__all__ = ["Part", "join"]


@dataclass(frozen=True, eq=False)
class Part:
    """Chains of beads with local indices (um, pg/um^3).

    Attributes:
        positions: (n, 3) float, bead centres (um).
        type_id: (n,) int, index into :attr:`atom_types`.
        density: (n,) float, bead densities (pg/um^3).
        mol_id: (n,) int, chain of each bead, 0 to ``n_chains - 1``.
        bonds: (m, 2) int, bead indices into :attr:`positions`.
        bond_type: (m,) int, index into :attr:`bond_types`.
        atom_types, bond_types: the part's type tables.
        fibre_volume: cylinder-equivalent fibre volume the part adds to the model (um^3).
        angles: (a, 3) int, bead indices (end, vertex, end); angle_type: (a,) int, index into
            :attr:`angle_types`.
        needle_points: (p, 2) float, needle hole centres (x, y) (um); needle_diameter (um).
        bead_diameter: (n,) float, bead diameters (um) where they vary within a type (a
            diameter spread); None: each bead has its type's diameter.
    """

    positions: np.ndarray
    type_id: np.ndarray
    density: np.ndarray
    mol_id: np.ndarray
    bonds: np.ndarray
    bond_type: np.ndarray
    atom_types: tuple[AtomType, ...]
    bond_types: tuple[BondType, ...]
    fibre_volume: float = 0.0
    angles: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), dtype=np.int64))
    angle_type: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    angle_types: tuple[AngleType, ...] = ()
    needle_points: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    needle_diameter: float = 0.0
    bead_diameter: np.ndarray | None = None

    @property
    def n_chains(self) -> int:
        """Number of chains (molecules)."""
        return int(self.mol_id.max()) + 1 if len(self.mol_id) else 0

    @property
    def diameter(self) -> np.ndarray:
        """(n,) bead diameters (um): :attr:`bead_diameter`, else the atom types'."""
        if self.bead_diameter is not None:
            return self.bead_diameter
        return np.array([t.diameter for t in self.atom_types])[self.type_id]


def _offsets(sizes) -> np.ndarray:
    """(k,) start of each of k consecutive blocks of the given sizes."""
    return np.cumsum([0, *sizes])[:-1]


def _stacked(parts: Sequence[Part], name: str, sizes) -> np.ndarray:
    """One index field of every part, each shifted by its part's offset, concatenated."""
    return np.concatenate(
        [getattr(p, name) + o for p, o in zip(parts, _offsets(sizes), strict=True)]
    )


def join(
    parts: Sequence[Part],
    box: Box,
    *,
    mat_thickness: float,
    faces_z: tuple[float, float],
    angle_style: str = "none",
) -> Model:
    """The model of the parts in order, in ``box``.

    Bead, molecule and type indices of each part are shifted past those of the parts before it;
    the type tables are concatenated; diameters are the parts' (:attr:`Part.diameter`); fibre volumes add up,
    needle holes are concatenated and the needle diameter is the largest. ``mat_thickness``
    (um), ``faces_z`` (bottom, top, um) and ``angle_style`` (LAMMPS style of the angle types,
    ``"none"`` without angles) are the model's. ``parts``: one at least.
    """
    beads = [len(p.positions) for p in parts]
    atom_types = tuple(t for p in parts for t in p.atom_types)
    type_id = _stacked(parts, "type_id", [len(p.atom_types) for p in parts])
    return Model(
        positions=np.concatenate([p.positions for p in parts]),
        diameter=np.concatenate([p.diameter for p in parts]),
        density=np.concatenate([p.density for p in parts]),
        type_id=type_id,
        mol_id=_stacked(parts, "mol_id", [p.n_chains for p in parts]),
        bonds=_stacked(parts, "bonds", beads),
        bond_type=_stacked(parts, "bond_type", [len(p.bond_types) for p in parts]),
        atom_types=atom_types,
        bond_types=tuple(t for p in parts for t in p.bond_types),
        box=box,
        mat_thickness=mat_thickness,
        fibre_volume=sum((p.fibre_volume for p in parts), 0.0),
        needle_points=np.concatenate([p.needle_points for p in parts]),
        needle_diameter=max(p.needle_diameter for p in parts),
        faces_z=faces_z,
        angles=_stacked(parts, "angles", beads),
        angle_type=_stacked(parts, "angle_type", [len(p.angle_types) for p in parts]),
        angle_types=tuple(t for p in parts for t in p.angle_types),
        angle_style=angle_style,
    )
