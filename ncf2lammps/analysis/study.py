"""Error against run time: relative errors of a study's outputs and its Pareto front."""

from __future__ import annotations

import numpy as np

__all__ = ["pareto_front", "relative_errors"]


def relative_errors(values: np.ndarray, reference: int) -> np.ndarray:
    """(P, K) |x - x_ref| / |x_ref| of P points' K outputs against row ``reference``.

    An output the reference lacks (NaN) gives NaN errors; a point without a value gives NaN.
    """
    values = np.asarray(values, dtype=float)
    ref = values[reference]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.abs(values - ref) / np.abs(ref)


def pareto_front(wall_s: np.ndarray, error: np.ndarray) -> np.ndarray:
    """(P,) mask of the points no other point beats on both wall time and error.

    A point is on the front when every faster point has a larger error (NaN errors never are).
    """
    wall_s = np.asarray(wall_s, dtype=float)
    error = np.asarray(error, dtype=float)
    order = np.lexsort((error, wall_s))
    best = np.minimum.accumulate(np.where(np.isnan(error[order]), np.inf, error[order]))
    previous_best = np.concatenate([[np.inf], best[:-1]])
    front = np.zeros(len(wall_s), dtype=bool)
    front[order] = error[order] < previous_best
    return front
