"""The stitch yarn: its tensions and length, where its bonds broke and when the first one did;
where its holes lie.

Holes (docs/stitch.md): a yarn runs on the loop face (top) and the underlap face (bottom) and
passes through the mat at its needle holes; a hole is where the yarn's path crosses its
mid-height. Hole positions are compared in fractional coordinates of the cell (:meth:`Box.fractional
<ncf2lammps.model.Box.fractional>`): an affine deformation of the cell
(the shear's box) leaves them unchanged, so a change is the yarn moving through the mat.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import Box

__all__ = [
    "YarnHoles",
    "bond_lengths",
    "bond_midpoints",
    "bond_tensions",
    "broken_bonds",
    "first_break",
    "hole_alignment",
    "hole_slip",
    "path_strains",
    "shog_width_ratio",
    "yarn_holes",
]

#: A face is reached where the path lies this fraction of the yarn's height span (5th to 95th
#: percentile of z) above or below its mid-height; in between the yarn is in a hole's leg.
FACE_BAND = 0.1


def _pair_keys(bonds: np.ndarray, base: int) -> np.ndarray:
    """(B,) int, one key per unordered bead pair of the (B, 2) bead indices (each < ``base``)."""
    ordered = np.sort(bonds, axis=1).astype(np.int64)
    return ordered[:, 0] * base + ordered[:, 1]


def broken_bonds(before: np.ndarray, after: np.ndarray) -> np.ndarray:
    """(K,) indices into ``before`` ((B, 2) bead indices) of the bonds missing from ``after``
    ((B', 2)): the bonds broken between two states."""
    base = int(max(before.max(initial=-1), after.max(initial=-1))) + 1
    gone = ~np.isin(_pair_keys(before, base), _pair_keys(after, base))
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


def bond_lengths(positions: np.ndarray, box: Box, bonds: np.ndarray) -> np.ndarray:
    """(B,) lengths (um) of the (B, 2) ``bonds`` between the (N, 3) ``positions`` (um) in
    ``box`` (periodic in x and y, any tilt)."""
    delta = box.minimum_image(positions[bonds[:, 1]] - positions[bonds[:, 0]])
    return np.linalg.norm(delta, axis=1)


def bond_tensions(
    positions: np.ndarray, box: Box, bonds: np.ndarray, k: np.ndarray, r0: np.ndarray
) -> np.ndarray:
    """(B,) tensions ``2 K (r - r0)`` (nN; negative in compression) of the (B, 2) harmonic
    ``bonds`` between the (N, 3) ``positions`` (um) in ``box`` (periodic in x and y, any tilt),
    with per-bond ``k`` (nN/um) and rest length ``r0`` (um), (B,) each."""
    return 2.0 * k * (bond_lengths(positions, box, bonds) - r0)


def path_strains(
    positions: tuple[np.ndarray, np.ndarray], boxes: tuple[Box, Box], bonds: np.ndarray
) -> tuple[float, float]:
    """(actual, affine): the relative change in total length of the (B, 2) ``bonds`` from the
    first state to the second (``positions`` (N, 3) um and ``boxes`` of each), and the change
    the boxes' in-plane deformation alone would give, every bond vector of the first state
    mapped by ``F = h1 h0^-1`` in x and y with z unchanged."""
    (before, after), (box0, box1) = positions, boxes
    vectors = box0.minimum_image(before[bonds[:, 1]] - before[bonds[:, 0]])
    deform = np.eye(3)
    deform[:2, :2] = box1.matrix[:2, :2] @ np.linalg.inv(box0.matrix[:2, :2])
    length = np.linalg.norm(vectors, axis=1).sum()
    actual = bond_lengths(after, box1, bonds).sum() / length - 1.0
    affine = np.linalg.norm(vectors @ deform.T, axis=1).sum() / length - 1.0
    return float(actual), float(affine)


def first_break(abscissa: np.ndarray, broken: np.ndarray) -> float:
    """The ``abscissa`` (angle, gap, ...) of the first record with a broken bond; nan if none
    broke. ``abscissa`` and the cumulative count ``broken`` are (R,) in record order."""
    hit = np.flatnonzero(broken > 0)
    return float(abscissa[hit[0]]) if hit.size else float("nan")


@dataclass(frozen=True)
class YarnHoles:
    """The holes of one closed yarn, in path order.

    Attributes:
        fractional: (H, 3) hole positions, fractional coordinates of the cell, unwrapped along
            the path (consecutive holes differ by the path between them).
        face: (H,) +1 where the path leaves the hole on the top face, -1 on the bottom face.
        path_um: (H,) length of the path from each hole to the next (um).
        period: (3,) fractional vector from a point of the yarn to its next image along it.
    """

    fractional: np.ndarray
    face: np.ndarray
    path_um: np.ndarray
    period: np.ndarray

    @property
    def spans(self) -> np.ndarray:
        """(H, 3) fractional vector from each hole to the next (the last to the first's image)."""
        following = np.roll(self.fractional, -1, axis=0)
        following[-1] += self.period
        return following - self.fractional


def yarn_holes(positions: np.ndarray, box: Box, beads: np.ndarray) -> YarnHoles:
    """The holes of the closed yarn through ``beads`` ((K,) bead indices in path order, the last
    bonded to the first) of the (N, 3) ``positions`` (um) in the periodic ``box`` (x, y). A yarn
    that never reaches both faces has no hole (empty arrays)."""
    h = box.matrix
    path = positions[beads]
    fractional_steps = np.linalg.solve(h, (np.roll(path, -1, axis=0) - path).T).T
    fractional_steps[:, :2] -= np.rint(fractional_steps[:, :2])
    steps = fractional_steps @ h.T
    period = fractional_steps.sum(axis=0)
    z = path[:, 2]  # z is not periodic
    low, high = np.percentile(z, [5.0, 95.0])
    middle, band = 0.5 * (low + high), FACE_BAND * (high - low)
    state = np.where(z > middle + band, 1, np.where(z < middle - band, -1, 0))
    if not ((state > 0).any() and (state < 0).any()):
        return YarnHoles(np.zeros((0, 3)), np.zeros(0, int), np.zeros(0), period)
    # walk the closed path once round from its first bead on a face (K + 1 points), carrying
    # the last face reached
    start = int(np.flatnonzero(state)[0])
    order = np.arange(start, start + len(beads) + 1)
    walk = path[start] + np.concatenate(
        [[np.zeros(3)], np.cumsum(steps[order[:-1] % len(beads)], axis=0)]
    )
    reached = state[order % len(beads)]
    last_on_face = np.maximum.accumulate(np.where(reached != 0, np.arange(len(order)), 0))
    held = reached[last_on_face]
    # a hole: the first bond where the path crosses mid-height after the last bead on one face
    changes = np.flatnonzero(held[1:] != held[:-1]) + 1
    above = walk[:, 2] > middle
    crossings = np.flatnonzero(above[1:] != above[:-1])
    bonds = crossings[np.searchsorted(crossings, last_on_face[changes - 1])]
    a, b = walk[bonds], walk[bonds + 1]
    t = (middle - a[:, 2]) / (b[:, 2] - a[:, 2])
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(walk, axis=0), axis=1))])
    arcs = arc[bonds] + t * (arc[bonds + 1] - arc[bonds])
    return YarnHoles(
        fractional=box.fractional(a + t[:, None] * (b - a)),
        face=held[changes],
        path_um=np.diff(np.append(arcs, arcs[0] + arc[-1])),
        period=period,
    )


