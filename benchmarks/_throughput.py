"""Shared by the throughput benchmarks: a fixed-length compaction deck on the paper's cell.

The cell is the paper's (runs/hpt310, 69 um chains, at ``dt_fraction`` 0.5) without the stitch,
so the compaction deck starts from model.data and needs no manufactured state. The plates close
at a fixed speed to Vf 0.33 and ``fix halt`` ends the run there: every path runs the same deck
for the same steps.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import time
from contextlib import chdir
from pathlib import Path

from ncf2lammps import load_spec, spec_from_dict
from ncf2lammps.engine import Engine, run_deck
from ncf2lammps.orchestration.build import build

ROOT = Path(__file__).resolve().parent.parent
LMP = shutil.which("lmp", path=str(Path(sys.executable).parent)) or "lmp"
MPIEXEC = shutil.which("mpiexec", path=str(Path(sys.executable).parent)) or "mpiexec"


def paper_mat_folder(directory: Path, plate_speed_m_s: float = 3.0) -> tuple[Path, int]:
    """Build the benchmark folder; returns (folder, atoms)."""
    data = load_spec(ROOT / "runs" / "hpt310" / "spec.toml").to_dict()
    data.pop("stitch")
    data["cell"] = {"length_mm": 11.2, "width_mm": 5.08}  # the stitch repeat of runs/hpt310
    data["compaction"].update(end="final_fvf", final_fvf=0.33, plate_speed_m_s=plate_speed_m_s)
    # the time step of every throughput figure measured so far (the case itself runs at 0.7)
    data["numerics"]["dt_fraction"] = 0.5
    spec = spec_from_dict(data)
    built = build(spec, directory, force=True)
    return built.directory, built.model.n_atoms


def run_python(folder: Path, chunk: int = 5000) -> tuple[float, int]:
    """(wall s, steps) of the compaction deck run by the Python driver (1 rank), working in
    ``folder`` (the deck's relative paths resolve there, as in a scene's process)."""
    start = time.perf_counter()
    with chdir(folder), Engine(log="log.python.lammps") as engine:
        run_deck(engine, "decks/in.compaction.lmp", chunk=chunk)
        steps = engine.step
    return time.perf_counter() - start, steps


def run_lmp(folder: Path, ranks: int = 1) -> tuple[float, int]:
    """(wall s, steps) of the same deck run by plain ``lmp`` on ``ranks`` MPI ranks."""
    command = [LMP, "-in", "decks/in.compaction.lmp", "-log", f"log.lmp{ranks}.lammps"]
    command += ["-screen", "none", "-nocite"]
    if ranks > 1:
        command = [MPIEXEC, "-n", str(ranks), *command]
    start = time.perf_counter()
    subprocess.run(command, cwd=folder, check=True)
    wall = time.perf_counter() - start
    log = (folder / f"log.lmp{ranks}.lammps").read_text()
    steps = sum(int(n) for n in re.findall(r"Loop time of \S+ on \d+ procs for (\d+) steps", log))
    return wall, steps
