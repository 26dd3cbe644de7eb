"""Build a run folder: model.data, spec.resolved.toml and the decks, written atomically.

The folder is first written as ``<DIR>.partial-<pid>`` and renamed into place at the end, so an
interrupted build never leaves a folder that looks complete.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..io.datafile import write_data
from ..io.spectoml import write_spec
from ..model import Model
from ..numerics import ContactLaw, Prepared, TimeStep, prepare
from ..scenes import Deck, applicable_scenes, render_deck
from ..spec import FabricSpec, SpecError
from .folder import RunFolderError, check_output, temporary_folder

__all__ = [
    "MAX_RANKS",
    "Build",
    "OutputExistsError",
    "build",
    "check_ranks",
    "prepare_output",
    "render_decks",
]

#: Largest number of MPI ranks accepted (``--np``).
MAX_RANKS = 4096


def check_ranks(ranks: int) -> None:
    """SpecError unless 1 <= ranks <= :data:`MAX_RANKS`."""
    if not 1 <= ranks <= MAX_RANKS:
        raise SpecError("--np", ranks, f"out of range: allowed [1, {MAX_RANKS}] MPI ranks")


class OutputExistsError(FileExistsError):
    """The output folder exists and is not empty."""


@dataclass(frozen=True)
class Build:
    """What :func:`build` wrote: the folder, the prepared run and its decks (by name)."""

    directory: Path
    run: Prepared
    decks: dict[str, Deck]

    @property
    def model(self) -> Model:
        """The model (physical masses and stiffnesses)."""
        return self.run.model

    @property
    def time_step(self) -> TimeStep:
        """The time step and its limits."""
        return self.run.time_step

    @property
    def contact(self) -> ContactLaw:
        """The contact law."""
        return self.run.contact


def render_decks(run: Prepared, plain_lmp: bool = False) -> dict[str, Deck]:
    """The run's decks by name (``verify`` and every scene the spec supports); raises
    :class:`~ncf2lammps.spec.SpecError` where a value makes a scene impossible."""
    return {
        name: render_deck(run, name, plain_lmp=plain_lmp)
        for name in ("verify", *applicable_scenes(run.spec))
    }


def prepare_output(directory: str | os.PathLike, force: bool = False) -> tuple[Path, Path]:
    """(final, partial) paths; refuses an existing non-empty folder unless ``force``, and a
    file or an unwritable place always (:func:`~ncf2lammps.orchestration.folder.check_output`)."""
    final = check_output(directory, force)
    partial = temporary_folder(final)
    shutil.rmtree(partial, ignore_errors=True)
    try:
        partial.mkdir(parents=True)
    except OSError as err:
        raise RunFolderError(final, f"cannot be made ({err.strerror}): choose another -o") from None
    return final, partial


def build(
    spec: FabricSpec | Prepared,
    directory: str | os.PathLike,
    force: bool = False,
    plain_lmp: bool = False,
    finish: Callable[[Path, Model], None] | None = None,
) -> Build:
    """Write model.data, spec.resolved.toml and decks/in.<scene>.lmp into ``directory``.

    ``plain_lmp`` renders scene decks that write their own restart files (for runs without
    the Python driver); ``finish(folder, model)`` adds files before the folder is renamed
    into place.
    """
    run = spec if isinstance(spec, Prepared) else prepare(spec)
    final, partial = prepare_output(directory, force)
    try:
        write_data(partial / "model.data", run.simulated)
        write_spec(partial / "spec.resolved.toml", run.spec)
        (partial / "decks").mkdir()
        decks = render_decks(run, plain_lmp)
        for name, deck in decks.items():
            (partial / "decks" / f"in.{name}.lmp").write_text(deck.text)
        if finish is not None:
            finish(partial, run.model)
        if final.exists():
            shutil.rmtree(final)
        partial.rename(final)
    except BaseException:
        shutil.rmtree(partial, ignore_errors=True)
        raise
    return Build(final, run, decks)
