"""Text outputs of LAMMPS: ``fix ave/time ... file`` tables."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

__all__ = ["read_ave_time"]


def read_ave_time(path: str | os.PathLike) -> dict[str, np.ndarray]:
    """Columns of a scalar ``fix ave/time`` file by name (``TimeStep``, ``v_time``, ...).

    Rows are returned in file order; a row cut short by a killed run is dropped.
    """
    lines = Path(path).read_text().splitlines()
    header = [ln for ln in lines if ln.startswith("#")][-1].lstrip("#").split()
    rows = [ln.split() for ln in lines if ln.strip() and not ln.startswith("#")]
    rows = [r for r in rows if len(r) == len(header)]
    table = np.array(rows, dtype=float).reshape(-1, len(header))
    return {name: table[:, j] for j, name in enumerate(header)}
