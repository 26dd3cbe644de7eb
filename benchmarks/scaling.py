"""Strong scaling of plain ``lmp`` on the paper's cell: 1 against 2 MPI ranks (JSON on stdout).

Target: parallel efficiency (rate at 2 ranks) / (2 x rate at 1 rank) >= 0.85. Each
figure is the median of ``--repeat`` runs of the same deck for the same steps.

    python benchmarks/scaling.py [--repeat 3] [--ranks 1 2]
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
from pathlib import Path

from _throughput import paper_mat_folder, run_lmp

from ncf2lammps.cli import at_least_one, script_main


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=at_least_one, default=3)
    parser.add_argument("--ranks", type=at_least_one, nargs="+", default=[1, 2])
    args = parser.parse_args()
    rates: dict[int, list[float]] = {n: [] for n in args.ranks}
    with tempfile.TemporaryDirectory() as tmp:
        folder, atoms = paper_mat_folder(Path(tmp) / "bench")
        for _ in range(args.repeat):
            for ranks in args.ranks:
                wall, steps = run_lmp(folder, ranks)
                rates[ranks].append(atoms * steps / wall)
    median = {n: statistics.median(r) for n, r in rates.items()}
    base = min(args.ranks)
    efficiency = {n: median[n] * base / (n * median[base]) for n in args.ranks}
    print(
        json.dumps(
            {
                "benchmark": "scaling",
                "atoms": atoms,
                "steps": steps,
                "atom_steps_per_s": median,
                "runs": rates,
                "efficiency": efficiency,
                "target_efficiency": 0.85,
                "meets_target": all(e >= 0.85 for e in efficiency.values()),
            },
            indent=2,
        )
    )


if __name__ == "__main__":
    script_main(main)
