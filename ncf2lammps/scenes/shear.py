"""Shear scenes (paper section 4.2): picture-frame kinematics of the periodic box.

Two scenes, one per sense of ``shear.senses`` (docs/shear.md): ``shear`` (positive) and
``shear_negative``, each from the same start and with files named after the scene.
Stages (templates/shear.lmp.j2):

1. ``shear``: from the manufactured state (restart) or, without a stitch, the generated mat;
   fibre bonds optionally pretensioned (``shear.fibre_pretension_N_m``); ``fix deform`` moves
   the box at a constant shear rate in the recipe of the frame (:func:`picture_frame`: for
   0/90 edge b turns, ``xy = s Lb sin g``, ``ly = Lb cos g``; for +-phi0 the box stretches) up
   to the final angle; the virial pressure tensor (interval means) and the box are recorded;
   data files are written at 22.5 and 45 deg (if reached) and at the final angle. No plates,
   no drag: contact damping only.

The rate, unless given, comes from an inertial number at a reference pressure
(docs/shear.md): ``I = gdot d sqrt(rho / P)`` with ``I = shear.inertial_number``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .. import units
from ..analysis.energy import energy_balance_residual
from ..analysis.plots import paper_comparable, plot_shear, plot_stitch_tension
from ..analysis.render3d import state_views
from ..analysis.shear import SENSE_GROUPS, PictureFrame, ShearCurve
from ..geometry.direction import lattice_direction
from ..io.datafile import read_data
from ..io.lammpslog import read_ave_time, scene_steps
from ..model import Model
from ..numerics import Prepared, inertial_strain_rate
from ..spec import FRAME_TOLERANCE_DEG, FabricSpec, SpecError, shear_recipe
from . import stitch
from .base import Scene
from .loading import LoadingControl, loading_attrs, loading_control

__all__ = [
    "NEGATIVE",
    "REFERENCE_PRESSURE_KPA",
    "SCENE",
    "picture_frame",
    "shear_rate",
]

#: Pressure of the inertial-number rate (kPa): DIN ISO 5084, the lowest at which NCF thickness
#: is measured; the stitch holds the manufactured cell at least this tight.
REFERENCE_PRESSURE_KPA = 1.0
#: Angles at which the cell is written and rendered (deg), the paper's Fig. 6b, c.
SNAPSHOT_DEG = (22.5, 45.0)
#: Recording intervals per degree of shear.
RECORDS_PER_DEG = 10
#: Steps between box updates of ``fix deform`` (it remaps every atom at each update). On the
#: paper's cell an update moves the box edge by 0.0014 d and the steps run 15 % faster than
#: with an update every step (docs/performance.md). The recording interval is a multiple of it.
DEFORM_EVERY = 10
#: Kinetic ratios are reported once the angle has passed this fraction of the final angle.
LOADED_FRACTION = 0.25


#: The sign s of each sense in the recipe (PictureFrame.sense).
SIGNS = {"positive": 1, "negative": -1}


def requires(spec: FabricSpec) -> tuple[str, ...]:
    """A stitched fabric is sheared as manufactured."""
    return ("manufacture",) if spec.stitch is not None else ()


def picture_frame(spec: FabricSpec, model: Model, sense: str) -> PictureFrame:
    """The recipe of ``shear.frame_deg`` at the realised angles of its plies' fibre types.

    Each frame direction is the ``AtomType.angle_deg`` of the first ply of that requested
    angle; ``half_angle`` is half the angle between the two that contains x (pi/4 for 0/90).
    """
    requested = spec.shear.frame(spec.plies)
    realised = []
    for angle in requested:
        index = next((i for i, p in enumerate(spec.plies) if p.angle_deg == angle), None)
        realised.append(angle if index is None else float(model.ply_angles_deg[index]))
    kind = shear_recipe((realised[0], realised[1]))
    if kind is None:
        raise SpecError(
            "shear.frame_deg",
            list(requested),
            f"realised as {realised[0]:.6g} and {realised[1]:.6g} deg, neither 0/90 nor mirror"
            f" images about x (to {FRAME_TOLERANCE_DEG:g} deg)",
        )
    half = math.pi / 4 if kind == "tilt" else math.radians(abs(realised[0]))
    return PictureFrame(kind, SIGNS[sense], half, (realised[0], realised[1]))


def shear_rate(spec: FabricSpec, model: Model) -> float:
    """Shear rate (rad/us): the spec's, else ``I sqrt(P / rho) / d``.

    The inertial number ``I = gdot d sqrt(rho / P)`` is the square root of the ratio of the
    kinetic stress of non-affine bead motion, ``rho (gdot d)^2``, to the confining stress P; it
    is ``shear.inertial_number`` with P = :data:`REFERENCE_PRESSURE_KPA`, d the mean fibre bead
    diameter and rho the fibre density. Measured on the coarse case: I = 0.1 gave a largest
    kinetic / external work of 4.3 %, I = 0.05 1.3 % (docs/shear.md); the quasi-static check is
    the kinetic stress ratio below ``kinetic_stress_limit`` (docs/loading.md).
    """
    settings = spec.shear
    if settings.shear_rate_deg_us is not None:
        return math.radians(settings.shear_rate_deg_us)
    pressure = units.to_micro(REFERENCE_PRESSURE_KPA, "kPa")
    return inertial_strain_rate(model, settings.inertial_number, pressure)


def _pretension_bonds(spec: FabricSpec, model: Model) -> list[tuple[int, float, float]]:
    """(bond type, K, r0) of the fibre bonds shortened to carry the pretension.

    A ply's chains carry ``T = N0 w / n`` each (N0 per unit width, n chains across the strip
    of width ``w = Lx Ly / |v|`` their direction ``v`` tiles, geometry/direction.py); a periodic
    straight chain of K, r0 then has ``r0' = r0 - T / 2K``.
    """
    n0 = units.to_micro(spec.shear.fibre_pretension_N_m, "N_m")
    if n0 == 0.0:
        return []
    lx, ly = model.box.lengths[:2]
    out = []
    for index, bond in enumerate(model.bond_types):
        in_type = model.bond_type == index
        if bond.role != "fibre" or not np.any(in_type):
            continue
        # The ply of the bond's beads (a wavy ply has several bond types).
        kind = model.atom_types[model.type_id[model.bonds[in_type][0, 0]]]
        chains, _ = model.count(kind.name)
        width = lattice_direction(kind.lattice, (lx, ly)).period
        tension = n0 * width / chains
        out.append((index + 1, bond.k, bond.r0 - tension / (2.0 * bond.k)))
    return out


def _control(run: Prepared) -> LoadingControl:
    """The shear's loading rate: from the inertial-number rate, records every
    1 / RECORDS_PER_DEG deg at the fastest rate, in whole box updates."""
    spec = run.spec
    return loading_control(
        spec.shear,
        shear_rate(spec, run.model),
        REFERENCE_PRESSURE_KPA,
        math.radians(1.0 / RECORDS_PER_DEG),
        run.time_step.dt,
        DEFORM_EVERY,
    )


def _stops(spec: FabricSpec, control: LoadingControl, dt: float) -> list[tuple[str, float, int]]:
    """Segments (label, end angle rad, most steps) ending at each snapshot angle and the final
    angle, at the inertial-number rate of ``control`` (the slowest) and time step ``dt`` (us)."""
    final = spec.shear.final_angle_deg
    angles = sorted({a for a in SNAPSHOT_DEG if a < final} | {final})
    every = control.every
    ends = [
        every * max(1, math.ceil(math.radians(a) / (control.rate * dt * every))) for a in angles
    ]
    # Each run halts at the first record whose angle is the end's to rounding: the angle is a
    # sum of per-step increments, so a record meant to end on it may fall short by an ulp.
    return [
        (f"{a:g}", math.radians(a) * (1.0 - 1e-9), int(end - start))
        for a, start, end in zip(angles, [0, *ends[:-1]], ends, strict=True)
        if end > start
    ]


def deck_values(run: Prepared, sense: str) -> dict:
    """Typed values of templates/shear.lmp.j2 (LAMMPS micro units) for ``sense``."""
    spec, model = run.spec, run.model
    control = _control(run)
    return {
        "frame": picture_frame(spec, model, sense),
        "restart_file": "manufactured.restart" if spec.stitch is not None else None,
        "pretension_bonds": _pretension_bonds(spec, run.simulated),
        "control": control,
        "segments": _stops(spec, control, run.time_step.dt),
        "history_every": control.every,
        "deform_every": DEFORM_EVERY,
        "stitch": stitch.deck_value(run, SENSE_GROUPS[sense]),
    }


def collect(run: Prepared, directory: Path, sense: str) -> tuple[dict, dict]:
    """(attrs, datasets) of the ``sense``'s group from its scene's files in ``directory``."""
    spec, model = run.spec, run.model
    name, frame = SENSE_GROUPS[sense], picture_frame(spec, model, sense)
    stress = read_ave_time(directory / f"{name}.history.txt")
    box = read_ave_time(directory / f"{name}.box.txt")
    curve = ShearCurve(
        box["v_g"],
        box["v_box_xy"],
        box["v_box_lx"],
        box["v_box_ly"],
        stress["v_fn"],
        stress["v_nxy"],
        stress["v_nyy"],
        stress["v_kinetic"],
        stress.get("v_nxx"),
    ).compute()
    final = math.radians(spec.shear.final_angle_deg)
    force = units.from_micro(curve.force, "N_m")
    work = units.from_micro(curve.force_work, "N_m")
    loaded = np.abs(force) > 0.1 * np.abs(force).max()
    attrs = {
        "steps": scene_steps(directory / f"{name}.final.txt"),
        "sense": sense,
        "recipe": frame.kind,
        "frame_deg": np.array(frame.angles_deg),
        "ply_angles_deg": model.ply_angles_deg,
        "force_at_45deg_N_per_m": units.from_micro(curve.force_at(math.pi / 4), "N_m"),
        "force_at_final_N_per_m": units.from_micro(curve.force_at(curve.angle[-1]), "N_m"),
        "max_kinetic_ratio": curve.max_kinetic_ratio(LOADED_FRACTION * final),
        **loading_attrs(
            spec.shear, box["v_load_kinetic_ratio"], box["v_g"] >= LOADED_FRACTION * final
        ),
        "energy_balance_residual": energy_balance_residual(
            curve.work, stress["v_kinetic"], stress["v_potential"]
        ),
        "work_virial_max_deviation": float(np.max(np.abs(work[loaded] / force[loaded] - 1))),
        "shear_rate_deg_us": math.degrees(shear_rate(spec, model)),
        "max_shear_rate_deg_us": math.degrees(float(np.max(box["v_load_rate"]))),
        "final_angle_deg": math.degrees(curve.angle[-1]),
        "fibre_pretension_N_m": spec.shear.fibre_pretension_N_m,
    }
    final_state = f"{name}_{_stops(spec, _control(run), run.time_step.dt)[-1][0]}deg.data"
    stitch_attrs, stitch_datasets = stitch.collect(
        run, directory, name, stress["TimeStep"], ("angle_deg", np.degrees), final_state
    )
    attrs |= (
        stitch_attrs
        | stitch.hole_attrs(model, directory / "manufactured.data", directory / final_state)
        | stitch.path_attrs(model, directory / "manufactured.data", directory / final_state)
        | stitch.tension_attrs(directory / final_state)
    )
    datasets = {
        **stitch_datasets,
        "angle_deg": np.degrees(curve.mid_angle),
        "force_N_per_m": force,
        "force_work_N_per_m": work,
        "work_J": units.from_micro(curve.work, "J"),
        "kinetic_ratio": curve.kinetic_ratio,
        "kinetic_stress_ratio": box["v_load_kinetic_ratio"][1:],
        "shear_rate_deg_us": np.degrees(box["v_load_rate"][1:]),
    }
    return attrs, datasets


def figures(results: dict, directory: Path, sense: str) -> list[Path]:
    """F_N against angle (virial, work, the paper's values for a 0/90 fabric) and the stitch
    tensions (a stitched fabric), every sense run drawn once, by the first sense's scene; renders
    at 22.5 and 45 deg."""
    name = SENSE_GROUPS[sense]
    written = []
    if name == next(s for s in SENSE_GROUPS.values() if s in results):
        angles = results[name]["attrs"].get("ply_angles_deg", ())
        ax = plot_shear(results, paper_marks=paper_comparable(angles))
        ax.figure.tight_layout()
        written.append(directory / "figures" / "shear_force.png")
        ax.figure.savefig(written[-1], dpi=110)
        if "stitch_angle_deg" in results[name]:
            ax = plot_stitch_tension(results)
            ax.figure.tight_layout()
            written.append(directory / "figures" / "stitch_tension.png")
            ax.figure.savefig(written[-1], dpi=110)
    for angle in SNAPSHOT_DEG:
        state_file = directory / f"{name}_{angle:g}deg.data"
        if not state_file.is_file():
            continue
        fig = state_views(read_data(state_file), f"sheared {angle:g} deg, {sense} sense")
        written.append(directory / "figures" / f"{name}_views_{angle:g}deg.png")
        fig.savefig(written[-1], dpi=110)
    return written


def _scene(sense: str) -> Scene:
    """The scene shearing in ``sense`` (it applies when ``shear.senses`` holds it)."""
    return Scene(
        name=SENSE_GROUPS[sense],
        template="shear.lmp.j2",
        applies=lambda spec: sense in spec.shear.senses,
        requires=requires,
        deck_values=lambda run: deck_values(run, sense),
        periods=lambda values: (values["history_every"],),
        collect=lambda run, directory: collect(run, directory, sense),
        figures=lambda results, directory: figures(results, directory, sense),
        chunk=2000,
    )


SCENE = _scene("positive")
NEGATIVE = _scene("negative")
