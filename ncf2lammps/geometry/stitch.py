"""The idealised stitch yarn from warp-knitting lapping notation (pure numpy).

Convention (docs/stitch.md): course ``k`` of a repeat is the overlap ``a-b``; its needle is
``n = min(a, b)`` and its hole sits at ``x_k = (k + 1/2) l_s``, ``y_k = (n + w + 1/2) g`` for the
yarn of wale ``w`` (``l_s`` stitch length, ``g`` gauge). The yarn passes through the holes in
course order, with sharp corners, alternately rising and sinking: from hole ``k`` to hole
``k + 1`` it runs straight on the loop face (top) after a rise and on the underlap face (bottom)
after a sink. Every face segment thus spans fibres between two different holes, so the
pretensioned yarn presses the mat together instead of slipping back through its own hole. For
tricot-chain (needles A A B B) the loop face shows straight loops along the wales and the
underlap face the diagonal zigzag between wales. A cell holds an even number of courses so the
path closes on itself; after them it continues shifted by the cell length along x. Every corner
is a right angle, so with ``special_bonds lj 0 0 1`` no bead near a corner overlaps a third
neighbour.

Interlooping (:attr:`StitchPath.link_corners`): in the knitted fabric each new loop is drawn
through the loop of the course before on the same needle, so the loops of a wale hold one
another. The links stand for that: on the loop face, straight along x, from the top corner
where a yarn sinks (odd course ``k``) to the top corner where the course ``k + 1`` rises on the
same needle (the same yarn in a chain stitch, the neighbouring wale's yarn in a tricot). With
full threading every needle has a hole at every course, so every sinking hole has its link.
A sliding link ends in a ring (:func:`slip_rings`) around the rising yarn's leg instead of on its
corner: the yarn can slip through the interlock, held by contact and friction alone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["SEGMENT_KINDS", "StitchPath", "slip_rings", "stitch_path"]

#: Names of the segment kinds, indexed by :attr:`StitchPath.kind`; ``link`` and ``ring`` name
#: the interlooping links and their slip rings (not segments of a yarn's path).
SEGMENT_KINDS = ("leg", "loop", "underlap", "link", "ring")


@dataclass(frozen=True)
class StitchPath:
    """Polylines of all stitch yarns in the cell (lengths in um).

    Attributes:
        yarn_vertices: (W, V, 3) float, unwrapped corner points of each wale's yarn.
        closing_shift: (3,) float, each yarn closes on its first vertex shifted by this.
        kind: (V,) int, kind of the segment starting at each vertex (see :data:`SEGMENT_KINDS`).
        needle_points: (P, 2) float, hole centres (x, y) wrapped into the cell, one per
            course and wale.
        link_corners: (L, 2, 2) int, per interlooping link the (yarn, vertex) of its start (the
            top corner where a yarn sinks) and of its end (the top corner where the next course
            rises on the same needle); one link per sinking hole.
        link_vector: (3,) float, every link runs from its start vertex by this vector (one stitch
            length along x on the loop face); the end vertex is its image in the periodic cell.
    """

    yarn_vertices: np.ndarray
    closing_shift: np.ndarray
    kind: np.ndarray
    needle_points: np.ndarray
    link_corners: np.ndarray
    link_vector: np.ndarray


def stitch_path(
    overlaps: tuple[tuple[int, int], ...],
    gauge: float,
    stitch_length: float,
    cell: tuple[float, float],
    z_bottom: float,
    z_top: float,
) -> StitchPath:
    """Corner points of the idealised stitch yarns filling a periodic cell.

    Args:
        overlaps: lapping of one repeat, ``((a, b), ...)``, one per course.
        gauge, stitch_length: needle spacing (y) and course spacing (x), um.
        cell: (length x, width y) of the cell, um; holds a whole, even number of courses and a
            whole number of wales.
        z_bottom, z_top: heights of the underlap face and the loop face, um.
    """
    a, b = np.asarray(overlaps, dtype=np.int64).T
    n_courses = round(cell[0] / stitch_length)
    n_wales = round(cell[1] / gauge)
    needle = np.resize(np.minimum(a, b), n_courses)
    x = (np.arange(n_courses) + 0.5) * stitch_length
    y = (needle + 0.5) * gauge
    # Two corners per hole: rise (bottom, top) at even courses, sink (top, bottom) at odd ones.
    rising = np.arange(n_courses) % 2 == 0
    z_first = np.where(rising, z_bottom, z_top)
    z_second = np.where(rising, z_top, z_bottom)
    one_yarn = np.column_stack(
        [np.repeat(x, 2), np.repeat(y, 2), np.column_stack([z_first, z_second]).ravel()]
    )
    kind = np.column_stack([np.zeros(n_courses, dtype=np.int64), np.where(rising, 1, 2)]).ravel()
    wale_shift = np.zeros((n_wales, 1, 3))
    wale_shift[:, 0, 1] = np.arange(n_wales) * gauge
    holes_x = np.repeat(x, n_wales)
    holes_y = (np.add.outer(y, np.arange(n_wales) * gauge) % cell[1]).ravel()
    # Links: the yarn w sinking at odd course k stands on needle needle[k] + w; at course k + 1
    # that needle holds the yarn w' = w + needle[k] - needle[k + 1] (mod wales), rising.
    sinking = np.arange(1, n_courses, 2)
    following = (sinking + 1) % n_courses
    wale = np.arange(n_wales)
    start_yarn = np.repeat(wale[None, :], len(sinking), axis=0)
    end_yarn = (start_yarn + (needle[sinking] - needle[following])[:, None]) % n_wales
    start_vertex = np.repeat(2 * sinking[:, None], n_wales, axis=1)
    end_vertex = np.repeat(2 * following[:, None] + 1, n_wales, axis=1)
    starts = np.stack([start_yarn, start_vertex], axis=-1).reshape(-1, 2)
    ends = np.stack([end_yarn, end_vertex], axis=-1).reshape(-1, 2)
    return StitchPath(
        yarn_vertices=one_yarn[None, :, :] + wale_shift,
        closing_shift=np.array([cell[0], 0.0, 0.0]),
        kind=kind,
        needle_points=np.column_stack([holes_x, holes_y]),
        link_corners=np.stack([starts, ends], axis=1),
        link_vector=np.array([stitch_length, 0.0, 0.0]),
    )


def slip_rings(centres: np.ndarray, radius: float, n_beads: int) -> np.ndarray:
    """(L, n_beads, 3) bead centres of horizontal rings of ``radius`` (um) around ``centres``
    ((L, 3) um), in order around each ring, bead 0 on the ring's -x side."""
    angle = np.pi + 2.0 * np.pi * np.arange(n_beads) / n_beads
    circle = radius * np.column_stack([np.cos(angle), np.sin(angle), np.zeros(n_beads)])
    return np.asarray(centres, dtype=float)[:, None, :] + circle[None, :, :]
