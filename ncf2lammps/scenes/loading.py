"""The loading rate of the test scenes (compaction, shear): constant, or adapted to the cell
(templates/loading.lmp.j2, docs/loading.md).

A test scene's rate r_I comes from its inertial number ``I = r d sqrt(rho / S_ref)`` at the
reference pressure S_ref (1 kPa, DIN ISO 5084). Both measure, over each control interval, the
stress S the test reports (compaction: the plate pressure; shear: the shear stress |F_N| /
thickness), floored at S_ref, and the kinetic stress ratio ``Q = (2 K / 3 V) / S``: the share
of the stress that is inertia. The quasi-static check bounds the error Q can cause on the
test's output (:data:`QUASI_STATIC_CHECKS`) by :data:`KINETIC_ERROR_LIMIT`, 1 %.

Adaptive loading holds the inertial number at S and brakes on Q above its target Q*: after each
interval the rate is multiplied by ``min(r_I sqrt(S / S_ref) / rate, sqrt(Q* / Q))`` (Q grows
as the square of the rate), that factor limited to ``[DOWN, UP]`` and the rate to
``[r_I, max_rate_factor r_I]``: never slower than the constant loading.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import units
from ..spec import KINETIC_ERROR_LIMIT, CompactionSpec, ShearSpec

__all__ = [
    "DOWN",
    "KINETIC_ERROR_LIMIT",
    "QUASI_STATIC_CHECKS",
    "SAMPLES",
    "UP",
    "LoadingControl",
    "control_interval",
    "kinetic_checks",
    "loading_attrs",
    "loading_control",
    "quasi_static",
]

#: Largest rise of the rate in one control interval: ten intervals to double it, so that the
#: cell's response keeps up with the rate it follows.
UP = 2.0**0.1
#: Largest fall of the rate in one control interval: a drop of the stress (a slip, a lock giving
#: way, a stitch breaking) halves it at once.
DOWN = 0.5
#: Samples of the stress and the kinetic stress in each control interval.
SAMPLES = 10
#: The quasi-static checks of the test scenes, (attribute of the largest kinetic error,
#: attribute of its limit): the relative error the kinetic stress can cause on the test's output
#: (docs/loading.md). The shear's stress is its output (F_N / thickness), so the error is the
#: kinetic stress ratio Q itself; the compaction reads a thickness at a pressure, which a
#: pressure off by Q moves by Q times the curve's local stiffening exponent.
QUASI_STATIC_CHECKS = (
    ("max_kinetic_stress_ratio", "kinetic_stress_limit"),
    ("max_kinetic_thickness_error", "kinetic_thickness_error_limit"),
)


@dataclass(frozen=True)
class LoadingControl:
    """Typed deck value of templates/loading.lmp.j2 (LAMMPS micro units).

    Attributes: ``adaptive``; ``rate`` (r_I, the inertial-number or given rate: um/us of plate
    travel or rad/us of shear); ``rate_max`` (the adaptive rate's bound, same unit);
    ``kinetic_target`` (Q*, the kinetic stress ratio above which it brakes); ``every``
    (steps of a control interval, a multiple of ``samples``); ``floor`` (S_ref, kPa);
    ``samples``; ``up``, ``down`` (bounds of one update's factor).
    """

    adaptive: bool
    rate: float
    rate_max: float
    kinetic_target: float
    every: int
    floor: float
    samples: int = SAMPLES
    up: float = UP
    down: float = DOWN


def control_interval(resolution: float, fastest: float, dt: float, multiple: int = 1) -> int:
    """Steps of a control and record interval: the coordinate advances by at most
    ``resolution`` (its unit) per interval at the ``fastest`` rate (unit/us), at time step
    ``dt`` (us); a multiple of ``multiple`` and of :data:`SAMPLES`."""
    step = math.lcm(multiple, SAMPLES)
    return step * max(1, math.floor(resolution / (fastest * dt * step)))


def loading_control(
    settings: CompactionSpec | ShearSpec,
    rate: float,
    floor_kPa: float,
    resolution: float,
    dt: float,
    multiple: int = 1,
) -> LoadingControl:
    """The loading of a scene with ``settings`` whose rate at the reference pressure
    ``floor_kPa`` is ``rate``: records every ``resolution`` of the coordinate at the fastest
    rate, at time step ``dt`` (us), in intervals that are a multiple of ``multiple`` steps."""
    adaptive = settings.loading == "adaptive"
    fastest = rate * settings.max_rate_factor if adaptive else rate
    return LoadingControl(
        adaptive=adaptive,
        rate=rate,
        rate_max=fastest,
        kinetic_target=settings.kinetic_stress_target,
        every=control_interval(resolution, fastest, dt, multiple),
        floor=units.to_micro(floor_kPa, "kPa"),
    )


def loading_attrs(
    settings: CompactionSpec | ShearSpec,
    ratio: np.ndarray,
    measured,
    thickness_error: np.ndarray | None = None,
) -> dict:
    """The loading's attributes of a test scene: ``loading``, ``max_kinetic_stress_ratio`` (the
    largest interval's kinetic stress ratio ``ratio`` (N,) over the ``measured`` records, (N,)
    bool) and the quasi-static check (:data:`QUASI_STATIC_CHECKS`): that ratio against
    ``kinetic_stress_limit``, or, for a test that reads a thickness at a pressure, the error it
    causes there, ``thickness_error`` (N,): ``max_kinetic_thickness_error`` against
    ``kinetic_thickness_error_limit``."""
    attrs = {"loading": settings.loading, "max_kinetic_stress_ratio": _largest(ratio, measured)}
    if thickness_error is None:
        return attrs | {"kinetic_stress_limit": KINETIC_ERROR_LIMIT}
    return attrs | {
        "max_kinetic_thickness_error": _largest(thickness_error, measured),
        "kinetic_thickness_error_limit": KINETIC_ERROR_LIMIT,
    }


def kinetic_checks(attrs: dict) -> list[tuple[float, float]]:
    """The quasi-static checks a scene's ``attrs`` hold, as (value, limit) pairs: a test's own
    (:data:`QUASI_STATIC_CHECKS`), none for the manufacture. Results written before the
    compaction's thickness check existed hold the kinetic stress ratio's check instead."""
    return [
        (float(attrs[value]), float(attrs[limit]))
        for value, limit in QUASI_STATIC_CHECKS
        if value in attrs and limit in attrs
    ]


def quasi_static(attrs: dict) -> bool:
    """Whether a scene's ``attrs`` pass every quasi-static check they hold."""
    return all(value <= limit for value, limit in kinetic_checks(attrs))


def _largest(values: np.ndarray, measured) -> float:
    """Largest of ``values`` (N,) over the ``measured`` records ((N,) bool); NaN if none."""
    values = np.asarray(values, dtype=float)[np.asarray(measured, dtype=bool)]
    return float(np.max(values)) if len(values) else math.nan
