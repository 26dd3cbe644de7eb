"""The stitch yarn under load: where its bonds broke, and when the first one did."""

from __future__ import annotations

import numpy as np

__all__ = ["bond_midpoints", "broken_bonds", "first_break"]


def _pair_keys(bonds: np.ndarray, n_atoms: int) -> np.ndarray:
    """(B,) int, one key per unordered bead pair of the (B, 2) bead indices."""
    ordered = np.sort(bonds, axis=1).astype(np.int64)
    return ordered[:, 0] * n_atoms + ordered[:, 1]


def broken_bonds(before: np.ndarray, after: np.ndarray, n_atoms: int) -> np.ndarray:
    """(K,) indices into ``before`` ((B, 2) bead indices) of the bonds missing from ``after``
    ((B', 2)): the bonds broken between two states of ``n_atoms`` beads."""
    gone = ~np.isin(_pair_keys(before, n_atoms), _pair_keys(after, n_atoms))
    return np.flatnonzero(gone)


def bond_midpoints(positions: np.ndarray, bonds: np.ndarray, lo: np.ndarray, lengths: np.ndarray):
    """(B, 3) midpoints (um) of the (B, 2) bonds between the (N, 3) ``positions`` of an
    orthogonal box (corner ``lo``, edge ``lengths``, periodic in x and y), wrapped into it."""
    start = positions[bonds[:, 0]]
    delta = positions[bonds[:, 1]] - start
    delta[:, :2] -= np.rint(delta[:, :2] / lengths[:2]) * lengths[:2]
    middle = start + 0.5 * delta
    middle[:, :2] = lo[:2] + np.mod(middle[:, :2] - lo[:2], lengths[:2])
    return middle


def first_break(abscissa: np.ndarray, broken: np.ndarray) -> float:
    """The ``abscissa`` (angle, gap, ...) of the first record with a broken bond; nan if none
    broke. ``abscissa`` and the cumulative count ``broken`` are (R,) in record order."""
    hit = np.flatnonzero(broken > 0)
    return float(abscissa[hit[0]]) if hit.size else float("nan")
