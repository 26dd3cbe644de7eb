"""HPC bundle: a run folder that plain ``mpirun -np N lmp -in in.run_all.lmp`` runs (no Python).

The bundle is :func:`~ncf2lammps.orchestration.build.build`'s folder (model.data, spec.resolved.toml,
decks/in.<scene>.lmp rendered from the same templates as a Python-driven run, here writing
their own restart files) plus ``in.run_all.lmp`` (the scenes chained with ``include``; a
finished scene is skipped when the job runs again), ``job.slurm`` and ``README.md``. Its outputs
are the files a Python-driven run collects, so ``ncf2lammps report DIR`` reads them back
(:func:`~ncf2lammps.orchestration.report.write_report`).
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from pathlib import Path

from .. import __version__
from ..io.deck import render
from ..model import Model
from ..scenes import applicable_scenes
from ..spec import FabricSpec, SpecError
from .build import build, check_ranks

__all__ = ["export"]

_WALL_TIME = re.compile(r"^(?:([0-9]{1,3})-)?([0-9]{1,3}):([0-5][0-9]):([0-5][0-9])$")
_MODULE = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_./+-]{0,99}$")
#: Longest wall time a job asks for (s): a year.
MAX_WALL_TIME_S = 365 * 86400


def export(
    spec: FabricSpec,
    directory: str | os.PathLike,
    ranks: int = 2,
    wall_time: str = "24:00:00",
    modules: Sequence[str] = (),
    force: bool = False,
) -> Path:
    """Write the bundle into ``directory`` (atomically); returns the folder.

    ``ranks`` (MPI ranks in job.slurm and the README), ``wall_time`` (Slurm ``[D-]HH:MM:SS``)
    and ``modules`` (``module load`` names) parameterise job.slurm.
    """
    check_ranks(ranks)
    if (match := _WALL_TIME.fullmatch(wall_time)) is None:
        raise SpecError("--time", wall_time, "must read [D-]HH:MM:SS")
    for name in modules:
        if not _MODULE.fullmatch(name) or ".." in name:
            raise SpecError(
                "--module", name, "must be a module name (letters, digits, _./+-; 100 at most)"
            )
    days, hours, minutes, seconds = (int(part or 0) for part in match.groups())
    total = ((days * 24 + hours) * 60 + minutes) * 60 + seconds
    if not 0 < total <= MAX_WALL_TIME_S:
        raise SpecError("--time", wall_time, "must be longer than 0:00:00 and at most 365-00:00:00")
    scenes = list(applicable_scenes(spec))
    values = {
        "version": __version__,
        "scenes": scenes,
        "ranks": ranks,
        "wall_time": [days, hours, minutes, seconds],
        "modules": list(modules),
        "dump_every": spec.output.dump_every_steps,
    }

    def finish(folder: Path, model: Model) -> None:
        (folder / "in.run_all.lmp").write_text(render("run_all.lmp.j2", **values))
        (folder / "job.slurm").write_text(render("job.slurm.j2", **values))
        (folder / "job.slurm").chmod(0o755)
        (folder / "README.md").write_text(render("README.bundle.md.j2", **values))

    return build(spec, directory, force=force, plain_lmp=True, finish=finish).directory
