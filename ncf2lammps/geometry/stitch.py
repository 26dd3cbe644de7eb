"""The idealised stitch yarn from warp-knitting lapping notation (pure numpy).

Convention (docs/stitch.md): course ``k`` of a repeat of ``K`` courses is the overlap ``a-b``;
its needle is ``n = min(a, b)`` and its hole sits at ``x_k = (k + 1/2) l_s``,
``y_k = (n + w + 1/2) g`` for the yarn of wale ``w`` (``l_s`` stitch length, ``g`` gauge). At each
hole the yarn makes a loop with sharp corners: it rises through the hole on the side of gap ``a``
(``y_k +- e``), crosses over the needle on the loop face (top, ``z_top``) to the side of gap ``b``
and goes down again. On the underlap face (bottom, ``z_bottom``) it runs straight from hole ``k``
to hole ``k + 1``: underlaps from one wale to the next draw the zigzag of tricot, underlaps within
a wale the straight lines of chain (pillar). After the repeat the path continues shifted by
``K l_s`` along x, so one yarn per wale closes on itself through the periodic boundary.
Every corner is a right angle, so with ``special_bonds lj 0 0 1`` no bead near a corner overlaps
a third neighbour.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["SEGMENT_KINDS", "StitchPath", "stitch_path"]

#: Names of the segment kinds, indexed by :attr:`StitchPath.kind`.
SEGMENT_KINDS = ("leg_up", "loop", "leg_down", "underlap")


@dataclass(frozen=True)
class StitchPath:
    """Polylines of all stitch yarns in the cell (lengths in um).

    Attributes:
        yarn_vertices: (W, V, 3) float, unwrapped corner points of each wale's yarn.
        closing_shift: (3,) float, each yarn closes on its first vertex shifted by this.
        kind: (V,) int, kind of the segment starting at each vertex (see :data:`SEGMENT_KINDS`).
        needle_points: (P, 2) float, hole centres (x, y) wrapped into the cell, one per
            course and wale.
    """

    yarn_vertices: np.ndarray
    closing_shift: np.ndarray
    kind: np.ndarray
    needle_points: np.ndarray


def stitch_path(
    overlaps: tuple[tuple[int, int], ...],
    gauge: float,
    stitch_length: float,
    cell: tuple[float, float],
    leg_offset: float,
    z_bottom: float,
    z_top: float,
) -> StitchPath:
    """Corner points of the idealised stitch yarns filling a periodic cell.

    Args:
        overlaps: lapping of one repeat, ``((a, b), ...)``, one per course.
        gauge, stitch_length: needle spacing (y) and course spacing (x), um.
        cell: (length x, width y) of the cell, whole multiples of the repeat, um.
        leg_offset: half the distance between the two legs of a loop, um.
        z_bottom, z_top: heights of the underlap face and the loop face, um.
    """
    a, b = np.asarray(overlaps, dtype=np.int64).T
    n_repeats = round(cell[0] / (len(a) * stitch_length))
    n_wales = round(cell[1] / gauge)
    needle = np.minimum(a, b)
    side_a = np.where(a > needle, 1.0, -1.0)
    needle = np.tile(needle, n_repeats)
    side_a = np.tile(side_a, n_repeats)
    n_courses = len(needle)
    x = (np.arange(n_courses) + 0.5) * stitch_length
    y = (needle + 0.5) * gauge
    # Four corners per course: bottom and top of the leg on side a, top and bottom on side b.
    corner_x = np.repeat(x, 4)
    corner_y = np.repeat(y, 4) + leg_offset * np.repeat(side_a, 4) * np.tile(
        [1, 1, -1, -1], n_courses
    )
    corner_z = np.tile([z_bottom, z_top, z_top, z_bottom], n_courses)
    one_yarn = np.column_stack([corner_x, corner_y, corner_z])
    wale_shift = np.zeros((n_wales, 1, 3))
    wale_shift[:, 0, 1] = np.arange(n_wales) * gauge
    yarns = one_yarn[None, :, :] + wale_shift
    kind = np.tile(np.arange(4), n_courses)
    holes_x = np.repeat(x, n_wales)
    holes_y = (np.add.outer(y, np.arange(n_wales) * gauge) % cell[1]).ravel()
    return StitchPath(
        yarn_vertices=yarns,
        closing_shift=np.array([cell[0], 0.0, 0.0]),
        kind=kind,
        needle_points=np.column_stack([holes_x, holes_y]),
    )
