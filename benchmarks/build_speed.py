"""Seconds from spec to data file on disk: the paper's cell and a ~1M-bead cell (JSON on stdout).

Target: 1M beads in <= 5 s on the 2-core development machine. Each figure is the median
of ``--repeat`` runs.

    python benchmarks/build_speed.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time
from pathlib import Path

from ncf2lammps import build_model, load_spec
from ncf2lammps.cli import at_least_one, script_main
from ncf2lammps.io.datafile import write_data

ROOT = Path(__file__).resolve().parent.parent


def time_build(spec, repeat: int) -> dict:
    times, n_atoms = [], 0
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(repeat):
            start = time.perf_counter()
            model = build_model(spec)
            write_data(Path(tmp) / "model.data", model)
            times.append(time.perf_counter() - start)
            n_atoms = model.n_atoms
    return {"n_atoms": n_atoms, "seconds_median": statistics.median(times), "seconds": times}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=at_least_one, default=3)
    args = parser.parse_args()
    paper = load_spec(ROOT / "runs" / "hpt310" / "spec.toml")
    # Two stitch repeats in each direction at d = 46 um: about one million beads.
    million = paper.replace(
        cell={"length_mm": 2 * 11.2, "width_mm": 2 * 5.08},
        discretisation={"chain_diameter_um": 46.0},
    )
    report = {
        "benchmark": "build_speed",
        "hpt310": time_build(paper, args.repeat),
        "million": time_build(million, args.repeat),
        "target_million_seconds": 5.0,
    }
    report["million"]["meets_target"] = report["million"]["seconds_median"] <= 5.0
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    script_main(main)
