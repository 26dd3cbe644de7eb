"""Example generate-and-run script: one test scene on a copy of a manufactured folder, at a
loading rate of your choice, so that compaction and shear of one expensive manufactured cell can
run side by side (each on its own ranks).

    python runs/test_from_manufactured.py runs/hpt310/spec.toml out/hpt310 out/hpt310-shear \\
        shear --inertial-number 0.05 --np 1
"""

import argparse
from pathlib import Path

import ncf2lammps as n2l
from ncf2lammps.cli import script_main
from ncf2lammps.io.results import mark_complete, read_results
from ncf2lammps.orchestration.report import write_report


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("spec", type=Path)
    parser.add_argument("manufactured", type=Path, help="folder of `run --scene manufacture`")
    parser.add_argument("output", type=Path, help="new folder (a copy of the manufactured one)")
    parser.add_argument("scene", choices=("compaction", "shear"))
    parser.add_argument("--inertial-number", type=float, default=None, help="default: the spec's")
    parser.add_argument(
        "--kinetic-stress-target",
        type=float,
        default=None,
        help="default: the spec's (docs/loading.md)",
    )
    parser.add_argument("--np", type=int, default=1, help="MPI ranks")
    args = parser.parse_args()

    spec = n2l.load_spec(args.spec)
    if args.inertial_number is not None:
        spec = spec.replace(**{args.scene: {"inertial_number": args.inertial_number}})
    if args.kinetic_stress_target is not None:
        spec = spec.replace(**{args.scene: {"kinetic_stress_target": args.kinetic_stress_target}})
    if args.output.exists():
        parser.error(f"output = {args.output}: exists; choose a new folder")
    n2l.copy_manufactured(spec, args.manufactured, args.output, [args.scene])
    path = n2l.run_scenes(spec, args.output, [args.scene], ranks=args.np)
    mark_complete(path)
    write_report(args.output)  # summary.md and figures of what ran here
    results = read_results(path)
    attrs = results[args.scene]["attrs"]
    print({key: attrs[key] for key in sorted(attrs) if not key.startswith("reference")})


if __name__ == "__main__":
    script_main(main)
