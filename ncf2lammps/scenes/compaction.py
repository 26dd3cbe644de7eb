"""Compaction scene (paper section 4.1): closing plates, pressure against gap, Vf, ISO thickness.

Stages (templates/compaction.lmp.j2):

1. ``compaction``: from the manufactured state (restart) or, without a stitch, the generated mat;
   a fixed bottom plate just under the lowest bead and a top plate just over the highest one
   (``fix wall/gran/region`` on plane regions, Coulomb friction of the spec); the top plate moves
   down at a constant speed to the gap of the final Vf; plate forces are summed by LAMMPS
   (``compute reduce`` of the walls' ``contacts``) and recorded with the gap every
   ``record_every_um`` of plate travel.

The speed comes from an inertial-number target at the reference pressure (DIN ISO 5084: 1 kPa):
``I = (v / h) d sqrt(rho / P)``, so ``v = I h sqrt(P / rho) / d`` (docs/compaction.md).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .. import units
from ..analysis.compaction import CompactionCurve
from ..analysis.plots import paper_comparable, plot_compaction
from ..io.lammpslog import read_ave_time, scene_steps
from ..model import Model
from ..numerics import Prepared, inertial_strain_rate
from ..spec import FabricSpec, SpecError
from . import stitch
from .base import Scene
from .loading import LoadingControl, loading_attrs, loading_control

__all__ = [
    "SCENE",
    "plate_speed",
]

#: Pressures at which thickness is reported (kPa): DIN ISO 5084 and the rheometer maximum.
REPORT_PRESSURES = (1.0, 18.0)


def applies(spec: FabricSpec) -> bool:
    """Every fabric can be compacted."""
    return True


def requires(spec: FabricSpec) -> tuple[str, ...]:
    """A stitched fabric is compacted as manufactured."""
    return ("manufacture",) if spec.stitch is not None else ()


def plate_speed(spec: FabricSpec, model: Model) -> float:
    """Plate speed (um/us): the spec's, else from the inertial number at the reference pressure."""
    settings = spec.compaction
    if settings.plate_speed_m_s is not None:
        return units.to_micro(settings.plate_speed_m_s, "m_s")
    pressure = units.to_micro(settings.reference_pressure_kPa, "kPa")
    return model.mat_thickness * inertial_strain_rate(model, settings.inertial_number, pressure)


#: Bound on a random bed's manufactured thickness over its generated faces: crossing chains
#: pressed into each other push the bed apart once the stitch holds it (the coarse bundle case
#: grew from 1.03 to 1.19 mm, 1.16 x).
RANDOM_BED_SWELL = 1.5


def _final_gap(spec: FabricSpec, model: Model) -> float:
    """Gap (um) at the final Vf, from the cylinder-equivalent fibre volume."""
    return model.fibre_volume / (model.cell_area * spec.compaction.final_fvf)


def deck_values(run: Prepared) -> dict:
    """Typed values of templates/compaction.lmp.j2 (LAMMPS micro units)."""
    spec, model = run.spec, run.model
    dt = run.time_step.dt
    control = _control(run)
    # The manufactured cell is no thicker than the generated stitch faces plus a bead (a random
    # bed: RANDOM_BED_SWELL times the faces): this bounds the travel; fix halt ends the run at
    # the final gap or pressure.
    faces = model.faces_z[1] - model.faces_z[0]
    if spec.mat.arrangement == "random":
        faces *= RANDOM_BED_SWELL
    start_gap = faces + float(model.diameter.max())
    travel = start_gap - _final_gap(spec, model)
    if travel <= 0.0:
        start_fvf = model.fibre_volume / (model.cell_area * start_gap)
        raise SpecError(
            "compaction.final_fvf",
            spec.compaction.final_fvf,
            f"is reached before the plates move (they start at a gap of {start_gap:.0f} um,"
            f" Vf {start_fvf:.3f}): allowed above {start_fvf:.3f}",
        )
    return {
        "restart_file": "manufactured.restart" if spec.stitch is not None else None,
        "contact": run.contact,
        "clearance": 1e-3 * float(model.diameter.min()),
        "control": control,
        "steps": math.ceil(travel / control.rate / dt),
        "record_every": control.every,
        "final_gap": _final_gap(spec, model),
        "max_pressure": _max_pressure(spec),
        "stitch": stitch.deck_value(run, "compaction"),
    }


def _control(run: Prepared) -> LoadingControl:
    """The plates' loading rate: from the inertial-number speed, records every
    ``record_every_um`` of travel at the fastest speed."""
    settings = run.spec.compaction
    return loading_control(
        settings,
        plate_speed(run.spec, run.model),
        settings.reference_pressure_kPa,
        settings.record_every_um,
        run.time_step.dt,
    )


def _max_pressure(spec: FabricSpec) -> float | None:
    """Pressure (LAMMPS micro units) at which the plates stop (``end = "max_pressure"``), or
    None (they stop at the final gap only)."""
    settings = spec.compaction
    if settings.end != "max_pressure":
        return None
    return units.to_micro(settings.max_pressure_kPa, "kPa")


