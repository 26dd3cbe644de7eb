"""The bead model: an immutable struct of numpy arrays built from a :class:`FabricSpec`.

All quantities are in LAMMPS ``micro`` units (um, pg, us, nN, kPa); indices are 0-based. Beads
stand for cylinders: bead density is set so that mass per chain length equals
``fill rho pi d^2 / 4`` (0.75 rho at spacing d/2 and fill 1), and volumes and Vf always use the
fibre volume, ``fill`` times the cylinder's (``fill``: the chain's internal fibre volume fraction,
1 in the paper's model). Options beyond the paper (docs/fidelity.md) are off by default.

Modules: ``core`` (the types and :class:`Model`), ``parts`` (:class:`Part` and :func:`join`, which
assembles every model), ``builder`` (:func:`build_model`: a part per ply, one for the stitch).
"""

from .builder import MAX_BEADS, build_model
from .core import AngleType, AtomType, BondType, Box, Model
from .parts import Part, join

__all__ = [
    "MAX_BEADS",
    "AngleType",
    "AtomType",
    "BondType",
    "Box",
    "Model",
    "Part",
    "build_model",
    "join",
]
