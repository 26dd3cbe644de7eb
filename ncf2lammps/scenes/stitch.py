"""The stitch yarn in the loading scenes (compaction, shear): its tension history and, with
``stitch.rupture``, the rupture of its bonds (templates/stitch.lmp.j2, docs/stitch.md).

The deck value :func:`deck_value` feeds the template's ``loading`` macro; manufacture writes the
stitch rest lengths it settled at (:data:`REST_LENGTHS_FILE`) for the break lengths. Records:
``<scene>.stitch.txt`` (mean and largest stitch tension, broken bonds), read by :func:`collect`.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from .. import units
from ..analysis.stitch import (
    YarnHoles,
    bond_midpoints,
    bond_tensions,
    broken_bonds,
    first_break,
    hole_slip,
    path_strains,
    shog_width_ratio,
    yarn_holes,
)
from ..io.datafile import read_data
from ..io.lammpslog import read_ave_time
from ..model import BondType, Box, Model
from ..numerics import Prepared
from ..spec import FabricSpec, SpecError, StitchSpec

__all__ = [
    "REST_LENGTHS_FILE",
    "RUPTURE_EVERY",
    "breaking_force",
    "collect",
    "deck_value",
    "hole_attrs",
    "is_interlock",
    "path_attrs",
    "ruptures",
    "segment_kind",
    "stitch_holes",
    "stitch_yarns",
    "tension_attrs",
]

#: Segment kinds of the interlock's bond types, not of a yarn's path (docs/stitch.md).
INTERLOCK_KINDS = ("link", "ring")
#: Steps between the checks of fix bond/break: a quasi-static bond stretches by far less than
#: its break margin in this many steps.
RUPTURE_EVERY = 10
#: Beads per breakable block of a yarn (templates/stitch.lmp.j2): odd, so that the middle bond
#: and the pairs it frees (within two beads of it) lie inside the block.
RUPTURE_BLOCK = 5
#: Written by manufacture with stitch.rupture: ``variable stitch_r0_<type> equal r0'`` (um).
REST_LENGTHS_FILE = "manufactured.stitch.lmp"
#: Broken bonds named in the ``stitch_broken_bonds`` attribute (summary.md), and stored with
#: their beads and midpoints (array attributes, well inside HDF5's 64 kB per attribute).
LISTED_BREAKS = 12
STORED_BREAKS = 1000


def segment_kind(label: str) -> str:
    """The segment kind (leg, loop, underlap, link, ring) of a stitch bond type's name or data
    file label, ``stitch_<kind>_<j>``; ``""`` for any other bond type."""
    return label.split("_")[1] if label.startswith("stitch_") else ""


def is_interlock(bond_type: BondType) -> bool:
    """Whether a bond type is an interlooping link's or slip ring's (``stitch.interlock``)."""
    return segment_kind(bond_type.name) in INTERLOCK_KINDS


def rest_lengths_file(spec: FabricSpec) -> str | None:
    """The rest-length file manufacture writes: only for a rupturing stitch."""
    return REST_LENGTHS_FILE if spec.stitch is not None and spec.stitch.rupture else None


def breaking_force(stitch: StitchSpec, bond: BondType) -> float:
    """Tension (nN) at which a stitch bond of ``bond`` breaks: tenacity x linear density
    (criterion ``force``), or ``EA`` x elongation at break (``strain``)."""
    if stitch.rupture_criterion == "force":
        return units.to_micro(0.01 * stitch.tenacity_cN_dtex * stitch.linear_density_dtex, "N")
    return bond.axial_stiffness * stitch.elongation_at_break


def _break_length(stitch: StitchSpec, bond: BondType) -> tuple[float, float]:
    """(scale, offset) of the break length ``r0' scale + offset`` (um) of a stitch bond of rest
    length r0' after manufacture: ``r0' + F_b / 2K`` (force) or ``r0' (1 + e_b)`` (strain)."""
    if stitch.rupture_criterion == "force":
        return 1.0, breaking_force(stitch, bond) / (2.0 * bond.k)
    return 1.0 + stitch.elongation_at_break, 0.0


def _check_pretension(spec: FabricSpec, bonds: list[BondType]) -> None:
    """A stitch that breaks below its manufacture pretension would tear at the first step."""
    stitch = spec.stitch
    weakest = units.from_micro(min(breaking_force(stitch, b) for b in bonds), "N")
    target = spec.manufacture.stitch_tension_N
    if weakest <= target:
        key = "tenacity_cN_dtex" if stitch.rupture_criterion == "force" else "elongation_at_break"
        raise SpecError(
            f"stitch.{key}",
            getattr(stitch, key),
            f"breaks the stitch at {weakest:.3g} N, not above the pretension"
            f" manufacture.stitch_tension_N = {target:g} N",
        )