def _stopped_by(spec: FabricSpec, pressure: np.ndarray, gap: np.ndarray, final_gap: float) -> str:
    """Which end stopped the plates: ``"max_pressure_kPa"`` if the last record is past it,
    ``"final_fvf"`` if the last gap (um) is within two records of the final one, else
    ``"steps"`` (the planned travel ran out first)."""
    limit = _max_pressure(spec)
    if limit is not None and pressure.size > 0 and pressure[-1] > limit:
        return "max_pressure_kPa"
    reached = gap.size > 0 and gap[-1] <= final_gap + 2.0 * spec.compaction.record_every_um
    return "final_fvf" if reached else "steps"


def collect(run: Prepared, directory: Path) -> tuple[dict, dict]:
    """(attrs, datasets) of /compaction from the scene's files in ``directory``."""
    spec, model = run.spec, run.model
    history = read_ave_time(directory / "compaction.history.txt")
    final_gap = _final_gap(spec, model)
    keep = history["v_gap"] >= final_gap * (1 - 1e-9)
    gap = history["v_gap"][keep]
    pressure = history["v_pressure"][keep]
    per_area = model.fibre_volume / model.cell_area
    speed = history["v_load_rate"][keep]
    kinetic_ratio = history["v_load_kinetic_ratio"][keep]
    curve = CompactionCurve(
        gap,
        pressure,
        per_area,
        force_top=history["v_force_top"][keep],
        force_bottom=history["v_force_bottom"][keep],
        kinetic=history["v_kinetic"][keep],
        potential=history["v_potential"][keep],
        reference_pressure=units.to_micro(spec.compaction.reference_pressure_kPa, "kPa"),
    ).compute()
    t1, t18 = (curve.thickness_at(p) for p in REPORT_PRESSURES)
    thickness_error = curve.kinetic_thickness_error(kinetic_ratio)
    attrs = {
        "steps": scene_steps(directory / "compaction.final.txt"),
        "ply_angles_deg": model.ply_angles_deg,
        "thickness_at_1kPa_mm": t1,
        "thickness_at_18kPa_mm": t18,
        "fvf_at_18kPa": units.from_micro(per_area, "mm") / t18 if math.isfinite(t18) else math.nan,
        "stiffening_exponent": curve.stiffening_exponent(*REPORT_PRESSURES),
        "max_kinetic_ratio": curve.max_kinetic_ratio,
        **loading_attrs(spec.compaction, kinetic_ratio, curve.loaded, thickness_error),
        "plate_force_imbalance": curve.plate_force_imbalance,
        "energy_balance_residual": curve.energy_balance_residual,
        "plate_speed_m_s": units.from_micro(plate_speed(spec, model), "m_s"),
        "max_plate_speed_m_s": units.from_micro(float(np.max(speed, initial=0.0)), "m_s"),
        "final_fvf": spec.compaction.final_fvf,
        "reached_fvf": float(curve.fvf[-1]) if len(gap) else math.nan,
        "stopped_by": _stopped_by(spec, pressure, gap, final_gap),
    }
    plate_datasets = {}
    if "v_force_stitch" in history:  # plates split by law: the stitch's share of the load
        force_stitch = history["v_force_stitch"][keep]
        share = curve.force_share(force_stitch)
        for pressure in REPORT_PRESSURES:
            attrs[f"stitch_plate_share_at_{pressure:g}kPa"] = curve.value_at(share, pressure)
        plate_datasets["stitch_plate_force_N"] = units.from_micro(force_stitch, "N")
    stitch_attrs, stitch_datasets = stitch.collect(
        run,
        directory,
        "compaction",
        history["TimeStep"][keep],
        ("gap_mm", lambda gap: units.from_micro(gap, "mm")),
        None,
    )
    attrs |= stitch_attrs
    datasets = {
        **stitch_datasets,
        "time_us": history["v_time"][keep],
        "gap_mm": curve.gap_mm,
        "pressure_kPa": curve.pressure,
        "pressure_smoothed_kPa": curve.smoothed,
        "fvf": curve.fvf,
        "force_top_N": units.from_micro(history["v_force_top"][keep], "N"),
        "force_bottom_N": units.from_micro(history["v_force_bottom"][keep], "N"),
        **plate_datasets,
        "plate_speed_m_s": units.from_micro(speed, "m_s"),
        "kinetic_stress_ratio": kinetic_ratio,
        "kinetic_thickness_error": thickness_error,
    }
    return attrs, datasets


def figures(results: dict, directory: Path) -> list[Path]:
    """Pressure against thickness with the paper's experiment and model marked (a 0/90 fabric)."""
    angles = results["compaction"]["attrs"].get("ply_angles_deg", ())
    ax = plot_compaction(results, paper_marks=paper_comparable(angles))
    ax.figure.tight_layout()
    path = directory / "figures" / "compaction.png"
    ax.figure.savefig(path, dpi=110)
    return [path]


SCENE = Scene(
    name="compaction",
    template="compaction.lmp.j2",
    applies=applies,
    requires=requires,
    deck_values=deck_values,
    periods=lambda values: (values["record_every"],),
    collect=collect,
    figures=figures,
    chunk=5000,
)
