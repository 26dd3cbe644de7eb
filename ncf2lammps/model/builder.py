"""Build the bead model of a :class:`FabricSpec`: one part per ply, one for the stitch yarns.

Lengths in um, LAMMPS ``micro`` units. Each builder returns a :class:`~.parts.Part` whose
positions are wrapped into the cell in x and y; :func:`~.parts.join` assembles them.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .. import units
from ..geometry import (
    SEGMENT_KINDS,
    BeadChain,
    StitchPath,
    ply_chains,
    ply_layout,
    sample_closed_polyline,
    sample_open_polyline,
    slip_rings,
    stitch_path,
)
from ..geometry.bundle import chain_fill
from ..geometry.direction import PlyDirection, spec_ply_direction
from ..geometry.mat import RandomBed, Waviness, wavy_chains
from ..geometry.size import MAX_BEADS, check_model_size
from ..spec import FabricSpec, SpecError, StitchSpec
from .core import AngleType, AtomType, BondType, Box, Model
from .parts import Part, join

__all__ = ["MAX_BEADS", "angle_kinds", "build_model", "rest_angles", "rest_length_types"]


def build_model(spec: FabricSpec) -> Model:
    """Generate the homogeneous mat at the initial Vf and the idealised stitch yarn."""
    check_model_size(spec)  # before any array: a SpecError beyond MAX_BEADS
    cell = tuple(units.to_micro(v, "mm") for v in spec.cell_mm)
    plies: list[Part] = []
    z = 0.0
    for index in range(len(spec.plies)):
        plies.append(_ply_part(spec, index, cell, z))
        z += _ply_thickness(spec, index)
    fibre_low = min(float((p.positions[:, 2] - p.diameter / 2).min()) for p in plies)
    fibre_high = max(float((p.positions[:, 2] + p.diameter / 2).max()) for p in plies)
    faces = (fibre_low, fibre_high)
    parts = plies
    if spec.stitch is not None:
        faces = _stitch_faces(spec.stitch, fibre_low, fibre_high)
        fibre_d_max = max(p.atom_types[0].diameter for p in plies)
        parts = [*plies, _stitch_part(spec, cell, faces, fibre_d_max)]
    margin = max(z, 4.0 * max(t.diameter for p in parts for t in p.atom_types))
    box = Box(
        lo=np.array([0.0, 0.0, faces[0] - margin]),
        hi=np.array([*cell, faces[1] + margin]),
        tilt=np.zeros(3),
    )
    bending = spec.discretisation.bending
    return join(parts, box, mat_thickness=z, faces_z=faces, angle_style=bending)


def _wrapped(positions: np.ndarray, cell: tuple[float, float]) -> np.ndarray:
    """(n, 3) copy of bead centres (any shape (..., 3)) with x, y wrapped into the cell (um)."""
    out = np.array(positions, dtype=float).reshape(-1, 3)
    out[:, 0] %= cell[0]
    out[:, 1] %= cell[1]
    return out


# --- plies ------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class _PlyChains:
    """A ply's chains and the pattern of n beads every chain repeats.

    Attributes: beads (C, n, 3) bead centres (um); bond_type (n,) index into bond_types of the
    bond from each bead to the next; length_per_bead (n,) chain length each bead stands for
    (um); rest_angle (n,) angle at each bead (deg); fibre_length: length of one chain (um).
    """

    beads: np.ndarray
    bond_type: np.ndarray
    bond_types: tuple[BondType, ...]
    length_per_bead: np.ndarray
    rest_angle: np.ndarray
    fibre_length: float


def _ply_thickness(spec: FabricSpec, index: int) -> float:
    """Thickness of ply ``index`` in the homogeneous mat, ``A / (Vf rho)`` (um)."""
    ply = spec.plies[index]
    areal = units.to_micro(ply.areal_weight_g_m2, "g_m2")
    return areal / (spec.mat.initial_fvf * units.to_micro(ply.density_g_cm3, "g_cm3"))


def _ply_part(spec: FabricSpec, index: int, cell: tuple[float, float], z_bottom: float) -> Part:
    """The chains of ply ``index`` from height ``z_bottom`` (um) up, one type for its beads."""
    ply = spec.plies[index]
    direction = spec_ply_direction(spec, index)
    rho = units.to_micro(ply.density_g_cm3, "g_cm3")
    modulus = units.to_micro(ply.E_GPa, "GPa")
    fill = chain_fill(spec)
    waviness = _waviness(spec, direction)
    layout = ply_layout(
        units.to_micro(ply.areal_weight_g_m2, "g_m2"),
        rho,
        direction.chain_length,
        direction.period,
        z_bottom,
        spec.mat.initial_fvf,
        spec.discretisation.chain_diameter_um,
        spec.discretisation.bead_spacing_ratio,
        f"ply[{index}]",
        fill=fill,
        waviness=waviness,
        bed=_bed(spec),
        stream=index,
    )
    d = layout.diameter
    area = fill * np.pi * d**2 / 4.0  # fibre cross-section of a chain of diameter d
    name = f"ply{index}_{ply.angle_deg:g}deg"
    if waviness is None:
        beads = ply_chains(layout, direction)
        chains = _straight_chains(
            beads, layout.spacing, direction.chain_length, name, modulus * area
        )
    else:
        beads, template = wavy_chains(layout, direction, waviness, index)
        chains = _wavy_chains(beads, template, direction.chain_length, name, modulus * area)
    n_chains, per_chain = chains.beads.shape[:2]
    d_chain = np.full(n_chains, d) if layout.diameters is None else layout.diameters
    local = np.arange(n_chains * per_chain).reshape(n_chains, per_chain)
    # Each bead's mass is its own fibre cross-section times the chain length it stands for.
    lengths = chains.length_per_bead[None, :]
    density = (
        rho * area * (d_chain[:, None] / d) ** 2 * lengths / (np.pi * d_chain[:, None] ** 3 / 6)
    )
    part = Part(
        positions=_wrapped(chains.beads, cell),
        type_id=np.zeros(n_chains * per_chain, dtype=np.int64),
        density=density.ravel(),
        mol_id=np.repeat(np.arange(n_chains), per_chain),
        bonds=np.stack([local, np.roll(local, -1, axis=1)], axis=-1).reshape(-1, 2),
        bond_type=np.tile(chains.bond_type, n_chains),
        atom_types=(
            AtomType(
                name,
                "fibre",
                float(d_chain.max()),
                rho,
                modulus,
                direction.angle_deg,
                fill,
                direction.lattice,
            ),
        ),
        bond_types=chains.bond_types,
        fibre_volume=area * chains.fibre_length * float(np.sum((d_chain / d) ** 2)),
        bead_diameter=None if layout.diameters is None else np.repeat(d_chain, per_chain),
    )
    if spec.discretisation.bending != "none":
        bending = area * modulus * ply.filament_diameter_um**2 / 16.0  # N_f E pi d_f^4 / 64
        part = _bent(part, spec.discretisation.bending, bending, chains, name)
    if layout.diameters is None:
        return part
    return _per_chain_stiffness(part, (d_chain / d) ** 2, per_chain)


def _per_chain_stiffness(part: Part, scale: np.ndarray, per_chain: int) -> Part:
    """``part`` with each chain's own bond and angle types, stiffnesses (``k``, ``EA``, ``EI``)
    x ``scale`` (C,): a chain's fibre cross-section over the nominal one (a diameter spread)."""
    chain_of_bond = np.arange(len(part.bond_type)) // per_chain
    chain_of_angle = np.arange(len(part.angle_type)) // per_chain
    bonds = tuple(
        replace(t, name=f"{t.name}_c{c}", k=t.k * f, axial_stiffness=t.axial_stiffness * f)
        for c, f in enumerate(scale)
        for t in part.bond_types
    )
    angles = tuple(
        replace(t, name=f"{t.name}_c{c}", k=t.k * f, bending_stiffness=t.bending_stiffness * f)
        for c, f in enumerate(scale)
        for t in part.angle_types
    )
    return replace(
        part,
        bond_type=part.bond_type + chain_of_bond * len(part.bond_types),
        bond_types=bonds,
        angle_type=part.angle_type + chain_of_angle * len(part.angle_types),
        angle_types=angles,
    )


