"""Example generate-and-run script: picture-frame shear of one manufactured cell in both senses,
at the spec's rate and at half of it, and the asymmetry F_N+(45) / F_N-(45) with the stitch
tensions as evidence; prints one JSON object.

    python runs/shear_senses.py runs/pm45-cbx300-coarse/spec.toml out/pm45 out/pm45-senses

The manufactured folder comes from ``ncf2lammps run SPEC -o out/pm45 --scene manufacture``; each
rate runs in its own copy of it (``OUTPUT/rate-1``, ``OUTPUT/rate-0.5``, each with its summary.md
and figures); a rate whose folder already
holds both senses' results is read, not run again. With ``stitch.rupture``
in the spec the manufactured folder must come from the same spec (it writes the rest lengths).
"""

import argparse
import json
import shutil
from pathlib import Path

import ncf2lammps as n2l
from ncf2lammps.cli import script_main
from ncf2lammps.io.results import read_results
from ncf2lammps.orchestration.report import write_report


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("spec", type=Path)
    parser.add_argument("manufactured", type=Path, help="folder of `run --scene manufacture`")
    parser.add_argument("output", type=Path, help="folder of the rate copies")
    parser.add_argument("--np", type=int, default=1, help="MPI ranks")
    parser.add_argument("--rates", type=float, nargs="+", default=[1.0, 0.5], help="x the spec's")
    args = parser.parse_args()

    base = n2l.load_spec(args.spec)
    inertial = base.shear.inertial_number
    report: dict = {"spec": str(args.spec), "rates": {}}
    for factor in args.rates:
        spec = base.replace(
            shear={"senses": ["positive", "negative"], "inertial_number": inertial * factor}
        )
        folder = args.output / f"rate-{factor:g}"
        results = read_results(folder / "results.h5") if folder.is_dir() else {}
        if not {"shear", "shear_negative"} <= results.keys():
            shutil.rmtree(folder, ignore_errors=True)
            n2l.copy_manufactured(spec, args.manufactured, folder, ["shear", "shear_negative"])
            results = read_results(
                n2l.run_scenes(spec, folder, ["shear", "shear_negative"], args.np)
            )
            write_report(folder)  # summary.md with the asymmetry, figures/shear_force.png
        senses = {}
        for group in ("shear", "shear_negative"):
            attrs = results[group]["attrs"]
            senses[attrs["sense"]] = {
                key: attrs.get(key)
                for key in (
                    "force_at_45deg_N_per_m",
                    "work_virial_max_deviation",
                    "max_kinetic_ratio",
                    "max_kinetic_stress_ratio",
                    "max_shear_rate_deg_us",
                    "steps",
                    "wall_s",
                    "stitch_tension_max_N",
                    "stitch_bonds_broken",
                    "stitch_first_break_angle_deg",
                )
            }
            tension = results[group].get("stitch_tension_mean_N")
            if tension is not None:
                senses[attrs["sense"]]["stitch_tension_mean_final_N"] = float(tension[-1])
        positive, negative = senses["positive"], senses["negative"]
        report["rates"][f"{factor:g}"] = {
            "inertial_number": inertial * factor,
            "senses": senses,
            "asymmetry_45deg": positive["force_at_45deg_N_per_m"]
            / negative["force_at_45deg_N_per_m"],
        }
    if len(args.rates) > 1:
        reference, *others = (report["rates"][f"{f:g}"] for f in args.rates)
        report["rate_change_45deg"] = {
            f"{f:g}": {
                sense: other["senses"][sense]["force_at_45deg_N_per_m"]
                / reference["senses"][sense]["force_at_45deg_N_per_m"]
                - 1.0
                for sense in ("positive", "negative")
            }
            for f, other in zip(args.rates[1:], others, strict=True)
        }
    print(json.dumps(report, indent=2, default=float))


if __name__ == "__main__":
    script_main(main)
