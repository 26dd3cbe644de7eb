"""Python driver against plain ``lmp``: atom-steps/s of the same deck on 1 rank (JSON on stdout).

Target: driver / lmp >= 0.95. Each figure is the median of ``--repeat`` runs; both
paths include LAMMPS start-up and reading the data file.

    python benchmarks/engine_overhead.py [--repeat 3] [--chunk 5000]
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
from pathlib import Path

from _throughput import paper_mat_folder, run_lmp, run_python

from ncf2lammps.cli import at_least_one, script_main


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=at_least_one, default=3)
    parser.add_argument("--chunk", type=at_least_one, default=5000, help="steps per driver chunk")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder, atoms = paper_mat_folder(Path(tmp) / "bench")
        python, plain = [], []
        for _ in range(args.repeat):
            wall, steps = run_python(folder, args.chunk)
            python.append(atoms * steps / wall)
            wall, lmp_steps = run_lmp(folder)
            plain.append(atoms * lmp_steps / wall)
            assert lmp_steps == steps, (steps, lmp_steps)
    ratio = statistics.median(python) / statistics.median(plain)
    print(
        json.dumps(
            {
                "benchmark": "engine_overhead",
                "atoms": atoms,
                "steps": steps,
                "chunk": args.chunk,
                "python_atom_steps_per_s": statistics.median(python),
                "lmp_atom_steps_per_s": statistics.median(plain),
                "python_runs": python,
                "lmp_runs": plain,
                "ratio": ratio,
                "target_ratio": 0.95,
                "meets_target": ratio >= 0.95,
            },
            indent=2,
        )
    )


if __name__ == "__main__":
    script_main(main)
