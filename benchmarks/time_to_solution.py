"""A case end to end: manufacture, compaction, shear to 45 deg (JSON on stdout).

Default: the paper's cell (runs/hpt310/spec.toml). Target: <= 15 min in total on the 2-core
machine. Reports wall time and steps per scene, the outputs (thickness after manufacture, t at
1 and 18 kPa, F_N at 45 deg) and the quasi-static checks. With ``--half`` the test scenes run
again from the same manufactured state at half the loading (half the inertial numbers, a quarter
of the adaptive loading's kinetic stress targets, docs/loading.md) and the relative change of
each output is reported (target: < 3 %).

    python benchmarks/time_to_solution.py [--case hpt310] [-o DIR] [--np N] [--half]
"""

from __future__ import annotations

import argparse
import json
import shutil
import tempfile
import time
from pathlib import Path

from ncf2lammps import load_spec, run, run_scenes
from ncf2lammps.io.results import read_results

ROOT = Path(__file__).resolve().parent.parent
TARGET_S = 900.0
CHECKS = (
    "kinetic_ratio",
    "stitch_tension_error",
    "max_kinetic_stress_ratio",
    "kinetic_stress_limit",
    "max_kinetic_thickness_error",
    "kinetic_thickness_error_limit",
    "max_kinetic_ratio",
    "max_plate_speed_m_s",
    "max_shear_rate_deg_us",
)
#: (scene, attribute) of the outputs the halving check compares.
OUTPUTS = (
    ("manufacture", "thickness_mm"),
    ("compaction", "thickness_at_1kPa_mm"),
    ("compaction", "thickness_at_18kPa_mm"),
    ("compaction", "stiffening_exponent"),
    ("shear", "force_at_45deg_N_per_m"),
)


def _scenes(results: dict) -> dict:
    """Per scene: wall time, steps, atom-steps/s, the quasi-static checks and the outputs."""
    atoms = int(results["attrs"]["n_atoms"])
    keys = ("wall_s", "steps", *CHECKS, *(attr for _, attr in OUTPUTS))
    return {
        name: {
            **{
                k: v.item() if hasattr(v, "item") else v
                for k, v in group["attrs"].items()
                if k in keys
            },
            "atom_steps_per_s": atoms * int(group["attrs"]["steps"]) / group["attrs"]["wall_s"],
        }
        for name, group in results.items()
        if name != "attrs" and "wall_s" in group["attrs"]
    }


def _halved(spec):
    """The spec's test scenes at half the loading: half the inertial numbers, and a quarter of
    the kinetic stress targets (the ratio grows as the square of the rate)."""
    return spec.replace(
        **{
            table: {
                "inertial_number": getattr(spec, table).inertial_number / 2,
                "kinetic_stress_target": getattr(spec, table).kinetic_stress_target / 4,
            }
            for table in ("compaction", "shear")
        }
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", default="hpt310", help="a folder of runs/ (default hpt310)")
    parser.add_argument("-o", "--output", help="keep the run here (default: a temporary folder)")
    parser.add_argument("--np", type=int, default=2, help="MPI ranks (default 2, this machine)")
    parser.add_argument("--half", action="store_true", help="run the tests at half the loading")
    args = parser.parse_args()
    spec = load_spec(ROOT / "runs" / args.case / "spec.toml")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(args.output or Path(tmp) / args.case)
        start = time.perf_counter()
        results = read_results(run(spec, folder, force=True, ranks=args.np))
        total = time.perf_counter() - start
        report = {
            "benchmark": "time_to_solution",
            "case": args.case,
            "atoms": int(results["attrs"]["n_atoms"]),
            "ranks": args.np,
            "scenes": _scenes(results),
            "total_s": total,
            "target_s": TARGET_S,
            "meets_target": total <= TARGET_S,
        }
        if args.half:
            half = folder.with_name(folder.name + "-half")
            shutil.rmtree(half, ignore_errors=True)
            shutil.copytree(folder, half)
            tests = [s for s in ("compaction", "shear") if s in results]
            slow = read_results(run_scenes(_halved(spec), half, tests, ranks=args.np))
            report["half"] = {
                "scenes": _scenes(slow),
                "relative_change": {
                    f"{scene}.{attr}": float(
                        slow[scene]["attrs"][attr] / results[scene]["attrs"][attr] - 1
                    )
                    for scene, attr in OUTPUTS
                    if scene in tests and attr in results[scene]["attrs"]
                },
                "target": 0.03,
            }
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
