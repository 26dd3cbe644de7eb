"""The bead model: an immutable struct of numpy arrays built from a :class:`FabricSpec`.

All quantities are in LAMMPS ``micro`` units (um, pg, us, nN, kPa); indices are 0-based. Beads
stand for cylinders: bead density is set so that mass per chain length equals
``fill rho pi d^2 / 4`` (0.75 rho at spacing d/2 and fill 1), and volumes and Vf always use the
fibre volume, ``fill`` times the cylinder's (``fill``: the chain's internal fibre volume fraction,
1 in the paper's model). Options beyond the paper (docs/fidelity.md) are off by default.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import units
from .geometry import SEGMENT_KINDS, ply_chains, ply_layout, sample_closed_polyline, stitch_path
from .geometry.mat import Waviness, wavy_chains
from .geometry.size import MAX_BEADS, check_model_size
from .spec import FabricSpec, SpecError

__all__ = ["MAX_BEADS", "AngleType", "AtomType", "BondType", "Box", "Model", "build_model"]


@dataclass(frozen=True)
class AtomType:
    """A bead type: one per ply, one for the stitch yarn.

    Attributes: name; role ``"fibre"`` or ``"stitch"``; diameter (um); material density
    (pg/um^3); axial modulus E (kPa); ``angle_deg`` of a ply's chains (0: along x, 90: along y;
    None for the stitch); ``fill``: fibre (or yarn) volume fraction inside the chain, so that
    its fibre cross-section is ``fill pi d^2 / 4``.
    """

    name: str
    role: str
    diameter: float
    density: float
    modulus: float
    angle_deg: float | None = None
    fill: float = 1.0


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


def build_model(spec: FabricSpec) -> Model:
    """Generate the homogeneous mat at the initial Vf and the idealised stitch yarn."""
    check_model_size(spec)  # before any array: a SpecError beyond MAX_BEADS
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
    fill = spec.discretisation.chain_internal_fvf
    waviness = _waviness(spec)
    angle_types: list[AngleType] = []
    angles, angle_type = [], []
    for index, ply in enumerate(spec.plies):
        along_x = ply.angle_deg == 0.0
        rho = units.to_micro(ply.density_g_cm3, "g_cm3")
        areal = units.to_micro(ply.areal_weight_g_m2, "g_m2")
        modulus = units.to_micro(ply.E_GPa, "GPa")
        chain_length, across = (length, width) if along_x else (width, length)
        layout = ply_layout(
            areal,
            rho,
            chain_length,
            across,
            z,
            fvf,
            d_nominal,
            ratio,
            f"ply[{index}]",
            fill=fill,
            waviness=waviness,
        )
        z += areal / (fvf * rho)
        per_chain = layout.beads_per_chain
        d, s = layout.diameter, layout.spacing
        area = fill * np.pi * d**2 / 4.0  # fibre cross-section of one chain
        name = f"ply{index}_{ply.angle_deg:g}deg"
        atom_types.append(AtomType(name, "fibre", d, rho, modulus, ply.angle_deg, fill))
        if waviness is None:
            beads = ply_chains(layout, along_x, across)
            bond_types.append(BondType(name, "fibre", modulus * area / (2 * s), s, modulus * area))
            r0 = length_per_bead = np.full(per_chain, s)
            chain_type = np.full(per_chain, len(bond_types) - 1)
            chain_density = np.full(per_chain, rho * area * s / (np.pi * d**3 / 6.0))
            fibre_length = chain_length
            rest_angle = np.full(per_chain, 180.0)
        else:
            beads, template = wavy_chains(layout, along_x, across, chain_length, waviness, index)
            per_chain = len(template.positions)
            r0, length_per_bead = template.bond_length, template.length_per_bead
            first, inverse = _distinct(r0)
            chain_type = len(bond_types) + inverse
            for j, i in enumerate(first):
                bond = float(r0[i])
                k = modulus * area / (2 * bond)
                bond_types.append(BondType(f"{name}_{j}", "fibre", k, bond, modulus * area))
            chain_density = rho * area * length_per_bead / (np.pi * d**3 / 6.0)
            fibre_length = float(r0.sum())
            rest_angle = _rest_angles(template.positions, chain_length)
        beads = beads.reshape(-1, 3)
        n = len(beads)
        local = np.arange(n).reshape(layout.n_chains, per_chain)
        chain_bonds = np.stack([local, np.roll(local, -1, axis=1)], axis=-1).reshape(-1, 2)
        positions.append(beads)
        diameter.append(np.full(n, d))
        density.append(np.tile(chain_density, layout.n_chains))
        type_id.append(np.full(n, index))
        mol_id.append(n_chains + np.repeat(np.arange(layout.n_chains), per_chain))
        bonds.append(chain_bonds + n_beads)
        bond_type.append(np.tile(chain_type, layout.n_chains))
        if spec.discretisation.bending != "none":
            bending = area * modulus * ply.filament_diameter_um**2 / 16.0  # N_f E pi d_f^4 / 64
            kinds = _angle_kinds(
                spec.discretisation.bending, bending, rest_angle, length_per_bead, name
            )
            types, per_bead = kinds
            per_bead = per_bead + len(angle_types)
            angle_types.extend(types)
            triples = np.stack([np.roll(local, 1, axis=1), local, np.roll(local, -1, axis=1)])
            angles.append(triples.reshape(3, -1).T + n_beads)
            angle_type.append(np.tile(per_bead, layout.n_chains))
        fibre_volume += area * fibre_length * layout.n_chains
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
        packing = spec.stitch.packing_fraction
        atom_types.append(AtomType("stitch", "stitch", s_d, s_rho, s_modulus, None, packing))
        area = packing * np.pi * s_d**2 / 4.0  # fibre cross-section of the yarn
        # One bond type per distinct rest length, so that every bond starts exactly at rest.
        first_stitch_bond = len(bond_types)
        first, inverse = _distinct(s_r0)
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
        bond_type.append(np.tile(first_stitch_bond + inverse, n_yarns))
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
        angles=np.concatenate(angles) if angles else np.zeros((0, 3), dtype=np.int64),
        angle_type=np.concatenate(angle_type) if angle_type else np.zeros(0, dtype=np.int64),
        angle_types=tuple(angle_types),
        angle_style=spec.discretisation.bending if angles else "none",
    )


def _waviness(spec: FabricSpec) -> Waviness | None:
    """The mat's waviness, None for the paper's straight chains."""
    mat = spec.mat
    if mat.waviness_amplitude_um == 0.0:
        return None
    return Waviness(
        amplitude=mat.waviness_amplitude_um,
        waves=mat.waviness_waves_per_cell,
        out_of_plane=mat.waviness_plane == "out-of-plane",
        phase_spread=mat.waviness_phase_spread_deg / 360.0,
        seed=mat.seed,
    )


def _distinct(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Classes of values equal to 1e-6 (rows of a 2-D array): (index of each class's first
    member, (n,) class of each value), classes in ascending order."""
    keys = np.rint(np.asarray(values) * 1e6).astype(np.int64)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    return first, inverse.ravel()


