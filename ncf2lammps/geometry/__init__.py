"""Pure-numpy geometry: mat chains, stitch yarn paths, curve-to-bead sampling."""

from .chains import BeadChain, sample_closed_polyline, sample_open_polyline
from .mat import PlyLayout, ply_chains, ply_layout
from .stitch import SEGMENT_KINDS, StitchPath, slip_rings, stitch_path

__all__ = [
    "SEGMENT_KINDS",
    "BeadChain",
    "PlyLayout",
    "StitchPath",
    "ply_chains",
    "ply_layout",
    "sample_closed_polyline",
    "sample_open_polyline",
    "slip_rings",
    "stitch_path",
]
