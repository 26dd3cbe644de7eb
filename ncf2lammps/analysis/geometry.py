"""Geometric measures of bead configurations in the periodic cell (x, y periodic, z open)."""

from __future__ import annotations

import numpy as np
from MDAnalysis.lib.distances import capped_distance

__all__ = ["max_overlap", "min_xy_distance"]


def _min_image_xy(delta: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    out = np.array(delta, dtype=float)
    out[..., :2] -= np.rint(out[..., :2] / lengths[:2]) * lengths[:2]
    return out


def min_xy_distance(positions: np.ndarray, points: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """(P,) smallest in-plane distance from each point to any position, periodic images included.

    Args:
        positions: (N, 3) bead centres (um).
        points: (P, 2) needle axes (x, y) (um).
        lengths: (3,) box edges (um); x and y periodic (orthogonal box).
    """
    delta = positions[None, :, :2] - np.asarray(points)[:, None, :]
    delta = _min_image_xy(delta, lengths)
    return np.sqrt((delta**2).sum(axis=-1)).min(axis=1)


def max_overlap(
    positions: np.ndarray,
    diameter: np.ndarray,
    first: np.ndarray,
    second: np.ndarray,
    lengths: np.ndarray,
    mol_id: np.ndarray | None = None,
) -> tuple[float, int, int]:
    """Largest overlap ``(r_i + r_j) - |x_i - x_j|`` between a bead of ``first`` and one of ``second``.

    Args:
        positions: (N, 3) bead centres (um); diameter: (N,) (um).
        first, second: (N,) bool masks of the two groups.
        lengths: (3,) orthogonal box edges; x, y periodic, z open.
        mol_id: (N,) chain of each bead; given, pairs of one chain are left out.

    Returns:
        (overlap in um, index i, index j); overlap <= 0 means no contact (then i = j = -1).
    """
    a, b = np.flatnonzero(first), np.flatnonzero(second)
    cutoff = float(diameter.max())
    z0 = positions[:, 2].min() - cutoff
    lz = 10.0 * (np.ptp(positions[:, 2]) + 2.0 * cutoff)
    box = np.array([lengths[0], lengths[1], lz, 90.0, 90.0, 90.0])
    shifted = positions - np.array([0.0, 0.0, z0])
    pairs, distances = capped_distance(shifted[a], shifted[b], cutoff, box=box)
    if len(pairs) == 0:
        return 0.0, -1, -1
    i, j = a[pairs[:, 0]], b[pairs[:, 1]]
    if mol_id is not None:
        keep = mol_id[i] != mol_id[j]
        i, j, distances = i[keep], j[keep], distances[keep]
        if len(i) == 0:
            return 0.0, -1, -1
    overlap = 0.5 * (diameter[i] + diameter[j]) - distances
    k = int(np.argmax(overlap))
    if overlap[k] <= 0.0:
        return float(overlap[k]), -1, -1
    return float(overlap[k]), int(i[k]), int(j[k])
