"""Run scenes in order and record their results in results.h5.

Stages of :func:`run`:
1. build the folder (model.data, spec.resolved.toml, decks) atomically;
2. create results.h5 with the root attributes (``complete = False``);
3. :func:`run_scenes`: for each scene asked for and the scenes it requires (compaction and shear
   of a stitched fabric start from manufacture), in :data:`~ncf2lammps.scenes.build.SCENES`
   order: open LAMMPS in the folder, run the scene's deck through its runner (chunked, with
   progress), write its group;
4. set ``complete = True`` on the file; write figures/ and summary.md.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path

from .. import __version__
from ..engine import Engine, lammps_version
from ..io.deck import render
from ..io.results import mark_complete, write_root, write_scene
from ..io.spectoml import dumps_spec
from ..model import build_model
from ..spec import FabricSpec, SpecError
from .build import applicable_scenes, build, deck_context, scene_module
from .progress import Progress
from .report import write_report

__all__ = ["run", "run_scenes", "scenes_to_run"]


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


def run_scenes(spec: FabricSpec, directory: str | os.PathLike, scenes: Sequence[str]) -> Path:
    """Run ``scenes`` in a built folder, re-rendering their decks from ``spec``; returns results.h5.

    The spec must describe the same model as the folder's (same beads and bonds); scene
    settings (rates, targets) may differ, e.g. to run a test again at another rate on the same
    manufactured state.
    """
    directory = Path(directory).resolve()
    model = build_model(spec)
    if (folder_atoms := _count_atoms(directory)) != model.n_atoms:
        raise SpecError(
            "<spec>", "...", f"describes {model.n_atoms} beads, the folder {folder_atoms}"
        )
    results = directory / "results.h5"
    for scene in scenes:
        values = deck_context(spec, model, scene)
        values.update(scene_module(scene).deck_values(spec, model))
        (directory / "decks" / f"in.{scene}.lmp").write_text(render(f"{scene}.lmp.j2", **values))
        start = time.perf_counter()
        with Engine(directory, log=f"log.{scene}.lammps") as engine, Progress(scene) as bar:
            attrs, datasets = scene_module(scene).execute(engine, spec, model, bar.update)
        attrs["wall_s"] = time.perf_counter() - start
        write_scene(results, scene, attrs, datasets)
    return results


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
) -> Path:
    """Build ``directory`` and run ``scenes`` (default: all) in order; returns results.h5."""
    wanted = scenes_to_run(spec, scenes)
    built = build(spec, directory, force=force)
    results = built.directory / "results.h5"
    write_root(
        results,
        {
            "ncf2lammps_version": __version__,
            "lammps_version": lammps_version(),
            "spec_toml": dumps_spec(spec),
            "n_atoms": built.model.n_atoms,
            "n_bonds": built.model.n_bonds,
            "mpi_ranks": 1,
            "created": datetime.now(UTC).isoformat(timespec="seconds"),
            "dt_us": built.time_step.dt,
            "dt_critical_us": built.time_step.critical,
            "dt_governing": built.time_step.governing,
            "dt_margin": built.time_step.margin,
        },
    )
    run_scenes(spec, built.directory, wanted)
    mark_complete(results)
    write_report(built.directory)
    return results
