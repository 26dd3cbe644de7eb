"""Run scenes in order on a built folder and record their results in results.h5.

Stages of :func:`run`:
1. build the folder (model.data, spec.resolved.toml, decks) atomically;
2. create results.h5 with the root attributes (``complete = False``);
3. for each scene asked for and the scenes they require (compaction and shear of a stitched
   fabric start from manufacture), in :data:`~ncf2lammps.scenes.build.SCENES` order: open
   LAMMPS in the folder, run the scene's deck through its runner (chunked, with progress),
   write its group;
4. set ``complete = True`` on the file; write figures/ and summary.md.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path

from .. import __version__
from ..engine import Engine
from ..io.results import mark_complete, write_root, write_scene
from ..io.spectoml import dumps_spec
from ..spec import FabricSpec, SpecError
from .build import applicable_scenes, build, scene_module
from .progress import Progress
from .report import write_report

__all__ = ["run"]


def run(
    spec: FabricSpec,
    directory: str | os.PathLike,
    scenes: Sequence[str] | None = None,
    force: bool = False,
) -> Path:
    """Build ``directory`` and run ``scenes`` (default: all) in order; returns results.h5."""
    available = applicable_scenes(spec)
    wanted = [s for s in available if scenes is None or s in scenes]
    if scenes is not None and (missing := set(scenes) - set(available)):
        raise SpecError(
            "--scene", sorted(missing)[0], f"not available for this spec ({', '.join(available)})"
        )
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
        with Engine(built.directory, log=f"log.{scene}.lammps") as engine, Progress(scene) as bar:
            attrs, datasets = scene_module(scene).execute(engine, spec, built.model, bar.update)
        attrs["wall_s"] = time.perf_counter() - start
        write_scene(results, scene, attrs, datasets)
    mark_complete(results)
    write_report(built.directory)
    return results
