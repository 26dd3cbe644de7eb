"""Manufacture scene (paper section 3): needles, stitch insertion, pretension, relaxation.

Stages, in order (templates/manufacture.lmp.j2 marks each with ``# stage:``):

0. ``push-off`` (only with ``mat.arrangement = "random"``): the random bed's overlaps pushed
   apart, fibre-fibre contacts only, every fibre bead's move per step limited (``fix
   nve/limit``) under the fibre drag, until the largest contact force is that of
   ``mat.pushoff_overlap_tolerance`` x the smallest chain diameter or ``mat.max_pushoff_steps``
   have run. Checked at both ends (Python): the largest geometric overlap before and after;
   above the tolerance after, the run stops with what to change.
1. ``needles``: stitch beads frozen and out of contact; one cylinder per needle hole (and its
   periodic images near the cell edge) grows from a thread to the needle radius at the needle
   speed and pushes fibre beads out (``fix wall/region`` harmonic, cutoff = bead radius), under
   a viscous drag ``-m v / tau`` on every bead (``fix viscous``).
2. ``insertion``: checked first (Python): channels open (no fibre bead centre closer to a needle
   axis than the needle radius) and no stitch bead overlapping a fibre bead by more than
   ``insertion_overlap_tolerance`` x d. Then stitch-fibre contact on, everything integrated, the
   needles still in place.
3. ``pretension``: needles withdrawn; stitch rest lengths shrink at a constant strain rate until
   the mean stitch tension reaches the target (the paper's negative thermal load).
4. ``relaxation``: an integral controller (``fix controller``) trims the strain to hold the target
   while the cell relaxes; stops when the windowed tension error and the kinetic ratio (kinetic
   energy / work the shrinking stitch has done since the ramp began, docs/design.md §8) are below their
   thresholds, and with ``stitch_creep_target_per_ms`` the stitch's creep too; writes
   ``manufactured.restart`` and ``manufactured.data``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from .. import units
from ..analysis.geometry import max_overlap, min_xy_distance
from ..analysis.plots import plot_histories
from ..analysis.render3d import state_views
from ..engine import Engine, EngineError
from ..geometry.direction import lattice_direction
from ..io.datafile import read_data
from ..io.lammpslog import read_ave_time, read_final
from ..model import Model
from ..numerics import GUARD_MAX_STEP_MOVE, Prepared
from ..spec import FabricSpec
from .base import Scene
from .stitch import hole_attrs, rest_lengths_file, segment_kind, tension_attrs

__all__ = ["SCENE", "ManufactureError", "needle_axes"]

#: Time-averaging window of the convergence check, in controller invocations.
WINDOW = 20
#: Steps between controller updates and convergence samples.
CONTROL_EVERY = 10
#: Largest move of a bead in one push-off step, fraction of the smallest diameter: every bead
#: moving this far per step has (1e-3 / GUARD_KINETIC_FLOOR_STEP_MOVE)^2 = 11 x the kinetic
#: guard's floor energy, below its jump factor of 50, so the kinetic guard stays armed.
PUSHOFF_STEP_MOVE = 1.0e-3
#: The needle walls act on the fibre beads within this many largest bead diameters beyond their
#: range: on the paper's cell the reach cylinders hold ~10 % of the beads, the group rebuilt
#: every 24 steps.
NEEDLE_REACH_MARGIN = 2.0
#: The push-off halts at the contact force of this fraction of the tolerated overlap: the
#: contact damping of pairs parting at the move limit lowers their force below k_n x overlap
#: (by half on the coarse random bed of tests/test_random_mat.py, measured against the overlap
#: of the same state at rest); the stage check then measures the overlap itself.
PUSHOFF_FORCE_MARGIN = 0.25

#: Stitch segment kinds the pretension shortens when the loops are held (``stitch.interlock``).
PULLED_KINDS = ("leg", "underlap")

#: History rows (of ``CONTROL_EVERY * WINDOW // 2`` steps) over which the final creep rate of the
#: stitch strain is fitted.
CREEP_ROWS = 20


class ManufactureError(EngineError):
    """A manufacture check failed (channels not open, stitch overlapping fibres)."""


def _line_clearance(coordinate: np.ndarray, lines: np.ndarray, period: float) -> np.ndarray:
    """Periodic distance from each coordinate (any shape) to the nearest line (inf if none)."""
    if len(lines) == 0:
        return np.full(coordinate.shape, np.inf)
    gap = coordinate[..., None] - lines
    gap -= np.rint(gap / period) * period
    return np.abs(gap).min(axis=-1)


def _axis_offsets(model: Model) -> np.ndarray:
    """(P, 2) small shifts of the needle axes off the chain lines through the holes.

    A straight chain that crosses a needle axis is pushed along itself from both sides and
    never cleared; a real needle point deflects it to one side. Each axis is moved by up to
    ``d/2`` (on a 5 x 5 grid of candidates) to the spot farthest from every chain line.
    """
    fibre = model.role_mask("fibre")
    d = float(model.diameter[fibre].max())
    lengths = tuple(model.box.lengths[:2])
    chain_first = np.unique(model.mol_id[fibre], return_index=True)[1]
    first_bead = np.flatnonzero(fibre)[chain_first]
    grid = np.linspace(-0.5 * d, 0.5 * d, 5)
    candidates = np.array([(ox, oy) for ox in grid for oy in grid])
    axes = model.needle_points[:, None, :] + candidates[None, :, :]  # (P, C, 2)
    worst = np.full(axes.shape[:2], np.inf)
    # Chain lines of a ply: a constant coordinate across its direction, periodic over its strip.
    for index, kind in enumerate(model.atom_types):
        if kind.role != "fibre":
            continue
        direction = lattice_direction(kind.lattice, lengths)
        lines = model.positions[first_bead[model.type_id[first_bead] == index], :2]
        clearance = _line_clearance(
            axes @ direction.across, lines @ direction.across, direction.period
        )
        worst = np.minimum(worst, clearance)
    offsets = candidates[np.argmax(worst, axis=1)]
    return offsets


def applies(spec: FabricSpec) -> bool:
    """Manufacture needs a stitch."""
    return spec.stitch is not None


def requires(spec: FabricSpec) -> tuple[str, ...]:
    """No scene must run before manufacture."""
    return ()


def needle_axes(model: Model) -> np.ndarray:
    """(Q, 2) needle axes: every hole (shifted off the chain lines, see :func:`_axis_offsets`)
    and each periodic image whose needle reaches into the cell."""
    lengths = model.box.lengths[:2]
    reach = model.needle_diameter / 2 + float(model.diameter.max())
    centres = model.needle_points + _axis_offsets(model)
    shifts = np.array([(i, j) for i in (-1, 0, 1) for j in (-1, 0, 1)], dtype=float) * lengths
    images = (centres[:, None, :] + shifts[None, :, :]).reshape(-1, 2)
    inside = np.all((images > -reach) & (images < lengths + reach), axis=1)
    return images[inside]


def deck_values(run: Prepared) -> dict:
    """Typed values of templates/manufacture.lmp.j2 (LAMMPS micro units)."""
    spec, model = run.spec, run.model
    settings = spec.manufacture
    dt = run.time_step.dt
    fibre = model.role_mask("fibre")
    fibre_types = [i + 1 for i, t in enumerate(model.atom_types) if t.role == "fibre"]
    stitch_type = next(i + 1 for i, t in enumerate(model.atom_types) if t.role == "stitch")
    axes = needle_axes(model)
    radius = model.needle_diameter / 2
    cutoff = float(model.diameter[fibre].max()) / 2
    nearest = float(min_xy_distance(model.positions[fibre], axes, model.box.lengths).min())
    start_radius = max(1e-3, min(0.5 * nearest, 0.1 * radius))
    if spec.mat.arrangement == "random":
        start_radius = 1e-3  # the push-off moves beads after this geometry: start as a line
    speed = units.to_micro(settings.needle_speed_m_s, "m_s")
    damping_steps = math.ceil(2 * settings.damping_time_us / dt)
    pulled = _pulled_bond_types(spec, model)
    stitch_bonds = [(i + 1, t.r0) for i, t in enumerate(model.bond_types) if pulled[i]]
    held_bonds = [
        (i + 1, t.r0)
        for i, t in enumerate(model.bond_types)
        if t.role == "stitch" and not pulled[i]
    ]
    bond_r0 = np.array([t.r0 for t in model.bond_types])[model.bond_type]
    mass = run.simulated.mass
    type_mass = [float(mass[model.type_id == t - 1].mean()) for t in (*fibre_types, stitch_type)]
    return {
        "fibre_types": fibre_types,
        "stitch_type": stitch_type,
        "needles": [(float(x), float(y)) for x, y in axes],
        "needle_radius": radius,
        "needle_start_radius": start_radius,
        "needle_speed": speed,
        "needle_zlo": float(model.box.lo[2]),
        "needle_zhi": float(model.box.hi[2]),
        "needle_epsilon": _needle_stiffness(run) / 2,
        "needle_cutoff": cutoff,
        "needle_reach": _needle_reach(model, radius + cutoff),
        "needle_plane_hold": settings.needle_plane_hold,
        "needle_steps": math.ceil((radius - start_radius) / speed / dt) + damping_steps,
        "insertion_steps": damping_steps,
        "fibre_mass": list(zip(fibre_types, type_mass[:-1], strict=True)),
        "stitch_mass": type_mass[-1],
        "damping_time": settings.damping_time_us,
        "stitch_damping_time": settings.stitch_damping_time_us or settings.damping_time_us,
        "relaxation_damping_time": settings.relaxation_damping_time_us or settings.damping_time_us,
        "tension": units.to_micro(settings.stitch_tension_N, "N"),
        "strain_rate": settings.pretension_strain_rate_per_us,
        "ramp_steps": settings.max_ramp_steps,
        "stitch_bond_types": stitch_bonds,
        "held_bond_types": held_bonds,
        "pulled_spans": _pulled_spans(model, pulled) if held_bonds else None,
        "stitch_rest_length": float(bond_r0[pulled[model.bond_type]].sum()),
        "control_every": CONTROL_EVERY,
        "control_time": settings.control_time_us,
        "window": WINDOW,
        "tension_tolerance": settings.tension_tolerance,
        "kinetic_ratio_target": settings.kinetic_ratio_target,
        "relax_steps": settings.max_relax_steps,
        "history_every": CONTROL_EVERY * WINDOW // 2,
        "creep": _creep_values(run),
        "pushoff": _pushoff_values(run) if spec.mat.arrangement == "random" else None,
        "rest_lengths_file": rest_lengths_file(spec),
    }


def _pulled_bond_types(spec: FabricSpec, model: Model) -> np.ndarray:
    """(T,) bool, the bond types the pretension shortens: every stitch type, or with an
    interlock (``stitch.interlock``) the legs' and underlaps' (loops, links and rings keep
    their length)."""
    held = spec.stitch.interlock != "none"
    return np.array(
        [
            t.role == "stitch" and (not held or segment_kind(t.name) in PULLED_KINDS)
            for t in model.bond_types
        ],
        dtype=bool,
    )


def _pulled_spans(model: Model, pulled: np.ndarray) -> list[tuple[int, int]]:
    """Runs ``(first, last)`` of 1-based bead ids on pulled bonds (``pulled``: (T,) bool per
    bond type): the group whose bonds the manufacture's tension averages, a bond counting when
    both its beads are in the group (the model gives every held loop two bonds at least, so
    that none joins two of them)."""
    beads = np.unique(model.bonds[pulled[model.bond_type]])
    breaks = np.flatnonzero(np.diff(beads) > 1)
    firsts, lasts = beads[np.r_[0, breaks + 1]], beads[np.r_[breaks, len(beads) - 1]]
    return [(int(a) + 1, int(b) + 1) for a, b in zip(firsts, lasts, strict=True)]


def _stitch_axial_stiffness(model: Model) -> float:
    """The stitch yarn's E A (nN): the mean over its bond types (one yarn, equal to rounding)."""
    return float(np.mean([t.axial_stiffness for t in model.bond_types if t.role == "stitch"]))