def ruptures(spec: FabricSpec, scene: str) -> bool:
    """Whether the stitch can break in ``scene``: with ``stitch.rupture``, in shear only. A
    compaction presses past the experiment's range (to Vf 0.67 by default) where the squeezed
    yarn's bonds snap and fire their beads out (a lost-atoms stop on the coarse +-45 cell)."""
    return spec.stitch is not None and spec.stitch.rupture and scene != "compaction"


def deck_value(run: Prepared, scene: str) -> dict | None:
    """The ``stitch`` value of the loading deck of ``scene`` (None without a stitch): bead type,
    bond count and, where it can break (:func:`ruptures`), the check period, rest-length file and
    per stitch bond type (1-based) the break length's (scale, offset)."""
    spec, model = run.spec, run.simulated
    if spec.stitch is None:
        return None
    stitch_type = next(i + 1 for i, t in enumerate(model.atom_types) if t.role == "stitch")
    value = {"type": stitch_type, "bonds": len(model.bonds), "rupture": None}
    if ruptures(spec, scene):
        # The interlock holds (docs/stitch.md): the yarn breaks in its own path.
        bonds = [
            (i + 1, t)
            for i, t in enumerate(model.bond_types)
            if t.role == "stitch" and not is_interlock(t)
        ]
        _check_pretension(spec, [t for _, t in bonds])
        yarns = stitch_yarns(model)
        value["rupture"] = {
            "first_id": int(yarns[0][0]) + 1,
            "per_yarn": len(yarns[0]),
            "mol_base": int(model.mol_id.max()) + 2,
            "block": RUPTURE_BLOCK,
            "every": RUPTURE_EVERY,
            "file": REST_LENGTHS_FILE,
            "bond_types": [(i, *_break_length(spec.stitch, t)) for i, t in bonds],
        }
    return value


def _breaks(directory: Path, final_state: str) -> dict:
    """Attributes of the stitch bonds missing from ``final_state`` against manufactured.data:
    their count, a list of the first few, and (at most :data:`STORED_BREAKS`) their beads
    (K, 2, 0-based) and midpoints in the manufactured cell (K, 3, mm)."""
    before = read_data(directory / "manufactured.data")
    after = read_data(directory / final_state)
    gone = broken_bonds(before.bonds, after.bonds)
    pairs = before.bonds[gone]
    box = before.box
    middle = units.from_micro(bond_midpoints(before.positions, pairs, box.lo, box.lengths), "mm")
    kinds = [segment_kind(before.bond_labels[t]) for t in before.bond_type[gone]]
    listed = [
        f"{kind} at ({x:.3f}, {y:.3f}, {z:.3f}) mm"
        for kind, (x, y, z) in zip(kinds[:LISTED_BREAKS], middle, strict=False)
    ]
    return {
        "stitch_bonds_broken": len(gone),
        "stitch_broken_bonds": "; ".join(listed) + (" ..." if len(gone) > LISTED_BREAKS else ""),
        "stitch_broken_beads": pairs[:STORED_BREAKS],
        "stitch_broken_midpoints_mm": middle[:STORED_BREAKS],
    }


def stitch_yarns(model: Model) -> list[np.ndarray]:
    """(K,) bead indices of each stitch yarn of ``model`` in path order: the model lays each
    closed yarn's beads consecutively; the beads of interlooping links and rings (bonded by
    those only, laid after the yarns) are left out."""
    interlock = np.array([is_interlock(t) for t in model.bond_types], dtype=bool)
    on_yarn = np.zeros(model.n_atoms, dtype=bool)
    on_yarn[model.bonds[~interlock[model.bond_type]].ravel()] = True
    beads = np.flatnonzero(model.role_mask("stitch") & on_yarn)
    return np.split(beads, np.flatnonzero(np.diff(model.mol_id[beads])) + 1)


def stitch_holes(model: Model, positions: np.ndarray, box: Box) -> list[YarnHoles]:
    """The holes of every stitch yarn of ``model`` in a state (positions (N, 3) um, box)."""
    return [yarn_holes(positions, box, yarn) for yarn in stitch_yarns(model)]


def _model_states(model: Model, reference: str | Path | None, state: str | Path):
    """[(positions (N, 3) um, box, bonds (B, 2))] of ``reference`` (a state file; None: the
    generated model) and ``state``, the model's beads only (the first ``model.n_atoms`` of a
    state: atoms a hand-edited deck adds come after them); None without a stitch, without the
    state files or with a state of fewer beads than the model."""
    files = [Path(f) for f in (reference, state) if f is not None]
    if not model.role_mask("stitch").any() or not all(f.is_file() for f in files):
        return None
    states = [read_data(f) for f in files]
    if min(len(s.positions) for s in states) < model.n_atoms:
        return None
    pairs = [(s.positions[: model.n_atoms], s.box, s.bonds) for s in states]
    if reference is None:
        pairs.insert(0, (model.positions, model.box, model.bonds))
    return pairs


