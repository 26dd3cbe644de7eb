"""The bead model: an immutable struct of numpy arrays built from a :class:`FabricSpec`.

All quantities are in LAMMPS ``micro`` units (um, pg, us, nN, kPa); indices are 0-based. Beads
stand for cylinders: bead density is set so that mass per chain length equals
``rho pi d^2 / 4`` (0.75 rho at spacing d/2), and volumes and Vf always use the cylinder volume.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import units
from .geometry import SEGMENT_KINDS, ply_chains, ply_layout, sample_closed_polyline, stitch_path
from .spec import FabricSpec, SpecError

__all__ = ["MAX_BEADS", "AtomType", "BondType", "Box", "Model", "build_model"]

#: Largest model built (about 5 GB of arrays and data file): ten times the million beads that are
#: a normal input. A spec asking for more is refused before any array is allocated.
MAX_BEADS = 10_000_000


@dataclass(frozen=True)
class AtomType:
    """A bead type: one per ply, one for the stitch yarn.

    Attributes: name; role ``"fibre"`` or ``"stitch"``; diameter (um); material density
    (pg/um^3); axial modulus E (kPa); ``angle_deg`` of a ply's chains (0: along x, 90: along y;
    None for the stitch).
    """

    name: str
    role: str
    diameter: float
    density: float
    modulus: float
    angle_deg: float | None = None


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
class Box:
    """Triclinic periodic box: ``lo``, ``hi`` (3,) um and tilt factors ``(xy, xz, yz)`` um."""

    lo: np.ndarray
    hi: np.ndarray
    tilt: np.ndarray

    @property
    def lengths(self) -> np.ndarray:
        """(3,) edge lengths ``hi - lo``, um."""
        return self.hi - self.lo


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
        }
        for name, (array, shape) in checks.items():
            if np.shape(array) != shape:
                raise ValueError(f"Model.{name} must have shape {shape}, got {np.shape(array)}")
        floats = ("positions", "diameter", "density", "needle_points")
        for name in (*floats, "type_id", "mol_id", "bonds", "bond_type"):
            dtype = np.float64 if name in floats else np.int64
            object.__setattr__(self, name, _frozen(getattr(self, name), dtype))
        for name in ("lo", "hi", "tilt"):
            object.__setattr__(self.box, name, _frozen(getattr(self.box, name), np.float64))
        if n and (self.type_id.min() < 0 or self.type_id.max() >= len(self.atom_types)):
            raise ValueError("Model.type_id must index atom_types")
        if len(self.bonds) and (self.bond_type.max() >= len(self.bond_types)):
            raise ValueError("Model.bond_type must index bond_types")

    @property
    def n_atoms(self) -> int:
        """Number of beads."""
        return len(self.positions)

    @property
    def n_bonds(self) -> int:
        """Number of bonds."""
        return len(self.bonds)

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


def build_model(spec: FabricSpec) -> Model:
    """Generate the homogeneous mat at the initial Vf and the idealised stitch yarn."""
    length, width = (units.to_micro(v, "mm") for v in spec.cell_mm)
    fvf = spec.mat.initial_fvf
    ratio = spec.discretisation.bead_spacing_ratio
    d_nominal = spec.discretisation.chain_diameter_um
    atom_types: list[AtomType] = []
    bond_types: list[BondType] = []
    positions, diameter, density, type_id, mol_id, bonds, bond_type = [], [], [], [], [], [], []
    n_beads = n_chains = 0
    z = 0.0
    fibre_volume = 0.0
    for index, ply in enumerate(spec.plies):
        along_x = ply.angle_deg == 0.0
        rho = units.to_micro(ply.density_g_cm3, "g_cm3")
        areal = units.to_micro(ply.areal_weight_g_m2, "g_m2")
        modulus = units.to_micro(ply.E_GPa, "GPa")
        chain_length, across = (length, width) if along_x else (width, length)
        layout = ply_layout(
            areal, rho, chain_length, across, z, fvf, d_nominal, ratio, f"ply[{index}]"
        )
        z += areal / (fvf * rho)
        planned = n_beads + layout.n_chains * layout.beads_per_chain
        if planned > MAX_BEADS:
            raise SpecError(
                "discretisation.chain_diameter_um",
                d_nominal,
                f"gives more than {MAX_BEADS:,} beads on this cell ({planned:,} by ply[{index}]);"
                " raise the chain diameter or shrink the cell",
            )
        beads = ply_chains(layout, along_x, across).reshape(-1, 3)
        d, s = layout.diameter, layout.spacing
        area = np.pi * d**2 / 4.0
        atom_types.append(
            AtomType(f"ply{index}_{ply.angle_deg:g}deg", "fibre", d, rho, modulus, ply.angle_deg)
        )
        bond_types.append(
            BondType(atom_types[-1].name, "fibre", modulus * area / (2 * s), s, modulus * area)
        )
        n = len(beads)
        per_chain = layout.beads_per_chain
        local = np.arange(n).reshape(layout.n_chains, per_chain)
        chain_bonds = np.stack([local, np.roll(local, -1, axis=1)], axis=-1).reshape(-1, 2)
        positions.append(beads)
        diameter.append(np.full(n, d))
        density.append(np.full(n, rho * area * s / (np.pi * d**3 / 6.0)))
        type_id.append(np.full(n, index))
        mol_id.append(n_chains + np.repeat(np.arange(layout.n_chains), per_chain))
        bonds.append(chain_bonds + n_beads)
        bond_type.append(np.full(len(chain_bonds), index))
        fibre_volume += area * chain_length * layout.n_chains
        n_beads += n
        n_chains += layout.n_chains
    mat_thickness = z
    fibre = np.concatenate(positions)
    fibre_d = np.concatenate(diameter)
    fibre_low = float((fibre[:, 2] - fibre_d / 2).min())
    fibre_high = float((fibre[:, 2] + fibre_d / 2).max())
    needle_points = np.zeros((0, 2))
    needle_diameter = 0.0
    faces = (fibre_low, fibre_high)
    if spec.stitch is not None:
        stitch = _stitch_beads(spec, length, width, fibre_low, fibre_high, float(fibre_d.max()))
        (
            s_positions,
            s_d,
            s_density,
            s_bonds,
            s_r0,
            s_kind,
            needle_points,
            needle_diameter,
            faces,
        ) = stitch
        stitch_type = len(atom_types)
        s_rho = units.to_micro(spec.stitch.density_g_cm3, "g_cm3")
        s_modulus = units.to_micro(spec.stitch.E_GPa, "GPa")
        atom_types.append(AtomType("stitch", "stitch", s_d, s_rho, s_modulus))
        area = np.pi * s_d**2 / 4.0
        # One bond type per distinct rest length, so that every bond starts exactly at rest.
        keys = np.rint(s_r0 * 1e6).astype(np.int64)
        _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
        for j, i in enumerate(first):
            r0 = float(s_r0[i])
            name = f"stitch_{SEGMENT_KINDS[s_kind[i]]}_{j}"
            bond_types.append(
                BondType(name, "stitch", s_modulus * area / (2 * r0), r0, s_modulus * area)
            )
        n_yarns, per_yarn = s_positions.shape[:2]
        flat = s_positions.reshape(-1, 3)
        positions.append(flat)
        diameter.append(np.full(len(flat), s_d))
        density.append(np.tile(s_density, n_yarns))
        type_id.append(np.full(len(flat), stitch_type))
        mol_id.append(n_chains + np.repeat(np.arange(n_yarns), per_yarn))
        offsets = (np.arange(n_yarns) * per_yarn)[:, None, None]
        bonds.append((s_bonds[None, :, :] + offsets).reshape(-1, 2) + n_beads)
        bond_type.append(np.tile(len(spec.plies) + inverse.ravel(), n_yarns))
    all_positions = np.concatenate(positions)
    all_positions[:, 0] %= length
    all_positions[:, 1] %= width
    all_d = np.concatenate(diameter)
    margin = max(mat_thickness, 4.0 * float(all_d.max()))
    box = Box(
        lo=np.array([0.0, 0.0, faces[0] - margin]),
        hi=np.array([length, width, faces[1] + margin]),
        tilt=np.zeros(3),
    )
    return Model(
        positions=all_positions,
        diameter=all_d,
        density=np.concatenate(density),
        type_id=np.concatenate(type_id),
        mol_id=np.concatenate(mol_id),
        bonds=np.concatenate(bonds),
        bond_type=np.concatenate(bond_type),
        atom_types=tuple(atom_types),
        bond_types=tuple(bond_types),
        box=box,
        mat_thickness=mat_thickness,
        fibre_volume=fibre_volume,
        needle_points=needle_points,
        needle_diameter=needle_diameter,
        faces_z=faces,
    )


def _stitch_beads(spec, length, width, fibre_low, fibre_high, fibre_d_max):
    """Beads of the stitch yarns: (W, n, 3) positions, diameter, (n,) densities, bonds, ..."""
    stitch = spec.stitch
    rho = units.to_micro(stitch.density_g_cm3, "g_cm3")
    linear = units.to_micro(stitch.linear_density_dtex, "dtex")
    d = stitch.diameter_um or float(np.sqrt(4.0 * linear / (np.pi * rho)))
    min_needle = d + fibre_d_max
    needle = units.to_micro(stitch.needle_diameter_mm, "mm")
    if needle < min_needle:
        raise SpecError(
            "stitch.needle_diameter_mm",
            stitch.needle_diameter_mm,
            f"must be at least {min_needle / 1e3:.4g} mm (stitch plus fibre diameter) to open a channel",
        )
    gauge = units.to_micro(stitch.gauge_mm, "mm")
    stitch_length = units.to_micro(stitch.stitch_length_mm, "mm")
    if needle >= min(gauge, stitch_length):
        raise SpecError(
            "stitch.needle_diameter_mm",
            needle / 1e3,
            f"must be below the hole spacing {min(gauge, stitch_length) / 1e3:.4g} mm"
            " (or use a smaller chain or stitch diameter)",
        )
    clearance = 0.01 * d
    z_bottom = fibre_low - d / 2 - clearance
    z_top = fibre_high + d / 2 + clearance
    path = stitch_path(stitch.overlaps, gauge, stitch_length, (length, width), z_bottom, z_top)
    ratio = spec.discretisation.bead_spacing_ratio
    chains = [sample_closed_polyline(v, path.closing_shift, ratio * d) for v in path.yarn_vertices]
    positions = np.stack([c.positions for c in chains])
    first = chains[0]
    area = np.pi * d**2 / 4.0
    bead_density = rho * area * first.length_per_bead / (np.pi * d**3 / 6.0)
    kind = path.kind[first.segment]
    return (
        positions,
        d,
        bead_density,
        first.bonds,
        first.bond_length,
        kind,
        path.needle_points,
        needle,
        (z_bottom, z_top),
    )