def _straight_chains(beads, spacing, chain_length, name, axial) -> _PlyChains:
    """The paper's straight chains, beads (C, n, 3) at ``spacing`` (um): one bond type at rest
    at the spacing, ``K = EA / (2 s)`` with ``EA = axial`` (nN)."""
    n = beads.shape[1]
    bond = BondType(name, "fibre", axial / (2 * spacing), spacing, axial)
    zeros = np.zeros(n, dtype=np.int64)
    return _PlyChains(beads, zeros, (bond,), np.full(n, spacing), np.full(n, 180.0), chain_length)


def _wavy_chains(beads, template: BeadChain, chain_length, name, axial) -> _PlyChains:
    """Wavy chains, beads (C, n, 3) each a translate of ``template`` (cell edge ``chain_length``
    um): one bond type per distinct rest length, ``K = EA / (2 r0)`` with ``EA = axial`` (nN)."""
    r0 = template.bond_length
    types, bond_type = rest_length_types(r0, "fibre", axial, lambda j, i: f"{name}_{j}")
    rest_angle = rest_angles(template.positions, chain_length)
    lengths = template.length_per_bead
    return _PlyChains(beads, bond_type, types, lengths, rest_angle, float(r0.sum()))


def _bent(part: Part, style: str, bending: float, chains: _PlyChains, name: str) -> Part:
    """``part`` with an angle at every bead of its closed chains (vertex the bead), of
    ``style`` with bending stiffness ``EI = bending`` (nN um^2)."""
    n_chains, per_chain = chains.beads.shape[:2]
    local = np.arange(n_chains * per_chain).reshape(n_chains, per_chain)
    triples = np.stack([np.roll(local, 1, axis=1), local, np.roll(local, -1, axis=1)])
    types, per_bead = angle_kinds(style, bending, chains.rest_angle, chains.length_per_bead, name)
    return replace(
        part,
        angles=triples.reshape(3, -1).T,
        angle_type=np.tile(per_bead, n_chains),
        angle_types=tuple(types),
    )


