"""Compaction curves: pressure against gap, thickness at given pressures, energetics (numpy)."""

from __future__ import annotations

import math

import numpy as np

from .. import units
from .energy import energy_balance_residual

__all__ = [
    "EXPERIMENT",
    "PAPER_MODEL_THICKNESS_1KPA_MM",
    "CompactionCurve",
    "first_crossing",
    "first_crossings",
    "smooth",
]

#: Experiment of the paper (rheometer, one layer, 10 um/s): (thickness mm, pressure kPa).
EXPERIMENT = ((0.68, 1.0), (0.44, 18.0))
#: Thickness at 1 kPa given by the paper's digital-chain model (mm).
PAPER_MODEL_THICKNESS_1KPA_MM = 0.34


def smooth(values: np.ndarray, window: int) -> np.ndarray:
    """Centred moving average over ``window`` samples (shrinking at the ends), (N,) -> (N,)."""
    values = np.asarray(values, dtype=float)
    window = max(1, min(int(window), len(values)))
    kernel = np.ones(window)
    total = np.convolve(values, kernel, mode="same")
    count = np.convolve(np.ones_like(values), kernel, mode="same")
    return total / count


def first_crossings(x: np.ndarray, pressure: np.ndarray, levels) -> np.ndarray:
    """``x`` (N,) where the record ``pressure`` (N,) first reaches each of ``levels`` (L,),
    (L,): linear between the two records around it (``x[0]`` if the first already does); NaN
    where it never does."""
    x = np.asarray(x, dtype=float)
    pressure = np.asarray(pressure, dtype=float)
    levels = np.atleast_1d(np.asarray(levels, dtype=float))
    crossing = np.full(levels.shape, np.nan)
    if len(pressure) == 0:
        return crossing
    envelope = np.maximum.accumulate(np.where(np.isnan(pressure), -np.inf, pressure))
    first = np.searchsorted(envelope, levels, side="left")
    crossing[first == 0] = x[0]
    inner = (first > 0) & (first < len(pressure))
    i = first[inner]
    weight = (levels[inner] - pressure[i - 1]) / (pressure[i] - pressure[i - 1])
    crossing[inner] = x[i - 1] + weight * (x[i] - x[i - 1])
    return crossing


def first_crossing(x: np.ndarray, pressure: np.ndarray, level: float) -> float:
    """``x`` (N,) where the record ``pressure`` (N,) first reaches ``level``
    (:func:`first_crossings`); NaN if it never does."""
    return float(first_crossings(x, pressure, level)[0])