def _creep_values(run: Prepared) -> dict | None:
    """The relaxation's creep criterion, None without ``manufacture.stitch_creep_target_per_ms``.

    The controller's strain increment per control interval, averaged over ``every`` steps
    (``creep_window_us`` rounded up to whole convergence windows, so that the relaxation's halt,
    once per such window, reads the convergence fix at a step it is computed; ``every`` is one
    of the deck's periods, so a checkpoint falls on a window's end and a resumed run's first
    check sees a whole window), times ``scale`` (1/us per increment, ``EA / (T control_every
    dt)``) is the creep: the tension the stitch would lose per us if its rest length stopped
    following the bed. ``target`` in 1/us."""
    settings = run.spec.manufacture
    if settings.stitch_creep_target_per_ms is None:
        return None
    dt = run.time_step.dt
    tension = units.to_micro(settings.stitch_tension_N, "N")
    stiffness = _stitch_axial_stiffness(run.simulated)
    windows = math.ceil(settings.creep_window_us / (CONTROL_EVERY * WINDOW * dt))
    return {
        "outputs": windows,
        "every": CONTROL_EVERY * WINDOW * windows,
        "scale": stiffness / (tension * CONTROL_EVERY * dt),
        "target": settings.stitch_creep_target_per_ms / units.to_micro(1.0, "ms"),
    }