def _waviness(spec: FabricSpec, direction: PlyDirection) -> Waviness | None:
    """The waviness of a ply along ``direction``, None for the paper's straight chains: an
    off-axis chain of lattice vector (a, b) crosses ``a + |b|`` cell edges and carries that many
    times ``mat.waviness_waves_per_cell`` waves."""
    mat = spec.mat
    if mat.waviness_amplitude_um == 0.0:
        return None
    return Waviness(
        amplitude=mat.waviness_amplitude_um,
        waves=mat.waviness_waves_per_cell * direction.edges_crossed,
        out_of_plane=mat.waviness_plane == "out-of-plane",
        phase_spread=mat.waviness_phase_spread_deg / 360.0,
        seed=mat.seed,
        off_axis=direction.lattice not in ((1, 0), (0, 1)),
    )


def _bed(spec: FabricSpec) -> RandomBed | None:
    """The mat's random bed, None for the paper's rows."""
    mat = spec.mat
    if mat.arrangement == "rows":
        return None
    return RandomBed(seed=mat.seed, spread=mat.diameter_spread)


def rest_angles(chain: np.ndarray, chain_length: float) -> np.ndarray:
    """(n,) angle (deg) at each bead of one closed chain between its two bonds (180: straight)."""
    shift = np.array([chain_length, 0.0, 0.0])
    before = np.vstack([chain[-1:] - shift, chain[:-1]]) - chain
    after = np.vstack([chain[1:], chain[:1] + shift]) - chain
    cosine = np.einsum("ij,ij->i", before, after)
    cosine /= np.linalg.norm(before, axis=1) * np.linalg.norm(after, axis=1)
    return np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))


