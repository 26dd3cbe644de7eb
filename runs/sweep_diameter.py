"""Example generate-and-run script: model sizes and time steps of the paper's fabric over chain
diameter (the discretisation knob of the paper's Fig. 2).

    python runs/sweep_diameter.py
"""

import argparse
from pathlib import Path

import ncf2lammps as n2l
from ncf2lammps.cli import script_main


def main() -> None:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args()  # --help only
    spec = n2l.load_spec(Path(__file__).parent / "hpt310" / "spec.toml")
    print(f"{'d_um':>6} {'chains':>7} {'beads':>9} {'dt_us':>10}  governing limit")
    for diameter in (200.0, 150.0, 100.0, 69.0, 50.0):
        variant = spec.replace(discretisation={"chain_diameter_um": diameter})
        model = n2l.build_model(variant)
        step = n2l.time_step(variant, model)
        chains = len(set(model.mol_id.tolist()))
        print(f"{diameter:6g} {chains:7d} {model.n_atoms:9d} {step.dt:10.4g}  {step.governing}")


if __name__ == "__main__":
    script_main(main)
