"""Compaction curves: pressure against gap, thickness at given pressures (pure numpy)."""

from __future__ import annotations

import numpy as np

__all__ = ["CompactionCurve", "smooth"]


def smooth(values: np.ndarray, window: int) -> np.ndarray:
    """Centred moving average over ``window`` samples (shrinking at the ends), (N,) -> (N,)."""
    values = np.asarray(values, dtype=float)
    window = max(1, min(int(window), len(values)))
    kernel = np.ones(window)
    total = np.convolve(values, kernel, mode="same")
    count = np.convolve(np.ones_like(values), kernel, mode="same")
    return total / count


class CompactionCurve:
    """Loading curve of a compaction test; ``compute()`` then read the attributes.

    Args:
        gap: (N,) plate gap, decreasing (mm).
        pressure: (N,) plate pressure (kPa).
        fibre_volume_per_area: fibre volume per cell area ``A / rho`` (mm), so Vf = it / gap.
        window: samples of the moving average that smooths the dynamic ripple.

    After :meth:`compute`: ``smoothed`` (N,) kPa; ``fvf`` (N,); :meth:`thickness_at`.
    """

    def __init__(self, gap, pressure, fibre_volume_per_area: float, window: int = 5):
        self.gap = np.asarray(gap, dtype=float)
        self.pressure = np.asarray(pressure, dtype=float)
        self.fibre_volume_per_area = float(fibre_volume_per_area)
        self.window = window

    def compute(self) -> CompactionCurve:
        """Smooth the pressure and derive Vf along the curve."""
        self.smoothed = smooth(self.pressure, self.window)
        self.fvf = self.fibre_volume_per_area / self.gap
        return self

    def thickness_at(self, pressure: float) -> float:
        """Gap (mm) where the smoothed pressure first reaches ``pressure``; NaN if never."""
        above = np.flatnonzero(self.smoothed >= pressure)
        if len(above) == 0:
            return float("nan")
        i = int(above[0])
        if i == 0:
            return float(self.gap[0])
        p0, p1 = self.smoothed[i - 1], self.smoothed[i]
        weight = (pressure - p0) / (p1 - p0)
        return float(self.gap[i - 1] + weight * (self.gap[i] - self.gap[i - 1]))
