"""A case end to end: manufacture, compaction, shear to 45 deg (JSON on stdout).

Default: the paper's cell (runs/hpt310/spec.toml). Target: <= 15 min in total on the 2-core
machine. Reports wall time and steps per scene, the outputs (thickness after manufacture, t at
1 and 18 kPa, F_N at 45 deg) and the quasi-static checks. With ``--repeat N`` the case runs N
times from scratch: ``total_s`` is the median of the runs' totals (the target is judged on it),
``runs`` holds each run's total and scene wall times, and ``outputs_identical`` whether every run
gave the first one's outputs to the last bit (the same ranks replay the same trajectory). With
``--half`` the test scenes of the first run run again from the same manufactured state at half
the loading (half the inertial numbers, a quarter of the adaptive loading's kinetic stress
targets, docs/loading.md) and the relative change of each output is reported (target: < 3 %).

    python benchmarks/time_to_solution.py [--case hpt310] [-o DIR] [--np N] [--repeat N] [--half]
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import tempfile
import time
from pathlib import Path

from ncf2lammps import copy_manufactured, load_spec, run, run_scenes
from ncf2lammps.cli import at_least_one, script_main
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


def _outputs(results: dict) -> dict:
    """The compared outputs of a run, ``scene.attribute``: value."""
    return {
        f"{scene}.{attr}": float(results[scene]["attrs"][attr])
        for scene, attr in OUTPUTS
        if scene in results and attr in results[scene]["attrs"]
    }


def _halved(spec):
    """The spec's test scenes at half the loading: half the inertial numbers, and with adaptive
    loading a quarter of the kinetic stress targets (the ratio grows as the square of the
    rate)."""
    changes = {}
    for table in ("compaction", "shear"):
        settings = getattr(spec, table)
        changes[table] = {"inertial_number": settings.inertial_number / 2}
        if settings.loading == "adaptive":
            changes[table]["kinetic_stress_target"] = settings.kinetic_stress_target / 4
    return spec.replace(**changes)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", default="hpt310", help="a folder of runs/ (default hpt310)")
    parser.add_argument("-o", "--output", help="keep the run here (default: a temporary folder)")
    parser.add_argument("--np", type=int, default=2, help="MPI ranks (default 2, this machine)")
    parser.add_argument("--half", action="store_true", help="run the tests at half the loading")
    parser.add_argument(
        "--repeat", type=at_least_one, default=1, help="runs from scratch (median total)"
    )
    args = parser.parse_args()
    spec = load_spec(ROOT / "runs" / args.case / "spec.toml")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(args.output or Path(tmp) / args.case)
        runs = []
        for number in range(1, args.repeat + 1):
            here = folder if number == 1 else folder.with_name(f"{folder.name}-repeat{number}")
            start = time.perf_counter()
            content = read_results(run(spec, here, force=True, ranks=args.np))
            runs.append((time.perf_counter() - start, content))
        results = runs[0][1]
        outputs = _outputs(results)
        total = statistics.median(seconds for seconds, _ in runs)
        report = {
            "benchmark": "time_to_solution",
            "case": args.case,
            "atoms": int(results["attrs"]["n_atoms"]),
            "ranks": args.np,
            "scenes": _scenes(results),
            "total_s": total,
            "runs": [
                {"total_s": seconds, "wall_s": {k: v["wall_s"] for k, v in _scenes(c).items()}}
                for seconds, c in runs
            ],
            "outputs_identical": all(_outputs(c) == outputs for _, c in runs[1:]),
            "target_s": TARGET_S,
            "meets_target": total <= TARGET_S,
        }
        if args.half:
            half = folder.with_name(folder.name + "-half")
            shutil.rmtree(half, ignore_errors=True)
            tests = [s for s in ("compaction", "shear") if s in results]
            halved = _halved(spec)
            copy_manufactured(halved, folder, half, tests)
            slow = read_results(run_scenes(halved, half, tests, ranks=args.np))
            slow_outputs = _outputs(slow)
            report["half"] = {
                "scenes": _scenes(slow),
                "relative_change": {
                    key: slow_outputs[key] / value - 1
                    for key, value in outputs.items()
                    if key.split(".")[0] in tests
                },
                "target": 0.03,
            }
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    script_main(main)
