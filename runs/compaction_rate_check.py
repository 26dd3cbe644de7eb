"""Example generate-and-run script: is compaction quasi-static? Halve the plate speed on the same
manufactured cell and compare the thickness at 1 and 18 kPa (docs/design.md §8: < 3 %).

    python runs/compaction_rate_check.py runs/hpt310-coarse/spec.toml out/rate-check
"""

import argparse
import shutil
from pathlib import Path

import ncf2lammps as n2l
from ncf2lammps.cli import script_main
from ncf2lammps.io.results import read_results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("spec", type=Path)
    parser.add_argument("output", type=Path, help="folder of the base run and the two rates")
    parser.add_argument("--np", type=int, default=1, help="MPI ranks")
    args = parser.parse_args()
    spec = n2l.load_spec(args.spec)
    folder = args.output
    base = folder / "base"
    # manufactures first if stitched
    n2l.run(spec, base, scenes=["compaction"], force=True, ranks=args.np)
    rows = []
    for factor in (1.0, 0.5):
        inertial = spec.compaction.inertial_number * factor
        target = folder / f"I{inertial:g}"
        shutil.rmtree(target, ignore_errors=True)
        variant = spec.replace(compaction={"inertial_number": inertial})
        n2l.copy_manufactured(variant, base, target, ["compaction"])
        attrs = read_results(n2l.run_scenes(variant, target, ["compaction"], ranks=args.np))[
            "compaction"
        ]["attrs"]
        rows.append((inertial, attrs["thickness_at_1kPa_mm"], attrs["thickness_at_18kPa_mm"]))
        print(
            f"I = {inertial:g}: t@1kPa {rows[-1][1]:.5f} mm, t@18kPa {rows[-1][2]:.5f} mm,"
            f" max kinetic thickness error {attrs['max_kinetic_thickness_error']:.2g},"
            f" max kinetic stress ratio {attrs['max_kinetic_stress_ratio']:.2g},"
            f" max KE/W {attrs['max_kinetic_ratio']:.2g}"
        )
    change = rows[1][1] / rows[0][1] - 1
    print(f"halving the speed moved t@1kPa by {100 * change:+.3f} % (quasi-static below 3 %)")


if __name__ == "__main__":
    script_main(main)
