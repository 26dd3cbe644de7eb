"""Run scenes in order on a built folder and record their results in results.h5.

Stages of :func:`run`:
1. build the folder (model.data, spec.resolved.toml, decks) atomically;
2. create results.h5 with the root attributes (``complete = False``);
3. for each scene in :data:`~ncf2lammps.scenes.build.SCENES` order that was asked for: open
   LAMMPS in the folder, run the scene's deck through its runner, write its group;
4. set ``complete = True`` on the file.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from datetime import UTC, datetime
from pathlib import Path

from .. import __version__
from ..engine import Engine
from ..io.results import mark_complete, write_root, write_scene
from ..io.spectoml import dumps_spec
from ..spec import FabricSpec
from .build import SCENES, Build, build

__all__ = ["RUNNERS", "run"]


def _verify(engine: Engine, built: Build) -> tuple[dict, dict]:
    """Load the model, evaluate forces once, compare counts with the model."""
    engine.file("decks/in.verify.lmp")
    if (engine.natoms, engine.nbonds) != (built.model.n_atoms, built.model.n_bonds):
        raise RuntimeError(
            f"LAMMPS read {engine.natoms} atoms / {engine.nbonds} bonds, model has"
            f" {built.model.n_atoms} / {built.model.n_bonds}"
        )
    return {"steps": engine.step}, {}


#: Scene name -> runner(engine, build) returning (attrs, datasets) of its results.h5 group.
RUNNERS: dict[str, Callable[[Engine, Build], tuple[dict, dict]]] = {"verify": _verify}


def run(
    spec: FabricSpec,
    directory: str | os.PathLike,
    scenes: Sequence[str] | None = None,
    force: bool = False,
) -> Path:
    """Build ``directory`` and run ``scenes`` (default: all) in order; returns results.h5."""
    wanted = [s for s in SCENES if scenes is None or s in scenes]
    built = build(spec, directory, force=force)
    results = built.directory / "results.h5"
    with Engine(built.directory, log=None) as engine:
        lammps_version = str(engine.lmp.version())
    write_root(
        results,
        {
            "ncf2lammps_version": __version__,
            "lammps_version": lammps_version,
            "spec_toml": dumps_spec(spec),
            "n_atoms": built.model.n_atoms,
            "n_bonds": built.model.n_bonds,
            "mpi_ranks": 1,
            "created": datetime.now(UTC).isoformat(timespec="seconds"),
        },
    )
    for scene in wanted:
        start = time.perf_counter()
        with Engine(built.directory, log=f"log.{scene}.lammps") as engine:
            attrs, datasets = RUNNERS[scene](engine, built)
        attrs["wall_s"] = time.perf_counter() - start
        write_scene(results, scene, attrs, datasets)
    mark_complete(results)
    return results
