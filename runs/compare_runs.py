"""Example post-processing script: compaction and shear curves (each sense run) of several run
folders or of every point of a study, with the paper's experiment and model marked
(docs/fidelity.md; ``--no-paper-marks`` for another fabric).

    python runs/compare_runs.py OUT.png LABEL=RUN_DIR [LABEL=RUN_DIR ...]
    python runs/compare_runs.py OUT.png --study STUDY_DIR
"""

import argparse
import csv
from pathlib import Path

from matplotlib.figure import Figure

from ncf2lammps.analysis.plots import plot_compaction, plot_shear
from ncf2lammps.cli import script_main
from ncf2lammps.io.results import read_results


def labelled(value: str) -> tuple[str, Path]:
    """``LABEL=RUN_DIR`` as (label, folder)."""
    if "=" not in value:
        raise argparse.ArgumentTypeError(f"{value!r}: expected LABEL=RUN_DIR")
    label, folder = value.rsplit("=", 1)  # a label may hold "=", a folder seldom does
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("output", type=Path, help="PNG to write")
    parser.add_argument("runs", nargs="*", type=labelled, help="LABEL=RUN_DIR")
    parser.add_argument("--study", type=Path, help="a study folder: plot all its points")
    parser.add_argument(
        "--no-paper-marks", action="store_true", help="another fabric than the paper's 0/90 NCF"
    )
    args = parser.parse_args()
    if args.study and not (args.study / "study.csv").is_file():
        parser.error(f"--study {args.study}: no study.csv there; give a study folder")
    runs = args.runs + (study_points(args.study) if args.study else [])
    if not runs:
        parser.error("runs: give LABEL=RUN_DIR or --study STUDY_DIR")

    for label, folder in args.runs:
        if not (folder / "results.h5").is_file():
            parser.error(f"{label}={folder}: no results.h5 there; give a run folder")
    # A study's point that failed has no results.h5: it is left out.
    curves = [
        (label, read_results(f / "results.h5")) for label, f in runs if (f / "results.h5").is_file()
    ]
    marks = not args.no_paper_marks
    compacted = any("compaction" in data for _, data in curves)
    sheared = any("shear" in data for _, data in curves)
    fig = Figure(figsize=(11.0 if compacted and sheared else 7.0, 4.8))
    axes = list(fig.subplots(1, compacted + sheared, squeeze=False)[0])
    for label, data in curves:
        if "compaction" in data:
            plot_compaction(data, axes[0], label=label, paper_marks=marks)
        if "shear" in data:
            plot_shear(data, axes[-1], label=label, paper_marks=marks)
    fig.tight_layout()
    fig.savefig(args.output, dpi=110)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    script_main(main)
