"""The bead model's types and the immutable :class:`Model` (LAMMPS ``micro`` units, 0-based)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["AngleType", "AtomType", "BondType", "Box", "Model"]


@dataclass(frozen=True)
class AtomType:
    """A bead type: one per ply, one for the stitch yarn.

    Attributes: name; role ``"fibre"`` or ``"stitch"``; diameter (um); material density
    (pg/um^3); axial modulus E (kPa); ``angle_deg``: the realised angle from x of a ply's
    chains (0: along x, 90: along y; None for the stitch); ``fill``: fibre (or yarn) volume
    fraction inside the chain, so that its fibre cross-section is ``fill pi d^2 / 4`` (above 1
    for a flattened stitch yarn, whose beads are thinner than the round yarn);
    ``lattice``: the ply's chain direction ``(a Lx, b Ly)`` as ``(a, b)`` (geometry/direction.py).
    """

    name: str
    role: str
    diameter: float
    density: float
    modulus: float
    angle_deg: float | None = None
    fill: float = 1.0
    lattice: tuple[int, int] | None = None


@dataclass(frozen=True)
class BondType:
    """A harmonic bond type ``E = K (r - r0)^2`` with ``K = E A / (2 r0)``.

    Attributes: name; role ``"fibre"`` or ``"stitch"``; ``k`` = LAMMPS K (nN/um); ``r0`` (um);
    ``axial_stiffness`` = E A (nN).
    """

    name: str
    role: str
    k: float
    r0: float
    axial_stiffness: float


@dataclass(frozen=True)
class AngleType:
    """A bending angle type along fibre chains (docs/fidelity.md).

    ``angle_style harmonic``: ``E = K (theta - theta0)^2``, ``K = EI / (2 s)``; ``cosine``:
    ``E = K (1 + cos theta)``, ``K = EI / s`` (rest at 180 deg). Attributes: name; role;
    ``k`` = LAMMPS K (energy, pg um^2/us^2); ``theta0`` (deg); ``bending_stiffness`` = EI
    (nN um^2); ``spacing`` = the chain length per vertex bead s (um).
    """

    name: str
    role: str
    k: float
    theta0: float
    bending_stiffness: float
    spacing: float


@dataclass(frozen=True)
class Box:
    """Triclinic periodic box: ``lo``, ``hi`` (3,) um and tilt factors ``(xy, xz, yz)`` um."""

    lo: np.ndarray
    hi: np.ndarray
    tilt: np.ndarray

    @property
    def lengths(self) -> np.ndarray:
        """(3,) edge lengths ``hi - lo``, um."""
        return self.hi - self.lo

    @property
    def matrix(self) -> np.ndarray:
        """(3, 3) edge vectors of the cell as columns, ``h`` (um)."""
        (lx, ly, lz), (xy, xz, yz) = self.lengths, self.tilt
        return np.array([[lx, xy, xz], [0.0, ly, yz], [0.0, 0.0, lz]])

    def fractional(self, points: np.ndarray) -> np.ndarray:
        """(N, 3) fractional coordinates ``h^-1 (x - lo)`` of the (N, 3) ``points`` (um)."""
        return np.linalg.solve(self.matrix, (np.asarray(points) - self.lo).T).T

    def minimum_image(self, delta: np.ndarray) -> np.ndarray:
        """(N, 3) nearest periodic images of the (N, 3) differences ``delta`` (um): the box is
        periodic in x and y (any tilt), not in z."""
        step = np.linalg.solve(self.matrix, np.asarray(delta, dtype=float).T).T
        step[:, :2] -= np.rint(step[:, :2])
        return step @ self.matrix.T


def _frozen(array, dtype) -> np.ndarray:
    out = np.ascontiguousarray(array, dtype=dtype)
    out.setflags(write=False)
    return out


@dataclass(frozen=True, eq=False)
class Model:
    """Beads, bonds, types and box of one cell; arrays are read-only.

    Attributes:
        positions: (N, 3) float, bead centres wrapped into the box in x and y (um).
        diameter: (N,) float, bead diameters (um).
        density: (N,) float, bead densities giving the cylinder-equivalent mass (pg/um^3).
        type_id: (N,) int, index into :attr:`atom_types`.
        mol_id: (N,) int, chain index (every fibre chain and every stitch yarn is one molecule).
        bonds: (M, 2) int, bead indices.
        bond_type: (M,) int, index into :attr:`bond_types`.
        atom_types, bond_types: the type tables.
        box: the periodic cell (z is the non-periodic thickness direction).
        mat_thickness: thickness of the homogeneous mat ``sum A / (Vf rho)`` (um).
        fibre_volume: cylinder-equivalent volume of all fibre chains (um^3).
        needle_points: (P, 2) float, needle hole centres (x, y) (um); empty without stitch.
        needle_diameter: diameter of the needles (um); 0 without stitch.
        faces_z: (bottom, top) heights of the stitch underlap and loop faces (um).
        angles: (A, 3) int, bead indices (end, vertex, end) of bending angles; empty unless
            ``discretisation.bending`` is on.
        angle_type: (A,) int, index into :attr:`angle_types`.
        angle_types: the angle type table; ``angle_style`` its LAMMPS style (``"none"``: none).
    """

    positions: np.ndarray
    diameter: np.ndarray
    density: np.ndarray
    type_id: np.ndarray
    mol_id: np.ndarray
    bonds: np.ndarray
    bond_type: np.ndarray
    atom_types: tuple[AtomType, ...]
    bond_types: tuple[BondType, ...]
    box: Box
    mat_thickness: float
    fibre_volume: float
    needle_points: np.ndarray
    needle_diameter: float
    faces_z: tuple[float, float]
    angles: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), dtype=np.int64))
    angle_type: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    angle_types: tuple[AngleType, ...] = ()
    angle_style: str = "none"

    def __post_init__(self):
        n = len(self.positions)
        checks = {
            "positions": (self.positions, (n, 3)),
            "diameter": (self.diameter, (n,)),
            "density": (self.density, (n,)),
            "type_id": (self.type_id, (n,)),
            "mol_id": (self.mol_id, (n,)),
            "bonds": (self.bonds, (len(self.bonds), 2)),
            "bond_type": (self.bond_type, (len(self.bonds),)),
            "angles": (self.angles, (len(self.angles), 3)),
            "angle_type": (self.angle_type, (len(self.angles),)),
        }
        for name, (array, shape) in checks.items():
            if np.shape(array) != shape:
                raise ValueError(f"Model.{name} must have shape {shape}, got {np.shape(array)}")
        floats = ("positions", "diameter", "density", "needle_points")
        for name in (*floats, "type_id", "mol_id", "bonds", "bond_type", "angles", "angle_type"):
            dtype = np.float64 if name in floats else np.int64
            object.__setattr__(self, name, _frozen(getattr(self, name), dtype))
        for name in ("lo", "hi", "tilt"):
            object.__setattr__(self.box, name, _frozen(getattr(self.box, name), np.float64))
        if n and (self.type_id.min() < 0 or self.type_id.max() >= len(self.atom_types)):
            raise ValueError("Model.type_id must index atom_types")
        if len(self.bonds) and (self.bond_type.max() >= len(self.bond_types)):
            raise ValueError("Model.bond_type must index bond_types")
        if len(self.angles) and (self.angle_type.max() >= len(self.angle_types)):
            raise ValueError("Model.angle_type must index angle_types")
        if bool(len(self.angles)) != (self.angle_style != "none"):
            raise ValueError("Model.angle_style must be 'none' exactly when there are no angles")

    @property
    def n_atoms(self) -> int:
        """Number of beads."""
        return len(self.positions)

    @property
    def n_bonds(self) -> int:
        """Number of bonds."""
        return len(self.bonds)

    @property
    def n_angles(self) -> int:
        """Number of bending angles."""
        return len(self.angles)

    @property
    def mass(self) -> np.ndarray:
        """(N,) bead masses ``density pi d^3 / 6`` (pg)."""
        return self.density * np.pi * self.diameter**3 / 6.0

    @property
    def cell_area(self) -> float:
        """In-plane cell area ``lx ly`` (um^2)."""
        return float(self.box.lengths[0] * self.box.lengths[1])

    def role_mask(self, role: str) -> np.ndarray:
        """(N,) bool, beads whose type has the given role (``"fibre"`` or ``"stitch"``)."""
        roles = np.array([t.role == role for t in self.atom_types])
        return roles[self.type_id]

    def areal_weight(self, role: str = "fibre") -> float:
        """Areal weight of the beads of one role (pg/um^2 = g/m^2)."""
        return float(self.mass[self.role_mask(role)].sum() / self.cell_area)

    def fvf(self, thickness):
        """Fibre volume fraction at a thickness (um; scalar or array), cylinder-equivalent."""
        return self.fibre_volume / (self.cell_area * np.asarray(thickness, dtype=float))

    def count(self, type_name: str) -> tuple[int, int]:
        """(chains, beads) of the named atom type."""
        index = [t.name for t in self.atom_types].index(type_name)
        mask = self.type_id == index
        return int(np.unique(self.mol_id[mask]).size), int(mask.sum())

    @property
    def ply_angles_deg(self) -> np.ndarray:
        """(P,) realised chain angles (deg) of the fibre types, in ply order."""
        return np.array([t.angle_deg for t in self.atom_types if t.role == "fibre"], dtype=float)