def hole_attrs(model: Model, reference: str | Path | None, state: str | Path) -> dict:
    """Where the stitch's holes lie in the state file ``state`` (docs/stitch.md):
    ``stitch_shog_width_ratio``, the width of the underlaps across the wales against the
    generated lapping, and ``stitch_hole_slip_mm``, the RMS in-plane distance the holes moved
    through the mat since ``reference`` (a state file; None: the generated model), less the
    fibres' rigid drift. Empty where :func:`_model_states` finds no states."""
    if (pairs := _model_states(model, reference, state)) is None:
        return {}
    (since_positions, since_box, _), (positions, box, _) = pairs
    generated = stitch_holes(model, model.positions, model.box)
    since = generated if reference is None else stitch_holes(model, since_positions, since_box)
    current = stitch_holes(model, positions, box)
    fibres = model.role_mask("fibre")
    move = box.fractional(positions[fibres]) - since_box.fractional(since_positions[fibres])
    move[:, :2] -= np.rint(move[:, :2])
    drift = np.array([*move[:, :2].mean(axis=0), 0.0])
    slip = hole_slip(since, current, since_box.matrix, drift)
    return {
        "stitch_shog_width_ratio": shog_width_ratio(generated, current),
        "stitch_hole_slip_mm": units.from_micro(slip, "mm"),
    }


def path_attrs(model: Model, reference: str | Path, state: str | Path) -> dict:
    """How much longer the stitch is in the state file ``state`` than in ``reference``
    (docs/stitch.md): ``stitch_path_strain``, the relative change of the total length of
    every stitch bond, and ``stitch_path_affine_strain``, the change the box's in-plane
    deformation alone would give (each bond carried by the cell's affine map, its z kept), over
    the bonds ``state`` still has (a broken one is left out). Their difference is what the
    cell's own motion (thickening, tows rolling) asks of the yarn. Empty where
    :func:`_model_states` finds no states."""
    if (pairs := _model_states(model, reference, state)) is None:
        return {}
    (before, box0, _), (after, box1, bonds) = pairs
    stitch_bonds = model.bonds[model.role_mask("stitch")[model.bonds[:, 0]]]
    stitch_bonds = np.delete(stitch_bonds, broken_bonds(stitch_bonds, bonds), axis=0)
    actual, affine = path_strains((before, after), (box0, box1), stitch_bonds)
    return {"stitch_path_strain": actual, "stitch_path_affine_strain": affine}


def tension_attrs(state: str | Path) -> dict:
    """``stitch_tension_<kind>_N``: the mean tension (N) of the stitch bonds of each segment
    kind (leg, loop, underlap; link, ring with an interlock) in the state file ``state``, with
    the rest lengths it holds (after the pretension). Empty without the file or a stitch."""
    if not Path(state).is_file():
        return {}
    data = read_data(state)
    kind = np.array([segment_kind(label) for label in data.bond_labels])[data.bond_type]
    k, r0 = data.bond_coeffs[data.bond_type].T
    tension = units.from_micro(bond_tensions(data.positions, data.box, data.bonds, k, r0), "N")
    return {
        f"stitch_tension_{name}_N": float(tension[kind == name].mean())
        for name in sorted(set(kind) - {""})
    }


def collect(
    run: Prepared,
    directory: Path,
    scene: str,
    steps: np.ndarray,
    abscissa: tuple[str, Callable[[np.ndarray], np.ndarray]],
    final_state: str | None,
) -> tuple[dict, dict]:
    """(attrs, datasets) of the stitch in a loading scene (empty without a stitch): the records
    of ``<scene>.stitch.txt`` at the scene's record ``steps`` (R,); ``abscissa`` = (name, its
    values from the recorded column), e.g. ``("angle_deg", degrees of v_g)``; with rupture the
    broken count per record, the first break and the broken bonds against ``final_state`` (a
    scene where the stitch can break, :func:`ruptures`)."""
    if run.spec.stitch is None:
        return {}, {}
    record = read_ave_time(directory / f"{scene}.stitch.txt")
    rows = np.searchsorted(record["TimeStep"], steps)
    name, convert = abscissa
    column = next(k for k in record if k != "TimeStep")
    x = convert(record[column][rows])
    tension_max = units.from_micro(record["v_stitch_tension_max"][rows], "N")
    datasets = {
        f"stitch_{name}": x,
        "stitch_tension_mean_N": units.from_micro(record["v_stitch_tension_mean"][rows], "N"),
        "stitch_tension_max_N": tension_max,
    }
    attrs = {"stitch_tension_max_N": float(tension_max.max()) if rows.size else np.nan}
    if not ruptures(run.spec, scene):
        return attrs, datasets
    broken = record["v_stitch_broken"][rows]
    datasets["stitch_bonds_broken"] = broken
    attrs[f"stitch_first_break_{name}"] = first_break(x, broken)
    return {**attrs, **_breaks(directory, final_state)}, datasets
