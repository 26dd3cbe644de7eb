"""Text outputs of LAMMPS: ``fix ave/time ... file`` tables, ``print ... file`` lines, logs."""

from __future__ import annotations

import itertools
import os
import re
from pathlib import Path

import numpy as np

__all__ = ["read_ave_time", "read_final", "read_loop_times", "scene_steps"]


def read_ave_time(path: str | os.PathLike) -> dict[str, np.ndarray]:
    """Columns of a scalar ``fix ave/time`` file by name (``TimeStep``, ``v_time``, ...).

    Rows are returned by time step, one per step (the last written wins: a resumed run writes
    again the steps after its checkpoint); a row cut short by a killed run is dropped.
    """
    lines = Path(path).read_text().splitlines()
    header = [ln for ln in lines if ln.startswith("#")][-1].lstrip("#").split()
    rows = [ln.split() for ln in lines if ln.strip() and not ln.startswith("#")]
    rows = [r for r in rows if len(r) == len(header)]
    table = np.array(rows, dtype=float).reshape(-1, len(header))
    _, last = np.unique(table[::-1, 0], return_index=True)
    table = table[len(table) - 1 - last]
    return {name: table[:, j] for j, name in enumerate(header)}


def read_final(path: str | os.PathLike) -> dict[str, float]:
    """Numbers of a scene's closing ``print ... file`` line, by the word before each
    (``ncf2lammps shear: step 120 angle 45 deg`` gives ``{"step": 120.0, "angle": 45.0}``)."""
    words = Path(path).read_text().split()
    out = {}
    for name, value in itertools.pairwise(words):
        try:
            out[name] = float(value)
        except ValueError:
            continue
    return out


def scene_steps(path: str | os.PathLike) -> int:
    """Steps a scene ran (its closing line's ``step`` minus ``from``, the step it started at:
    a scene read from a restart file continues the step count of the scene before it)."""
    final = read_final(path)
    return int(final["step"] - final.get("from", 0.0))


_LOOP = re.compile(r"^Loop time of (\S+) on (\d+) procs")


def read_loop_times(path: str | os.PathLike) -> tuple[float, int]:
    """(wall seconds summed over ``run`` commands, MPI ranks) of a LAMMPS log file."""
    seconds, ranks = 0.0, 1
    for line in Path(path).read_text(errors="replace").splitlines():
        if match := _LOOP.match(line):
            seconds += float(match.group(1))
            ranks = int(match.group(2))
    return seconds, ranks