def angle_kinds(style, bending, rest_angle, spacing, name):
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


# --- type tables ------------------------------------------------------------------------------


def _distinct(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Classes of values equal to 1e-6 (rows of a 2-D array): (index of each class's first
    member, (n,) class of each value), classes in ascending order."""
    keys = np.rint(np.asarray(values) * 1e6).astype(np.int64)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    return first, inverse.ravel()


def rest_length_types(r0: np.ndarray, role: str, axial: float, label):
    """One bond type per distinct rest length, so that every bond starts exactly at rest.

    ``r0``: (m,) rest lengths (um); ``K = EA / (2 r0)`` with ``EA = axial`` (nN); ``label(j, i)``
    names class ``j`` whose first bond is ``i``. Returns (types, (m,) type index of each bond).
    """
    first, inverse = _distinct(r0)
    types = tuple(
        BondType(label(j, i), role, axial / (2 * float(r0[i])), float(r0[i]), axial)
        for j, i in enumerate(first)
    )
    return types, inverse


# --- stitch -----------------------------------------------------------------------------------


def _stitch_diameter(stitch: StitchSpec) -> float:
    """Yarn diameter (um): the spec's, else ``sqrt(4 T / (pi rho phi))`` from its dtex."""
    rho = units.to_micro(stitch.density_g_cm3, "g_cm3") * stitch.packing_fraction
    linear = units.to_micro(stitch.linear_density_dtex, "dtex")
    return stitch.diameter_um or float(np.sqrt(4.0 * linear / (np.pi * rho)))


def _stitch_contact_diameter(stitch: StitchSpec) -> float:
    """The yarn's bead diameter (um): ``contact_diameter_um`` (a flattened yarn), refused above
    the yarn's diameter, else the yarn's diameter."""
    d = _stitch_diameter(stitch)
    contact = stitch.contact_diameter_um
    if contact is None:
        return d
    if contact > d:
        raise SpecError(
            "stitch.contact_diameter_um",
            contact,
            f"must not exceed the yarn's diameter {d:.4g} um (a flattened yarn is thinner than"
            " the round one; unset: the round yarn)",
        )
    return contact


def _stitch_faces(stitch: StitchSpec, fibre_low: float, fibre_high: float) -> tuple[float, float]:
    """Heights of the underlap and loop axes (um): one bead radius and a 1 % clearance beyond
    the fibre extent ``fibre_low``..``fibre_high`` (um)."""
    d = _stitch_contact_diameter(stitch)
    clearance = 0.01 * d
    return fibre_low - d / 2 - clearance, fibre_high + d / 2 + clearance


def _needle_diameter(stitch: StitchSpec, d: float, fibre_d_max: float) -> float:
    """The needle diameter (um), refused unless it opens a channel for the yarn (diameter ``d``)
    past the thickest chain (``fibre_d_max``) and stays below the hole spacing."""
    min_needle = d + fibre_d_max
    needle = units.to_micro(stitch.needle_diameter_mm, "mm")
    if needle < min_needle:
        raise SpecError(
            "stitch.needle_diameter_mm",
            stitch.needle_diameter_mm,
            f"must be at least {min_needle / 1e3:.4g} mm (stitch plus fibre diameter) to open a channel",
        )
    spacing = min(
        units.to_micro(stitch.gauge_mm, "mm"), units.to_micro(stitch.stitch_length_mm, "mm")
    )
    if needle >= spacing:
        raise SpecError(
            "stitch.needle_diameter_mm",
            needle / 1e3,
            f"must be below the hole spacing {spacing / 1e3:.4g} mm"
            " (or use a smaller chain or stitch diameter)",
        )
    return needle


def _stitch_part(
    spec: FabricSpec, cell: tuple[float, float], faces: tuple[float, float], fibre_d_max: float
) -> Part:
    """The stitch yarns between the underlap and loop heights ``faces`` (um), one bead type and
    one bond type per distinct rest length; no fibre volume; the needle holes. The beads have
    the contact diameter (spaced by ``bead_spacing_ratio`` x it), and the yarn's mass per length
    and axial stiffness whatever it is."""
    stitch = spec.stitch
    d = _stitch_diameter(stitch)
    contact = _stitch_contact_diameter(stitch)
    needle = _needle_diameter(stitch, contact, fibre_d_max)
    gauge = units.to_micro(stitch.gauge_mm, "mm")
    stitch_length = units.to_micro(stitch.stitch_length_mm, "mm")
    path = stitch_path(stitch.overlaps, gauge, stitch_length, cell, *faces)
    spacing = spec.discretisation.bead_spacing_ratio * contact
    chains = [sample_closed_polyline(v, path.closing_shift, spacing) for v in path.yarn_vertices]
    first = chains[0]  # every yarn translates the first
    n_yarns, per_yarn = len(chains), len(first.positions)
    rho = units.to_micro(stitch.density_g_cm3, "g_cm3")
    modulus = units.to_micro(stitch.E_GPa, "GPa")
    packing = stitch.packing_fraction
    yarn_rho = rho * packing  # mass of the yarn per volume of its cylinder
    area = packing * np.pi * d**2 / 4.0  # fibre cross-section of the yarn
    kind = path.kind[first.segment]
    # Held loops keep their length while legs and underlaps are pulled: never one type for both.
    loop = kind == SEGMENT_KINDS.index("loop")
    loop_bonds = np.bincount(first.segment)[path.kind == SEGMENT_KINDS.index("loop")]
    if stitch.interlock != "none" and loop_bonds.min() < 2:
        raise SpecError(
            "stitch.interlock",
            stitch.interlock,
            "needs two bonds at least on every loop (the manufacture's tension is read from the"
            " pulled bonds' beads): a smaller stitch.diameter_um or"
            " discretisation.bead_spacing_ratio",
        )
    classes = [np.ones_like(loop)] if stitch.interlock == "none" else [loop, ~loop]
    types: tuple[BondType, ...] = ()
    bond_type = np.zeros(len(kind), dtype=np.int64)
    for members in classes:
        member_kind, offset = kind[members], len(types)
        new, inverse = rest_length_types(
            first.bond_length[members],
            "stitch",
            modulus * area,
            lambda j, i: f"stitch_{SEGMENT_KINDS[member_kind[i]]}_{offset + j}",  # noqa: B023
        )
        bond_type[members] = inverse + offset
        types += new
    cylinder = np.pi * d**2 / 4.0
    fill = packing * (d / contact) ** 2  # the yarn's fibre area over the bead's cross-section
    bead_density = yarn_rho * cylinder * first.length_per_bead / (np.pi * contact**3 / 6.0)
    offsets = (np.arange(n_yarns) * per_yarn)[:, None, None]
    yarns = Part(
        positions=_wrapped(np.stack([c.positions for c in chains]), cell),
        type_id=np.zeros(n_yarns * per_yarn, dtype=np.int64),
        density=np.tile(bead_density, n_yarns),
        mol_id=np.repeat(np.arange(n_yarns), per_yarn),
        bonds=(first.bonds[None, :, :] + offsets).reshape(-1, 2),
        bond_type=np.tile(bond_type, n_yarns),
        atom_types=(AtomType("stitch", "stitch", contact, rho, modulus, None, fill),),
        bond_types=types,
        needle_points=path.needle_points,
        needle_diameter=needle,
    )
    if stitch.interlock == "none":
        return yarns
    corner_bead = path.link_corners[..., 0] * per_yarn + np.searchsorted(
        first.segment, path.link_corners[..., 1]
    )
    sliding = stitch.interlock == "sliding"
    return _with_links(
        yarns, corner_bead, path, cell, spacing, modulus * area, yarn_rho * cylinder, sliding
    )


def _with_links(
    yarns: Part,
    corner_bead: np.ndarray,
    path: StitchPath,
    cell: tuple[float, float],
    spacing: float,
    axial: float,
    linear_density: float,
    sliding: bool,
) -> Part:
    """``yarns`` with the interlooping links of ``path`` after them (docs/stitch.md).

    Held: per link a straight chain of equal bonds (about ``spacing`` um) from the corner bead
    ``corner_bead[l, 0]`` to ``corner_bead[l, 1]`` ((L, 2) int). Sliding: the chain runs on the
    loop face to one stitch bead diameter d short of the end corner, drops by d and ends on a
    ring of radius d around the leg one d below that corner (the ring's beads touch the leg's). Inner
    beads one molecule each, every link and ring of the yarn's axial stiffness ``axial`` (nN)
    and mass per length ``linear_density`` (pg/um); links and rings have bond types of their own.
    """
    d = yarns.atom_types[0].diameter
    start = path.yarn_vertices[path.link_corners[0, 0, 0], path.link_corners[0, 0, 1]]
    end = start + path.link_vector
    waypoints = [start, end - [d, 0.0, 0.0], end - [d, 0.0, d]] if sliding else [start, end]
    # a held link keeps one inner bead at least: a lone bond would cross the bed unseen
    beads, lengths = sample_open_polyline(np.array(waypoints), spacing, 1 if sliding else 2)
    template = beads[1:-1]
    n_links, n_inner = len(corner_bead), len(template)
    starts = path.yarn_vertices[path.link_corners[:, 0, 0], path.link_corners[:, 0, 1]]
    inner = ((starts - start)[:, None, :] + template[None, :, :]).reshape(-1, 3)
    inner_id = len(yarns.positions) + np.arange(n_links * n_inner).reshape(n_links, n_inner)
    offset = len(yarns.bond_types)
    link_types, link_type = rest_length_types(
        np.tile(lengths, n_links), "stitch", axial, lambda j, i: f"stitch_link_{offset + j}"
    )
    new_positions, new_lengths = [inner], [np.tile(lengths[:-1], n_links)]
    new_bond_types, ring_bonds, end_bead = (
        link_types,
        np.zeros((0, 2), np.int64),
        corner_bead[:, 1:],
    )
    if sliding:
        n_ring = max(6, round(2.0 * np.pi * d / spacing))
        ring_id = inner_id.max() + 1 + np.arange(n_links * n_ring).reshape(n_links, n_ring)
        ring_bonds = np.stack([ring_id, np.roll(ring_id, -1, axis=1)], axis=-1).reshape(-1, 2)
        chord = float(2.0 * d * np.sin(np.pi / n_ring))
        name = f"stitch_ring_{offset + len(link_types)}"
        new_bond_types += (BondType(name, "stitch", axial / (2 * chord), chord, axial),)
        centres = starts + path.link_vector - [0.0, 0.0, d]
        new_positions.append(slip_rings(centres, d, n_ring).reshape(-1, 3))
        new_lengths.append(np.full(ring_id.size, chord))
        end_bead = ring_id[:, :1]
    chain = np.hstack([corner_bead[:, :1], inner_id, end_bead])
    link_bonds = np.stack([chain[:, :-1], chain[:, 1:]], axis=-1).reshape(-1, 2)
    positions = np.vstack(new_positions)
    bead_volume = np.pi * d**3 / 6.0
    ring_type = np.full(len(ring_bonds), offset + len(link_types), dtype=np.int64)
    return replace(
        yarns,
        positions=np.vstack([yarns.positions, _wrapped(positions, cell)]),
        type_id=np.concatenate([yarns.type_id, np.zeros(len(positions), dtype=np.int64)]),
        density=np.concatenate(
            [yarns.density, linear_density * np.concatenate(new_lengths) / bead_volume]
        ),
        mol_id=np.concatenate([yarns.mol_id, yarns.n_chains + np.arange(len(positions))]),
        bonds=np.vstack([yarns.bonds, link_bonds, ring_bonds]),
        bond_type=np.concatenate([yarns.bond_type, offset + link_type, ring_type]),
        bond_types=(*yarns.bond_types, *new_bond_types),
    )
