"""Example post-processing script: compaction and shear curves of several run folders side by
side, with the paper's experiment and model marked (docs/fidelity.md).

    python runs/compare_runs.py OUT.png LABEL=RUN_DIR [LABEL=RUN_DIR ...]
"""

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from ncf2lammps.io.results import read_results
from ncf2lammps.scenes.compaction import EXPERIMENT, PAPER_MODEL_THICKNESS_1KPA_MM
from ncf2lammps.scenes.shear import EXPERIMENT_FORCE_45DEG_N_PER_M, PAPER_MODEL_FORCE_45DEG_N_PER_M

if len(sys.argv) < 3 or any("=" not in arg for arg in sys.argv[2:]):
    sys.exit(__doc__.strip().splitlines()[-1].strip())
out = Path(sys.argv[1])
runs = [arg.split("=", 1) for arg in sys.argv[2:]]
fig, (press, shear) = plt.subplots(1, 2, figsize=(11.0, 4.6))
for label, folder in runs:
    data = read_results(Path(folder) / "results.h5")
    if "compaction" in data:
        group = data["compaction"]
        press.plot(group["gap_mm"], group["pressure_smoothed_kPa"], lw=1.2, label=label)
    if "shear" in data:
        group = data["shear"]
        shear.plot(group["angle_deg"], group["force_N_per_m"], lw=1.0, label=label)
press.plot(*zip(*EXPERIMENT, strict=True), "ks", ms=7, label="experiment (paper)")
press.plot([PAPER_MODEL_THICKNESS_1KPA_MM], [1.0], "r^", ms=7, label="paper model at 1 kPa")
press.set(yscale="log", ylim=(0.05, 100.0), xlabel="plate gap (mm)", ylabel="pressure (kPa)")
shear.plot([45.0], [EXPERIMENT_FORCE_45DEG_N_PER_M], "ks", ms=7, label="experiment (paper)")
shear.plot([45.0], [PAPER_MODEL_FORCE_45DEG_N_PER_M], "r^", ms=7, label="paper model")
shear.set(xlabel="shear angle (deg)", ylabel="normalised shear force F_N (N/m)")
for ax in (press, shear):
    ax.legend(fontsize=7)
fig.tight_layout()
fig.savefig(out, dpi=110)
print(f"wrote {out}")
