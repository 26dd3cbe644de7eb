"""Trajectory analyses of LAMMPS dumps read with MDAnalysis: local thickness and fibre volume
fraction of the cell on an in-plane grid, frame by frame.

The dump (``dump custom ... id mol type x y z radius``, sorted by id) is read with MDAnalysis'
LAMMPSDUMP reader; bead sizes and cylinder-equivalent fibre volumes come from the model, in the
same (id) order. A frame written twice (a resumed run writes again the steps after its
checkpoint) counts once, the later copy.
"""

from __future__ import annotations

import os
import warnings

import MDAnalysis as mda
import numpy as np
from MDAnalysis.analysis.base import AnalysisBase
from MDAnalysis.lib.mdamath import triclinic_vectors

from ..model import Model

__all__ = ["LocalThickness", "local_thickness", "unique_frames"]


class LocalThickness(AnalysisBase):
    """Local thickness and Vf on an ``(nx, ny)`` grid of the (possibly tilted) cell.

    Each bead falls in the grid cell of its centre (fractional in-plane coordinates). In each
    grid cell the thickness is the highest bead top minus the lowest bead bottom (um) and the
    local Vf is the cylinder-equivalent fibre volume of its beads over ``cell area x
    thickness``. ``results.step`` (F,), ``results.thickness`` and ``results.fvf`` (F, nx, ny).

    Args:
        atomgroup: all beads, in model (id) order.
        radius: (N,) bead radii (um).
        fibre_volume: (N,) cylinder-equivalent fibre volume of each bead (um^3; 0 for stitch).
        bins: grid cells along the cell edges a and b.
    """

    def __init__(self, atomgroup, radius, fibre_volume, bins=(8, 4), **kwargs):
        super().__init__(atomgroup.universe.trajectory, **kwargs)
        self._atoms = atomgroup
        self._radius = np.asarray(radius, dtype=float)
        self._volume = np.asarray(fibre_volume, dtype=float)
        self._bins = tuple(int(b) for b in bins)

    def _prepare(self):
        shape = (self.n_frames, *self._bins)
        self.results.step = np.zeros(self.n_frames)
        self.results.thickness = np.full(shape, np.nan)
        self.results.fvf = np.full(shape, np.nan)

    def _single_frame(self):
        nx, ny = self._bins
        box = triclinic_vectors(self._ts.dimensions).astype(float)
        positions = self._atoms.positions.astype(float)
        fractional = positions[:, :2] @ np.linalg.inv(box[:2, :2])
        index = np.floor(np.mod(fractional, 1.0) * self._bins).astype(int)
        cell = np.minimum(index[:, 0], nx - 1) * ny + np.minimum(index[:, 1], ny - 1)
        top = np.full(nx * ny, -np.inf)
        bottom = np.full(nx * ny, np.inf)
        np.maximum.at(top, cell, positions[:, 2] + self._radius)
        np.minimum.at(bottom, cell, positions[:, 2] - self._radius)
        thickness = np.where(np.isfinite(top), top - bottom, np.nan)
        volume = np.bincount(cell, weights=self._volume, minlength=nx * ny)
        area = abs(np.linalg.det(box[:2, :2])) / (nx * ny)
        self.results.step[self._frame_index] = self._ts.data.get("step", self._ts.frame)
        self.results.thickness[self._frame_index] = thickness.reshape(nx, ny)
        self.results.fvf[self._frame_index] = (volume / (area * thickness)).reshape(nx, ny)


def unique_frames(universe) -> list[int]:
    """Frame indices with one frame per time step, the last written of each, in step order."""
    steps = np.array([ts.data.get("step", ts.frame) for ts in universe.trajectory])
    _, last = np.unique(steps[::-1], return_index=True)
    return sorted((len(steps) - 1 - last).tolist(), key=lambda i: steps[i])


def local_thickness(dump: str | os.PathLike, model: Model, bins=(8, 4)) -> LocalThickness:
    """:class:`LocalThickness` run over the unique frames of a dump of ``model``: its first
    ``model.n_atoms`` beads (a hand-edited deck's added atoms come after them). ValueError for
    a dump with fewer beads than the model."""
    with warnings.catch_warnings():  # the dump has no masses and no time unit: not needed
        warnings.simplefilter("ignore", UserWarning)
        universe = mda.Universe(str(dump), format="LAMMPSDUMP")
    if len(universe.atoms) < model.n_atoms:
        raise ValueError(
            f"{dump}: {len(universe.atoms)} beads, fewer than the model's {model.n_atoms}"
        )
    fibre = model.role_mask("fibre")
    density = np.array([t.density for t in model.atom_types])[model.type_id]
    volume = np.where(fibre, model.mass / density, 0.0)
    analysis = LocalThickness(universe.atoms[: model.n_atoms], model.diameter / 2, volume, bins)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return analysis.run(frames=unique_frames(universe))
