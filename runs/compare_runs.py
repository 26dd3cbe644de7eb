"""Example post-processing script: compaction (and shear, where run) curves of several run
folders or of every point of a study, with the paper's experiment and model marked
(docs/fidelity.md).

    python runs/compare_runs.py OUT.png LABEL=RUN_DIR [LABEL=RUN_DIR ...]
    python runs/compare_runs.py OUT.png --study STUDY_DIR
"""

import argparse
import csv
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from ncf2lammps.io.results import read_results
from ncf2lammps.scenes.compaction import EXPERIMENT, PAPER_MODEL_THICKNESS_1KPA_MM
from ncf2lammps.scenes.shear import EXPERIMENT_FORCE_45DEG_N_PER_M, PAPER_MODEL_FORCE_45DEG_N_PER_M


def labelled(value: str) -> tuple[str, Path]:
    """``LABEL=RUN_DIR`` as (label, folder)."""
    if "=" not in value:
        raise argparse.ArgumentTypeError(f"{value!r}: expected LABEL=RUN_DIR")
    label, folder = value.split("=", 1)
    return label, Path(folder)


def study_points(study: Path) -> list[tuple[str, Path]]:
    """(label: point and its knob values, folder) of every point of a study."""
    rows = list(csv.DictReader((study / "study.csv").open()))
    knobs = [key for key in rows[0] if "." in key]
    return [
        (row["point"] + ": " + ", ".join(f"{k.split('.')[-1]} {row[k]}" for k in knobs),
         study / "points" / row["point"])
        for row in rows
    ]  # fmt: skip


parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("output", type=Path, help="PNG to write")
parser.add_argument("runs", nargs="*", type=labelled, help="LABEL=RUN_DIR")
parser.add_argument("--study", type=Path, help="a study folder: plot all its points")
args = parser.parse_args()
runs = args.runs + (study_points(args.study) if args.study else [])
if not runs:
    parser.error("runs: give LABEL=RUN_DIR or --study STUDY_DIR")

curves = []
for label, folder in runs:
    if (folder / "results.h5").is_file():
        curves.append((label, read_results(folder / "results.h5")))
sheared = any("shear" in data for _, data in curves)
fig, axes = plt.subplots(1, 2 if sheared else 1, figsize=(11.0 if sheared else 7.0, 4.8))
press, shear = (axes[0], axes[1]) if sheared else (axes, None)
for label, data in curves:
    if "compaction" in data:
        group = data["compaction"]
        press.plot(group["gap_mm"], group["pressure_smoothed_kPa"], lw=1.2, label=label)
    if shear is not None and "shear" in data:
        group = data["shear"]
        shear.plot(group["angle_deg"], group["force_N_per_m"], lw=1.0, label=label)
press.plot(*zip(*EXPERIMENT, strict=True), "ks", ms=7, label="experiment (paper)")
press.plot([PAPER_MODEL_THICKNESS_1KPA_MM], [1.0], "r^", ms=7, label="paper model at 1 kPa")
press.set(yscale="log", ylim=(0.05, 100.0), xlabel="plate gap (mm)", ylabel="pressure (kPa)")
press.legend(fontsize=7)
if shear is not None:
    shear.plot([45.0], [EXPERIMENT_FORCE_45DEG_N_PER_M], "ks", ms=7, label="experiment (paper)")
    shear.plot([45.0], [PAPER_MODEL_FORCE_45DEG_N_PER_M], "r^", ms=7, label="paper model")
    shear.set(xlabel="shear angle (deg)", ylabel="normalised shear force F_N (N/m)")
    shear.legend(fontsize=7)
fig.tight_layout()
fig.savefig(args.output, dpi=110)
print(f"wrote {args.output}")
