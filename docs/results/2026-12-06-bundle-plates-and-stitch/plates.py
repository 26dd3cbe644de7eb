"""Where each bead type lies against the compaction plates, per dump frame.

Usage: python plates.py RUN

Reads RUN/compaction.lammpstrj (columns id mol type x y z radius), RUN/compaction.history.txt
and the bottom plate's height from RUN/log.compaction.lammps. Prints per frame the gap and the
pressure of its record and, per atom type, how far the lowest bead surface lies below the
bottom plate and the highest above the top plate (um; positive: past the plate).
"""

import re
import sys
from pathlib import Path

import numpy as np

run = Path(sys.argv[1])
log = (run / "log.compaction.lammps").read_text()
bottom = float(re.findall(r"variable\s+plate_bottom equal (\S+)", log)[-1])
history = np.loadtxt(run / "compaction.history.txt")
for frame in (run / "compaction.lammpstrj").read_text().split("ITEM: TIMESTEP\n")[1:]:
    lines = frame.splitlines()
    step, count = int(lines[0]), int(lines[2])
    atoms = np.loadtxt(lines[8 : 8 + count])
    kind, z, radius = atoms[:, 2].astype(int), atoms[:, 5], atoms[:, 6]
    record = history[np.argmin(np.abs(history[:, 0] - step))]
    gap, pressure = record[2], record[5]
    past = [
        f"type {t}: {bottom - (z - radius)[kind == t].min():+7.1f} / "
        f"{(z + radius)[kind == t].max() - (bottom + gap):+7.1f}"
        for t in np.unique(kind)
    ]
    print(f"step {step} gap {gap:7.1f} um P {pressure:7.3f} kPa  " + "  ".join(past))