def hole_alignment(reference: YarnHoles, current: YarnHoles) -> int | None:
    """The cyclic shift of ``current``'s holes that matches ``reference``'s (the shift with the
    same faces and the nearest in-plane positions, periodic); None if their counts or faces
    cannot be matched."""
    count = len(reference.face)
    if count == 0 or len(current.face) != count:
        return None
    best, best_distance = None, np.inf
    for shift in range(count):
        if not np.array_equal(np.roll(current.face, -shift), reference.face):
            continue
        delta = np.roll(current.fractional, -shift, axis=0)[:, :2] - reference.fractional[:, :2]
        distance = np.abs(delta - np.rint(delta)).sum()
        if distance < best_distance:
            best, best_distance = shift, distance
    return best


def shog_width_ratio(
    reference: list[YarnHoles], current: list[YarnHoles], threshold: float = 0.01
) -> float:
    """Width across the wales (along the cell's edge b) of the yarns' shogging face runs in
    ``current``, over their width in ``reference`` (the same yarns' holes, e.g. as generated):
    1 where the holes keep the lapping's needle positions, 0 where every underlap has pulled
    straight. A run shogs where its reference span along b exceeds ``threshold`` x the largest
    one. nan without shogging runs (a chain stitch) or with holes that do not match."""
    total_reference, total_current = 0.0, 0.0
    for ref, cur in zip(reference, current, strict=True):
        shift = hole_alignment(ref, cur)
        if shift is None:
            return float("nan")
        across_ref = np.abs(ref.spans[:, 1])
        across_cur = np.abs(np.roll(cur.spans, -shift, axis=0)[:, 1])
        shogs = across_ref > threshold * max(across_ref.max(), 1e-300)
        total_reference += across_ref[shogs].sum()
        total_current += across_cur[shogs].sum()
    return total_current / total_reference if total_reference > 0 else float("nan")


def hole_slip(
    reference: list[YarnHoles], current: list[YarnHoles], cell: np.ndarray, drift: np.ndarray
) -> float:
    """RMS in-plane distance (um) the holes moved through the mat from ``reference`` to
    ``current``: the change of their fractional positions less the mat's rigid ``drift`` ((3,)
    fractional, e.g. the fibres' mean displacement), measured in the reference ``cell``
    ((3, 3), :attr:`Box.matrix <ncf2lammps.model.Box.matrix>`). nan with holes that do not
    match."""
    moved = []
    for ref, cur in zip(reference, current, strict=True):
        shift = hole_alignment(ref, cur)
        if shift is None:
            return float("nan")
        delta = np.roll(cur.fractional, -shift, axis=0) - ref.fractional - drift
        delta[:, :2] -= np.rint(delta[:, :2])
        delta[:, 2] = 0.0
        moved.append(delta @ cell.T)
    if not moved:
        return float("nan")
    return float(np.sqrt((np.concatenate(moved)[:, :2] ** 2).sum(axis=1).mean()))