def _rest_angles(chain: np.ndarray, chain_length: float) -> np.ndarray:
    """(n,) angle (deg) at each bead of one closed chain between its two bonds (180: straight)."""
    shift = np.array([chain_length, 0.0, 0.0])
    before = np.vstack([chain[-1:] - shift, chain[:-1]]) - chain
    after = np.vstack([chain[1:], chain[:1] + shift]) - chain
    cosine = np.einsum("ij,ij->i", before, after)
    cosine /= np.linalg.norm(before, axis=1) * np.linalg.norm(after, axis=1)
    return np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))


def _angle_kinds(style, bending, rest_angle, spacing, name):
    """Angle types of one chain's beads: (types, (n,) type index of each bead).

    One type per distinct (rest angle, chain length per bead); ``K = EI / (2 s)`` (harmonic) or
    ``EI / s`` (cosine) with ``EI = bending`` (nN um^2) and ``s`` the bead's chain length.
    """
    first, inverse = _distinct(np.column_stack([rest_angle, spacing]))
    types = []
    for j, i in enumerate(first):
        s = float(spacing[i])
        k = bending / (2.0 * s) if style == "harmonic" else bending / s
        label = f"{name}_bend" if len(first) == 1 else f"{name}_bend_{j}"
        types.append(AngleType(label, "fibre", k, float(rest_angle[i]), bending, s))
    return types, inverse


def _stitch_beads(spec, length, width, fibre_low, fibre_high, fibre_d_max):
    """Beads of the stitch yarns: (W, n, 3) positions, diameter, (n,) densities, bonds, ..."""
    stitch = spec.stitch
    rho = units.to_micro(stitch.density_g_cm3, "g_cm3") * stitch.packing_fraction
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
