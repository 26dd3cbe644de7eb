"""Curves to bead chains (pure numpy).

A chain is a closed (or open) polyline sampled by beads: every vertex carries a bead, and each
segment is split into equal bonds close to the target spacing. Periodic straight chains are the
special case of one segment whose end is the start shifted by a box edge.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["BeadChain", "sample_closed_polyline", "sample_open_polyline"]


@dataclass(frozen=True)
class BeadChain:
    """Beads of closed chains.

    Attributes:
        positions: (N, 3) float, bead centres (unwrapped; the caller wraps into the box).
        bonds: (M, 2) int, 0-based bead indices of consecutive beads (chains closed).
        bond_length: (M,) float, rest length of each bond (its length at generation).
        segment: (M,) int, index of the polyline segment each bond lies on.
        length_per_bead: (N,) float, chain length each bead stands for (mean of its two bonds).
    """

    positions: np.ndarray
    bonds: np.ndarray
    bond_length: np.ndarray
    segment: np.ndarray
    length_per_bead: np.ndarray


def _sample_segments(starts: np.ndarray, ends: np.ndarray, spacing: float, min_bonds: int):
    """Beads at each segment's start and equal bonds along it.

    Args:
        starts, ends: (S, 3) float, segment end points (um).
        spacing: target bond length (um); segment ``j`` gets
            ``max(min_bonds, round(L_j / spacing))`` equal bonds.
        min_bonds: the fewest bonds on a segment.

    Returns:
        positions (M, 3) float (bond starts, in order), segment (M,) int (segment of each bond),
        bond_length (M,) float.
    """
    delta = ends - starts
    seg_length = np.linalg.norm(delta, axis=1)
    if np.any(seg_length <= 0.0):
        raise ValueError("polyline has a zero-length segment")
    n_bonds = np.maximum(min_bonds, np.rint(seg_length / spacing)).astype(np.int64)
    segment = np.repeat(np.arange(len(starts)), n_bonds)
    first_bond = np.concatenate([[0], np.cumsum(n_bonds)[:-1]])
    fraction = (np.arange(n_bonds.sum()) - first_bond[segment]) / n_bonds[segment]
    positions = starts[segment] + fraction[:, None] * delta[segment]
    return positions, segment, (seg_length / n_bonds)[segment]


def sample_closed_polyline(vertices: np.ndarray, closing_shift: np.ndarray, spacing: float):
    """Sample a closed polyline with beads at every vertex and equal bonds on each segment.

    Args:
        vertices: (V, 3) float, polyline vertices in order (um).
        closing_shift: (3,) float, the path closes on ``vertices[0] + closing_shift`` (a periodic
            translation; zeros for a loop that closes in place).
        spacing: target bond length (um); segment ``j`` gets ``max(1, round(L_j / spacing))``
            equal bonds.

    Returns:
        :class:`BeadChain` of one closed chain with ``N = M`` beads and bonds.
    """
    vertices = np.asarray(vertices, dtype=float)
    ends = np.vstack([vertices[1:], vertices[:1] + np.asarray(closing_shift, dtype=float)])
    positions, segment, bond_length = _sample_segments(vertices, ends, spacing, 1)
    n = len(positions)
    bonds = np.column_stack([np.arange(n), (np.arange(n) + 1) % n])
    length_per_bead = 0.5 * (bond_length + np.roll(bond_length, 1))
    return BeadChain(positions, bonds, bond_length, segment, length_per_bead)


def sample_open_polyline(vertices: np.ndarray, spacing: float, min_bonds: int = 1):
    """Sample an open polyline with beads at every vertex and equal bonds on each segment.

    Args:
        vertices: (V, 3) float, polyline vertices in order (um), V >= 2.
        spacing: target bond length (um); segment ``j`` gets
            ``max(min_bonds, round(L_j / spacing))`` equal bonds.
        min_bonds: the fewest bonds on a segment (2 puts a bead inside every segment).

    Returns:
        positions (M + 1, 3) float, the beads from ``vertices[0]`` to ``vertices[-1]``, and
        bond_length (M,) float, the length of the bond after each bead but the last.
    """
    vertices = np.asarray(vertices, dtype=float)
    positions, _, bond_length = _sample_segments(vertices[:-1], vertices[1:], spacing, min_bonds)
    return np.vstack([positions, vertices[-1:]]), bond_length
