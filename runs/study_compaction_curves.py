"""Example post-processing script: the compaction curves of every point of a study on one plot,
with the paper's experiment and model marked (docs/fidelity.md).

    python runs/study_compaction_curves.py STUDY_DIR OUT.png
"""

import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from ncf2lammps.io.results import read_results
from ncf2lammps.scenes.compaction import EXPERIMENT, PAPER_MODEL_THICKNESS_1KPA_MM

study, out = Path(sys.argv[1]), Path(sys.argv[2])
rows = list(csv.DictReader((study / "study.csv").open()))
knobs = [key for key in rows[0] if "." in key]
fig, ax = plt.subplots(figsize=(7.0, 4.8))
for row in rows:
    results = study / "points" / row["point"] / "results.h5"
    if not results.is_file() or "compaction" not in (data := read_results(results)):
        continue
    label = row["point"] + ": " + ", ".join(f"{k.split('.')[-1]} {row[k]}" for k in knobs)
    group = data["compaction"]
    ax.plot(group["gap_mm"], group["pressure_smoothed_kPa"], lw=1.2, label=label)
ax.plot(*zip(*EXPERIMENT, strict=True), "ks", ms=7, label="experiment (paper)")
ax.plot([PAPER_MODEL_THICKNESS_1KPA_MM], [1.0], "r^", ms=7, label="paper model at 1 kPa")
ax.set_yscale("log")
ax.set_ylim(0.05, 100.0)
ax.set_xlabel("thickness = plate gap (mm)")
ax.set_ylabel("pressure (kPa)")
ax.legend(fontsize=7)
fig.tight_layout()
fig.savefig(out, dpi=110)
print(f"wrote {out}")