class CompactionCurve:
    """Loading curve of a compaction test; ``compute()`` then read the attributes.

    Inputs are in LAMMPS micro units (um, kPa, nN, pg um^2/us^2); thicknesses come out in mm.

    Args:
        gap: (N,) plate gap, decreasing (um).
        pressure: (N,) plate pressure (kPa).
        fibre_volume_per_area: fibre volume per cell area ``A / rho`` (um), so Vf = it / gap.
        force_top, force_bottom: (N,) normal forces on the two plates (nN).
        kinetic, potential: (N,) kinetic and potential energy (pg um^2/us^2).
        reference_pressure: the energetics are read from where the smoothed pressure first
            reaches it (kPa), so that they do not depend on where the plates stop.
        window: samples of the moving average that smooths the dynamic ripple.

    After :meth:`compute`: ``gap_mm``, ``smoothed`` (kPa), ``fvf`` (all (N,)); ``work`` (N,)
    external work ``W = integral of F dgap`` with F the mean plate force, trapezoidal
    (pg um^2/us^2); ``loaded`` (N,) past the reference pressure with W > 0;
    ``max_kinetic_ratio`` (largest kinetic energy / W once loaded); ``plate_force_imbalance``
    (travel-weighted ``|F_top - F_bottom| / F`` once loaded: 0 for quasi-static plates);
    ``energy_balance_residual`` (:func:`~ncf2lammps.analysis.energy.energy_balance_residual`);
    :meth:`thickness_at`, :meth:`value_at`, :meth:`force_share`, :meth:`stiffening_exponent`,
    :meth:`local_stiffening_exponent`, :meth:`kinetic_thickness_error`.
    """

    def __init__(
        self,
        gap,
        pressure,
        fibre_volume_per_area: float,
        *,
        force_top,
        force_bottom,
        kinetic,
        potential,
        reference_pressure: float,
        window: int = 5,
    ):
        self.gap = np.asarray(gap, dtype=float)
        self.pressure = np.asarray(pressure, dtype=float)
        self.fibre_volume_per_area = float(fibre_volume_per_area)
        self.force_top = np.asarray(force_top, dtype=float)
        self.force_bottom = np.asarray(force_bottom, dtype=float)
        self.kinetic = np.asarray(kinetic, dtype=float)
        self.potential = np.asarray(potential, dtype=float)
        self.reference_pressure = float(reference_pressure)
        self.window = window

    def compute(self) -> CompactionCurve:
        """Smooth the pressure, derive Vf along the curve and the energetics of the loading."""
        gap = self.gap
        self.gap_mm = units.from_micro(gap, "mm")
        self.smoothed = smooth(self.pressure, self.window)
        self.fvf = units.from_micro(self.fibre_volume_per_area, "mm") / self.gap_mm
        force = 0.5 * (self.force_top + self.force_bottom)
        steps = 0.5 * (force[1:] + force[:-1]) * -np.diff(gap)
        self.work = np.concatenate([[0.0], np.cumsum(steps)])
        reached = self.smoothed >= self.reference_pressure
        self.loaded = np.maximum.accumulate(reached) & (self.work > 0.0)
        ratio = self.kinetic[self.loaded] / self.work[self.loaded]
        self.max_kinetic_ratio = float(ratio.max()) if len(ratio) else math.nan
        mismatch = np.abs(self.force_top - self.force_bottom)
        travel = np.abs(np.gradient(gap)) * self.loaded if len(gap) > 1 else np.zeros(len(gap))
        self.plate_force_imbalance = (
            float(np.sum(mismatch * travel) / np.sum(force * travel))
            if np.any(travel)
            else math.nan
        )
        self.energy_balance_residual = energy_balance_residual(
            self.work, self.kinetic, self.potential
        )
        return self

    def stiffening_exponent(self, low: float, high: float) -> float:
        """Exponent b of ``Vf = a P^b`` between the pressures ``low`` and ``high`` (kPa):
        ``ln(t_low / t_high) / ln(high / low)`` from :meth:`thickness_at`; NaN if either is."""
        return math.log(self.thickness_at(low) / self.thickness_at(high)) / math.log(high / low)

    def thickness_at(self, pressure: float) -> float:
        """Gap (mm) where the smoothed pressure first reaches ``pressure`` (kPa); NaN if never."""
        return self.value_at(self.gap_mm, pressure)

    def value_at(self, values, pressure: float) -> float:
        """``values`` (N,), one per record, where the smoothed pressure first reaches
        ``pressure`` (kPa), linear between records; NaN if it never does."""
        return first_crossing(values, self.smoothed, pressure)

    def force_share(self, part_force) -> np.ndarray:
        """Share of the plates' mean force carried by a part of the beads, (N,): its mean force
        on the two plates ``part_force`` (N,) (nN) over the plates' mean force, both smoothed
        as the pressure is; NaN where the plates carry nothing."""
        total = smooth(0.5 * (self.force_top + self.force_bottom), self.window)
        part = smooth(part_force, self.window)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(total > 0.0, part / total, np.nan)

    def local_stiffening_exponent(self, pressure) -> np.ndarray:
        """Local exponent ``b = -d ln t / d ln P`` of the smoothed curve at each ``pressure``
        (L,) (kPa), (L,): the secant over a factor 2 in pressure, between the thicknesses
        where the curve first reaches ``P / sqrt 2`` and ``sqrt 2 P``, the window held within
        the pressures the curve spans (its first record, its highest). A secant, not the
        steepest slope inside the window: an estimate where the curve has a knee."""
        pressure = np.atleast_1d(np.asarray(pressure, dtype=float))
        low = np.maximum(pressure / math.sqrt(2.0), self.smoothed[0])
        high = np.minimum(pressure * math.sqrt(2.0), np.max(self.smoothed))
        thickness = first_crossings(self.gap_mm, self.smoothed, np.concatenate([low, high]))
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.log(thickness[: len(low)] / thickness[len(low) :]) / np.log(high / low)

    def kinetic_thickness_error(self, stress_ratio) -> np.ndarray:
        """Relative error of the thickness read at each record's pressure that the record's
        kinetic stress ratio ``Q`` (N,) can cause, (N,), to first order: a pressure off by the
        share Q moves the thickness at it by ``Q b``, with b the
        :meth:`local_stiffening_exponent` at the smoothed pressure (floored at the reference
        pressure, as Q's stress is)."""
        stress = np.maximum(self.smoothed, self.reference_pressure)
        return np.asarray(stress_ratio, dtype=float) * self.local_stiffening_exponent(stress)
