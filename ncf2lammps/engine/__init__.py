"""LAMMPS for ncf2lammps: the engine, the run loop of a deck, its journal and checkpoints.

:mod:`.core` is the only module that imports ``lammps``; :mod:`.deckrun` runs a deck in chunks
(its docstring writes the loop out); :mod:`.journal` journals the run, writes the checkpoints
and replays a deck on resume. Nothing here changes the working directory: relative paths
resolve against the process's.
"""

from .core import Engine, EngineError, UnstableRunError, lammps_version, load_lammps
from .deckrun import run_deck
from .journal import CheckpointError, Checkpoints

__all__ = [
    "CheckpointError",
    "Checkpoints",
    "Engine",
    "EngineError",
    "UnstableRunError",
    "lammps_version",
    "load_lammps",
    "run_deck",
]