def _needle_reach(model: Model, wall_range: float) -> dict:
    """The fibre beads the needle walls (range ``wall_range`` um from an axis at full radius)
    act on: those within ``radius`` um of an axis, a dynamic group rebuilt ``every`` steps, so
    few that a bead at the speed guard's limit
    (:data:`~ncf2lammps.numerics.GUARD_MAX_STEP_MOVE` smallest diameters per step) cannot cross
    the margin of :data:`NEEDLE_REACH_MARGIN` largest diameters in between: the walls exert the
    same forces as on every fibre bead."""
    margin = NEEDLE_REACH_MARGIN * float(model.diameter.max())
    every = int(margin // (GUARD_MAX_STEP_MOVE * float(model.diameter.min())))
    return {"radius": wall_range + margin, "every": max(1, every)}


def _needle_stiffness(run: Prepared) -> float:
    """Stiffness (nN/um) of the needle walls. On rows, the fibre-stitch contact's: the contact
    law's, or under the bundle law its rigid stitch law (the bundle's own stiffness is the fibre
    bed's at its onset, tens of N/m: dense rows of bundle chains pushed their beads through a
    needle that soft). On a random bed, whose chains cross the needle axes anywhere and must be
    pushed aside whole, at least the rigid ``contact.normal_stiffness_N_m`` and the stiffest
    fibre bond's 2 K, so that no bond pulls a bead through a needle."""
    if run.spec.mat.arrangement != "random":
        return (run.contact.stitch or run.contact).stiffness
    fibre_bonds = [2.0 * t.k for t in run.simulated.bond_types if t.role == "fibre"]
    rigid = units.to_micro(run.spec.contact.normal_stiffness_N_m, "N_m")
    return max(rigid, *fibre_bonds)


def _pushoff_values(run: Prepared) -> dict:
    """The push-off stage's slab (the fibre beads' generated heights, um), move limit (um per
    step), halt period, step cap and the contact
    force (nN) at :data:`PUSHOFF_FORCE_MARGIN` of the tolerated overlap ``delta``: ``k_n
    delta`` (hooke) or ``4/3 E* sqrt(R* delta) delta`` (hertz, ``E* = E / 2``, ``R*`` of two of
    the smallest chains: a larger pair at that force overlaps less)."""
    model, law = run.model, run.contact
    d_min = float(model.diameter[model.role_mask("fibre")].min())
    delta = PUSHOFF_FORCE_MARGIN * run.spec.mat.pushoff_overlap_tolerance * d_min
    if law.model == "hooke":
        force = law.normal * delta
    else:
        force = 4.0 / 3.0 * (law.normal / 2.0) * np.sqrt(d_min / 4.0 * delta) * delta
    fibre_z = model.positions[model.role_mask("fibre"), 2]
    return {
        "zlo": float(fibre_z.min()),
        "zhi": float(fibre_z.max()),
        "step_limit": PUSHOFF_STEP_MOVE * float(model.diameter.min()),
        "every": CONTROL_EVERY,
        "steps": run.spec.mat.max_pushoff_steps,
        "force": float(force),
    }


def _periods(values: dict) -> tuple[int, ...]:
    """Recording and control periods (steps) of the manufacture deck."""
    every = values["control_every"]
    creep = (values["creep"]["every"],) if values["creep"] else ()
    return (values["history_every"], every, every * values["window"], *creep)


def _check_channels_and_overlap(engine: Engine, run: Prepared) -> dict:
    """Measure the channels after the needle step and the stitch-fibre overlap at insertion."""
    spec, model = run.spec, run.model
    positions = engine.gather("x", 3)
    fibre = model.role_mask("fibre")
    stitch = model.role_mask("stitch")
    centres = model.needle_points + _axis_offsets(model)
    channel = min_xy_distance(positions[fibre], centres, model.box.lengths)
    radius = model.needle_diameter / 2
    if np.any(channel < radius):
        worst = int(np.argmin(channel))
        raise ManufactureError(
            f"channel check at step {engine.step}: a fibre bead centre sits {channel[worst]:.4g} um"
            f" from needle {worst} (radius {radius:.4g} um); raise manufacture.damping_time_us or"
            " lower manufacture.needle_speed_m_s so the needles finish opening the channels"
        )
    overlap, i, j = max_overlap(positions, model.diameter, stitch, fibre, model.box.lengths)
    d_ref = 0.5 * (model.diameter[stitch].max() + model.diameter[fibre].max())
    tolerance = spec.manufacture.insertion_overlap_tolerance
    if overlap > tolerance * d_ref:
        raise ManufactureError(
            f"insertion check at step {engine.step}: stitch bead {i + 1} overlaps fibre bead"
            f" {j + 1} by {overlap / d_ref:.3g} d (tolerance {tolerance:g} d); raise"
            " stitch.needle_diameter_mm or manufacture.insertion_overlap_tolerance"
        )
    return {
        "channel_min_distance_um": float(channel.min()),
        "needle_radius_um": float(radius),
        "insertion_max_overlap_d": max(0.0, overlap / d_ref),
    }


#: Measures of the live checks at insertion (Python driver only), for :func:`collect`.
CHECKS_FILE = "manufacture.checks.json"


def _fibre_overlap(engine: Engine, run: Prepared) -> float:
    """Largest overlap of two fibre beads of different chains now, fraction of the smallest
    chain diameter."""
    model = run.model
    fibre = model.role_mask("fibre")
    positions = engine.gather("x", 3)
    overlap = max_overlap(positions, model.diameter, fibre, fibre, model.box.lengths, model.mol_id)
    return max(0.0, overlap[0]) / float(model.diameter[fibre].min())


def _check_pushoff(engine: Engine, run: Prepared, stage: str) -> dict:
    """At ``push-off``: the random bed's initial overlap; at ``needles`` after a push-off: its
    steps and final overlap, a ManufactureError above ``mat.pushoff_overlap_tolerance``."""
    mat = run.spec.mat
    if stage == "push-off":
        return {"pushoff_initial_max_overlap_d": _fibre_overlap(engine, run)}
    overlap = _fibre_overlap(engine, run)
    if overlap > mat.pushoff_overlap_tolerance:
        capped = engine.step >= mat.max_pushoff_steps
        why = "the step cap mat.max_pushoff_steps" if capped else "its contact-force criterion"
        raise ManufactureError(
            f"push-off check at step {engine.step}: fibre beads still overlap by {overlap:.3g} d"
            f" (tolerance {mat.pushoff_overlap_tolerance:g} d) when the stage stopped at {why};"
            " raise mat.max_pushoff_steps or manufacture.damping_time_us, or lower"
            " mat.initial_fvf or mat.waviness_amplitude_um"
        )
    return {"pushoff_steps": engine.step, "pushoff_max_overlap_d": overlap}


def _stage_checks(engine: Engine, run: Prepared, stage: str) -> dict:
    """At ``insertion``: the channel and overlap checks; at ``push-off`` and ``needles`` of a
    random bed: :func:`_check_pushoff`. Their measures are also kept in :data:`CHECKS_FILE`
    (rank 0, merged with the earlier stages') for :func:`collect`."""
    if stage == "insertion":
        checks = _check_channels_and_overlap(engine, run)
    elif run.spec.mat.arrangement == "random" and stage in ("push-off", "needles"):
        checks = _check_pushoff(engine, run, stage)
    else:
        return {}
    if engine.rank == 0:
        path = Path(CHECKS_FILE)
        earlier = json.loads(path.read_text()) if path.is_file() else {}
        path.write_text(json.dumps({**earlier, **checks}))
    return checks


def _final_rate(time: np.ndarray, value: np.ndarray) -> float:
    """Least-squares slope (1/us) of ``value`` over the last :data:`CREEP_ROWS` history rows:
    the rate at which the controller still shortens the stitch when the run stops (0 at rest)."""
    last = slice(-min(CREEP_ROWS, len(time)), None)
    return float(np.polyfit(time[last], value[last], 1)[0]) if len(time) > 1 else math.nan


def _final_creep(run: Prepared, final: dict, strain_rate: float) -> float:
    """The stitch's creep at the stop (1/ms): the tension it would lose per ms with its rest
    length frozen, ``EA / T`` x the strain rate; the deck's own windowed value with
    ``stitch_creep_target_per_ms`` (what the criterion read), else from ``strain_rate`` (1/us,
    the fit over the last :data:`CREEP_ROWS` history rows)."""
    per_us = final.get("creep")
    if per_us is None:
        tension = units.to_micro(run.spec.manufacture.stitch_tension_N, "N")
        per_us = abs(strain_rate) * _stitch_axial_stiffness(run.simulated) / tension
    return float(per_us * units.to_micro(1.0, "ms"))


def collect(run: Prepared, directory: Path) -> tuple[dict, dict]:
    """(attrs, datasets) of /manufacture from the scene's files in ``directory``."""
    spec = run.spec
    history = read_ave_time(directory / "manufacture.history.txt")
    work = history["v_work"]
    final = read_final(directory / "manufacture.final.txt")
    checks = directory / CHECKS_FILE
    target = spec.manufacture.stitch_tension_N
    tension = units.from_micro(final["tension"], "N")
    strain_rate = _final_rate(history["v_time"], history["v_strain"])
    attrs = {
        "steps": int(final["step"]),
        "thickness_mm": units.from_micro(final["thickness"], "mm"),
        "stitch_tension_N": tension,
        "stitch_tension_target_N": target,
        "stitch_tension_error": (tension - target) / target,
        "tension_tolerance": spec.manufacture.tension_tolerance,
        "kinetic_ratio": final["kinetic_ratio"],
        "kinetic_ratio_target": spec.manufacture.kinetic_ratio_target,
        "pretension_work_J": units.from_micro(final["work"], "J"),
        "stitch_strain": final["strain"],
        "stitch_strain_rate_per_us": strain_rate,
        "stitch_creep_per_ms": _final_creep(run, final, strain_rate),
        **(
            {"stitch_creep_target_per_ms": spec.manufacture.stitch_creep_target_per_ms}
            if spec.manufacture.stitch_creep_target_per_ms is not None
            else {}
        ),
        **(json.loads(checks.read_text()) if checks.is_file() else {}),
        **hole_attrs(run.model, None, directory / "manufactured.data"),
        **tension_attrs(directory / "manufactured.data"),
    }
    datasets = {
        "time_us": history["v_time"],
        "stitch_tension_N": units.from_micro(history["v_tension"], "N"),
        "thickness_mm": units.from_micro(history["v_thickness"], "mm"),
        "stitch_strain": history["v_strain"],
        "kinetic_energy_J": units.from_micro(history["v_kinetic"], "J"),
        "pretension_work_J": units.from_micro(work, "J"),
        "kinetic_ratio": np.divide(
            history["v_kinetic"], work, out=np.full(len(work), np.nan), where=work > 0
        ),
    }
    return attrs, datasets


def figures(results: dict, directory: Path) -> list[Path]:
    """Renders of the manufactured cell (front, back, side; 3 x 2 cells) and the histories."""
    group = results["manufacture"]
    attrs = group["attrs"]
    written = []
    state_file = directory / "manufactured.data"
    if state_file.is_file():
        fig = state_views(read_data(state_file), "as manufactured")
        written.append(directory / "figures" / "manufacture_views.png")
        fig.savefig(written[-1], dpi=110)
    fig = plot_histories(
        group["time_us"],
        [
            (
                "stitch tension (N)",
                group["stitch_tension_N"],
                attrs["stitch_tension_target_N"],
                False,
            ),
            ("thickness (mm)", group["thickness_mm"], None, False),
            ("kinetic / work", group["kinetic_ratio"], attrs["kinetic_ratio_target"], True),
        ],
        "manufacture",
    )
    written.append(directory / "figures" / "manufacture_history.png")
    fig.savefig(written[-1], dpi=110)
    return written


SCENE = Scene(
    name="manufacture",
    template="manufacture.lmp.j2",
    applies=applies,
    requires=requires,
    deck_values=deck_values,
    periods=_periods,
    collect=collect,
    figures=figures,
    chunk=2000,
    stage_checks=_stage_checks,
)
