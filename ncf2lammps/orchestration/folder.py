"""The checks of the folders the verbs read and write, in one place.

:func:`check_run_folder` tells whether a folder is a run folder fit for ``report`` or
``run --resume`` (missing, empty, a file, a study's, built but never run, an unfinished export,
a killed run, an unreadable results.h5); :func:`check_output` whether ``-o`` can be written.
Each failure is a :class:`RunFolderError`: one line naming the path, what is wrong and what to
do. Reading results.h5 itself is :func:`~ncf2lammps.io.results.read_results`'s.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

from ..engine import CheckpointError, Checkpoints
from ..io.results import ROOT_ATTRS, ResultsFileError, read_results
from ..scenes import SCENES
from ..spec import SpecError, load_spec

__all__ = ["RunFolder", "RunFolderError", "check_output", "check_run_folder"]

#: Files of which one marks a folder as ncf2lammps output (``--force`` replaces only such).
OUTPUT_MARKERS = ("spec.resolved.toml", "model.data", "results.h5", "in.run_all.lmp")

#: A temporary folder of an interrupted build (:func:`~ncf2lammps.orchestration.build.build`).
_PARTIAL = re.compile(r"\.partial-(\d+)$")


def temporary_folder(final: Path) -> Path:
    """``<final>.partial-<pid>`` (this process's pid): where ``final`` is written before it is
    renamed into place."""
    return final.with_name(f"{final.name}.partial-{os.getpid()}")


def process_alive(pid: int) -> bool:
    """Whether process ``pid`` exists on this host (one of another user counts)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass
    return True


def abandoned_temporary_folders(final: Path) -> list[Path]:
    """Temporary folders of ``final`` whose process is gone (killed), the newest first."""
    found = [
        path
        for path in final.parent.glob(f"{final.name}.partial-*")
        if (owner := _PARTIAL.search(path.name)) and not process_alive(int(owner[1]))
    ]
    return sorted(found, key=lambda path: path.stat().st_mtime, reverse=True)


class RunFolderError(ValueError):
    """A folder that cannot serve the verb; ``str()`` is one line: path, what is wrong, what
    to do."""

    def __init__(self, path: str | os.PathLike, why: str, option: str = ""):
        self.path = Path(path)
        self.why = why
        prefix = f"{option}: " if option else ""
        super().__init__(" ".join(f"{prefix}{self.path}: {why}".split()))


@dataclass(frozen=True)
class RunFolder:
    """A checked run folder: its path, results.h5 content (None for an exported bundle not yet
    collected), whether the run finished, and its scenes with a complete group."""

    path: Path
    results: dict | None
    complete: bool
    scenes: tuple[str, ...]

    @property
    def bundle(self) -> bool:
        """An exported bundle run by plain ``lmp`` (reported from its scene files)."""
        return (self.path / "in.run_all.lmp").is_file()


def _restart(directory: Path) -> str:
    return f"start it again with `ncf2lammps run SPEC -o {directory} --force`"


def _check_folder(directory: Path, need: str) -> None:
    """The folder exists, is a folder, is not empty, not a study's nor a temporary build's."""
    if not directory.exists():
        what = "nothing to resume" if need == "resume" else "nothing to report"
        raise RunFolderError(
            directory,
            f"no such folder ({what}): make it with `ncf2lammps run SPEC -o {directory}`",
        )
    if not directory.is_dir():
        raise RunFolderError(
            directory, "is a file, not a run folder (give the folder `ncf2lammps run -o` wrote)"
        )
    try:
        empty = not any(directory.iterdir())
    except OSError as err:
        raise RunFolderError(directory, f"cannot be listed ({err.strerror})") from None
    if empty:
        raise RunFolderError(
            directory,
            f"is empty, not a run folder: make it with `ncf2lammps run SPEC -o {directory}`",
        )
    if _PARTIAL.search(directory.name):
        raise RunFolderError(
            directory, "is the temporary folder of an interrupted build: delete it and build again"
        )
    if (directory / "points").is_dir() and not (directory / "model.data").is_file():
        raise RunFolderError(
            directory,
            f"is a study folder: give one of its points, e.g. {directory / 'points' / 'p00'}",
        )


def _bundle(directory: Path, need: str) -> RunFolder:
    """An exported bundle: reportable once a scene has finished under plain ``lmp``."""
    if need == "resume":
        raise RunFolderError(
            directory,
            "is an exported bundle: resume it by running `mpirun -np N lmp -in in.run_all.lmp`"
            " in it again (finished scenes are skipped)",
        )
    if not (directory / "spec.resolved.toml").is_file():
        raise RunFolderError(directory, "is a bundle without spec.resolved.toml: export it again")
    if not any((directory / f"{scene}.final.txt").is_file() for scene in SCENES):
        raise RunFolderError(
            directory,
            "is an exported bundle no scene of which has finished: run `mpirun -np N lmp -in"
            " in.run_all.lmp` in it, then report",
        )
    return RunFolder(directory, None, False, ())


def check_run_folder(path: str | os.PathLike, need: str = "report") -> RunFolder:
    """Check that ``path`` is a run folder fit for ``need`` (``"report"`` or ``"resume"``).

    ``report`` needs results.h5 (or an exported bundle with a finished scene) with at least one
    finished scene and write access for figures/ and summary.md; ``resume`` needs the built
    files (model.data, spec.resolved.toml, decks/) and a readable results.h5. A killed run's
    folder passes both (``complete`` False). Raises :class:`RunFolderError`.
    """
    if need not in ("report", "resume"):
        raise ValueError(f"need must be 'report' or 'resume', not {need!r}")
    try:
        return _check_run_folder(Path(path), need)
    except RunFolderError as err:
        if need != "resume":
            raise
        raise RunFolderError(err.path, err.why, "--resume") from None


def _check_run_folder(directory: Path, need: str) -> RunFolder:
    _check_folder(directory, need)
    if (
        need == "report"
        and (directory / "figures").exists()
        and not (directory / "figures").is_dir()
    ):
        raise RunFolderError(directory, "holds a file named figures: report writes figures/ there")
    if need == "report" and (directory / "summary.md").is_dir():
        raise RunFolderError(directory, "holds a folder named summary.md: report writes that file")
    if (directory / "in.run_all.lmp").is_file():
        return _bundle(directory, need)  # its results.h5 is collected again from scene files
    results_path = directory / "results.h5"
    built = [name for name in ("model.data", "spec.resolved.toml") if (directory / name).is_file()]
    if not results_path.exists():
        if built:
            raise RunFolderError(
                directory,
                "was built but never run (no results.h5): run it with"
                f" `ncf2lammps run SPEC -o {directory} --force`",
            )
        raise RunFolderError(
            directory,
            "is not a run folder (no results.h5, model.data or spec.resolved.toml): give the"
            " folder `ncf2lammps run -o` wrote",
        )
    if need == "resume":
        _check_resumable(directory)
    try:
        results = read_results(results_path)
    except ResultsFileError as err:
        what = "cannot be resumed" if need == "resume" else "cannot be reported"
        raise RunFolderError(
            results_path, f"{err.reason}; the run {what}: {_restart(directory)}"
        ) from None
    missing = [key for key in ROOT_ATTRS if key not in results["attrs"]]
    if missing:
        raise RunFolderError(
            results_path,
            f"is not a run's results file (no root attribute {missing[0]!r}):"
            f" {_restart(directory)}",
        )
    scenes = tuple(
        name
        for name, group in results.items()
        if name in SCENES and bool(group["attrs"].get("complete"))
    )
    complete = bool(results["attrs"]["complete"])
    if need == "report":
        if not complete and not scenes:
            raise RunFolderError(
                directory,
                "holds a run that stopped before its first scene finished (nothing to report):"
                f" continue it with `ncf2lammps run SPEC -o {directory} --resume`",
            )
        if not os.access(directory, os.W_OK):
            raise RunFolderError(
                directory, "is not writable (report writes figures/ and summary.md into it)"
            )
    return RunFolder(directory, results, complete, scenes)


def _check_name_lengths(final: Path, ancestor: Path, renamed: bool) -> None:
    """Every name in ``final`` (and its temporary build name if it is ``renamed`` into place)
    fits the file system of ``ancestor``, its deepest existing folder."""
    name_max = os.pathconf(ancestor, "PC_NAME_MAX")
    longest = max(len(os.fsencode(part)) for part in final.parts)
    temporary = len(os.fsencode(temporary_folder(final).name if renamed else final.name))
    if max(longest, temporary) > name_max:
        raise RunFolderError(
            final, f"cannot be made: a name in it is longer than the {name_max} bytes allowed"
        )


def _check_resumable(directory: Path) -> None:
    """The built files a resume reads (model.data, a readable spec.resolved.toml, decks/) and
    every scene's last checkpoint with the journal run it names."""
    for name, present in (
        ("model.data", Path.is_file),
        ("spec.resolved.toml", Path.is_file),
        ("decks", Path.is_dir),
    ):
        if not present(directory / name):
            raise RunFolderError(
                directory, f"has no {name}, so it cannot be resumed: {_restart(directory)}"
            )
    try:
        load_spec(directory / "spec.resolved.toml")
    except SpecError as err:
        raise RunFolderError(
            directory, f"cannot be resumed: its spec.resolved.toml is damaged ({err.why})"
        ) from None
    for scene in SCENES:
        try:
            Checkpoints(scene).check(directory)
        except CheckpointError as err:
            raise RunFolderError(
                directory, f"cannot be resumed: {err}; {_restart(directory)}"
            ) from None


def check_output(
    path: str | os.PathLike, force: bool = False, study: bool = False, make: bool = False
) -> Path:
    """Check that ``-o path`` can become the output folder; returns it (``..`` resolved in the
    path's text; made now if ``make``).

    ``make``: the verb writes into the folder where it is (``validate``, ``study``); otherwise
    the folder is built under a temporary name and renamed into place, replacing the folder
    with ``force`` (``run``, ``build``, ``export``). Refused: an existing file (even with
    ``force``), a path below a file, a name the system cannot take, a place that cannot be
    written; without ``force`` a non-empty folder (a killed run's is pointed to ``--resume``)
    unless ``study`` (a study folder is continued; :func:`~ncf2lammps.orchestration.study.study`
    checks it holds a study); for a folder built elsewhere, the current folder or one holding
    it, and with ``force`` a non-empty folder that holds no ncf2lammps output
    (:data:`OUTPUT_MARKERS`): ``force`` replaces runs, not arbitrary folders.
    """
    final = Path(os.path.normpath(path))
    try:
        exists = final.exists()
    except OSError as err:
        raise RunFolderError(final, f"cannot be used ({err.strerror}): choose another -o") from None
    if exists and not final.is_dir():
        raise RunFolderError(final, "is a file, not a folder: choose another -o")
    try:
        here = Path.cwd()
    except OSError as err:  # the current folder was deleted under the shell
        if not final.is_absolute():
            raise RunFolderError(
                final, f"is relative to a current folder that is gone ({err.strerror})"
            ) from None
        here = None
    renamed = not make and not study  # built under a temporary name and renamed into place
    if renamed and here is not None and final.resolve() in (here, *here.parents):
        raise RunFolderError(
            final,
            "is the current folder or holds it: the output is built under a temporary name and"
            " moved into place, so give a new folder (e.g. -o out)",
        )
    nonempty = exists and any(final.iterdir())
    ours = any((final / name).is_file() for name in OUTPUT_MARKERS)
    if nonempty and force and renamed and not ours:
        raise RunFolderError(
            final,
            "is not empty and holds no ncf2lammps output (none of "
            f"{', '.join(OUTPUT_MARKERS)}): --force only replaces such a folder; choose another -o",
        )
    if nonempty and not force and not study:
        why = "exists and is not empty (choose another -o" + (" or --force)" if ours else ")")
        if (final / "results.h5").is_file():
            try:
                unfinished = not bool(read_results(final / "results.h5")["attrs"].get("complete"))
            except ResultsFileError:
                unfinished = False
            if unfinished:
                why = (
                    "exists and holds an unfinished run: continue it with --resume,"
                    " or replace it with --force"
                )
        from .build import OutputExistsError  # the error `build` has always raised here

        raise OutputExistsError(f"{final}: {why}")
    ancestor = final if final.exists() else final.parent
    while not ancestor.exists() and ancestor != ancestor.parent:
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise RunFolderError(final, f"cannot be made: {ancestor} is a file, not a folder")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise RunFolderError(
            final, f"cannot be made: {ancestor} is not writable (choose another -o)"
        )
    _check_name_lengths(final, ancestor, renamed)
    if make:
        try:
            final.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise RunFolderError(
                final, f"cannot be made ({err.strerror}): choose another -o"
            ) from None
    return final
