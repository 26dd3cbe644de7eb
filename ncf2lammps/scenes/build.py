"""Build a run folder: model.data, spec.resolved.toml and the decks, written atomically.

The folder is first written as ``<DIR>.partial-<pid>`` and renamed into place at the end, so an
interrupted build never leaves a folder that looks complete.
"""

from __future__ import annotations

import importlib
import math
import os
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from .. import __version__
from ..io.datafile import write_data
from ..io.deck import cadence, render
from ..io.spectoml import write_spec
from ..model import Model, build_model
from ..numerics import ContactLaw, TimeStep, contact_law, guards, simulated_model, time_step
from ..spec import FabricSpec, SpecError

__all__ = [
    "MAX_RANKS",
    "SCENES",
    "Build",
    "OutputExistsError",
    "applicable_scenes",
    "build",
    "check_ranks",
    "checkpoint_interval",
    "deck_context",
    "friction_pairs",
    "prepare_output",
]

#: Scenes in the order ``run`` executes them; ``verify`` (load, run 0) is built but not run.
#: Each is a module ``ncf2lammps.scenes.<name>`` with ``applies(spec)``, ``requires(spec)``,
#: ``deck_values(spec, model)``, ``execute(engine, spec, model, progress)`` and
#: ``figures(results, directory)``.
SCENES = ("manufacture", "compaction", "shear")


def scene_module(name: str):
    """The module implementing scene ``name``."""
    return importlib.import_module(f"{__package__}.{name}")


def applicable_scenes(spec: FabricSpec) -> tuple[str, ...]:
    """The scenes a spec supports, in run order (manufacture needs a stitch)."""
    return tuple(s for s in SCENES if scene_module(s).applies(spec))


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
    """What :func:`build` wrote: the folder, the model, its time step and contact law."""

    directory: Path
    model: Model
    time_step: TimeStep
    contact: ContactLaw
    decks: dict[str, Path]


def neighbor_skin(spec: FabricSpec, model: Model) -> float:
    """Neighbour skin (um): the spec's, else d/10 of the largest bead and at least 1 um."""
    if spec.numerics.neighbor_skin_um is not None:
        return spec.numerics.neighbor_skin_um
    return max(1.0, 0.1 * float(model.diameter.max()))


def deck_context(
    spec: FabricSpec,
    model: Model,
    scene: str,
    data_file: str = "model.data",
    restart_every: int = 0,
) -> dict:
    """The typed values every deck is rendered from (see templates/base.lmp.j2).

    ``restart_every`` (steps) writes LAMMPS restart files from the deck itself, for decks run
    by plain ``lmp`` (the Python driver writes its own checkpoints).
    """
    step = time_step(spec, model)
    skin = neighbor_skin(spec, model)
    longest_bond = max(t.r0 for t in model.bond_types)
    return {
        "version": __version__,
        "scene": scene,
        "data_file": data_file,
        "restart_file": None,
        "contact": contact_law(spec, model),
        "friction_pairs": friction_pairs(spec, model),
        "angle_style": None if model.angle_style == "none" else model.angle_style,
        "dt": step.dt,
        "skin": skin,
        "comm_cutoff": float(model.diameter.max()) + skin + 1.5 * longest_bond,
        "thermo_every": spec.numerics.thermo_every,
        "guards": guards(spec, model, step.dt),
        "dump_every": spec.output.dump_every_steps if scene != "verify" else 0,
        "restart_every": restart_every,
    }


def friction_pairs(spec: FabricSpec, model: Model) -> list[tuple[int, int, float]]:
    """(fibre type, stitch type, mu) 1-based, for a fibre-stitch friction of its own
    (``contact.fibre_stitch_friction``); empty when every pair shares ``contact.friction``."""
    mu = spec.contact.fibre_stitch_friction
    stitch = [i + 1 for i, t in enumerate(model.atom_types) if t.role == "stitch"]
    if mu is None or not stitch:
        return []
    fibre = [i + 1 for i, t in enumerate(model.atom_types) if t.role == "fibre"]
    return [(i, stitch[0], float(mu)) for i in fibre]


def prepare_output(directory: str | os.PathLike, force: bool = False) -> tuple[Path, Path]:
    """(final, partial) paths; refuses an existing non-empty folder unless ``force``."""
    final = Path(directory)
    if final.exists() and (not final.is_dir() or any(final.iterdir())) and not force:
        raise OutputExistsError(f"{final}: exists and is not empty (choose another -o or --force)")
    partial = final.with_name(f"{final.name}.partial-{os.getpid()}")
    shutil.rmtree(partial, ignore_errors=True)
    partial.mkdir(parents=True)
    return final, partial


def checkpoint_interval(spec: FabricSpec, deck: str) -> int:
    """Steps between checkpoints: ``output.checkpoint_every_steps`` rounded up to a multiple of
    the deck's :func:`~ncf2lammps.io.deck.cadence`, so none splits a recording window (0: none)."""
    every = spec.output.checkpoint_every_steps
    period = cadence(deck)
    return period * math.ceil(every / period) if every else 0


def build(
    spec: FabricSpec,
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
    model = build_model(spec)
    step = time_step(spec, model)
    final, partial = prepare_output(directory, force)
    try:
        write_data(partial / "model.data", simulated_model(spec, model))
        write_spec(partial / "spec.resolved.toml", spec)
        (partial / "decks").mkdir()
        decks = {}
        for scene in ("verify", *applicable_scenes(spec)):
            values = deck_context(spec, model, scene, "model.data")
            if scene != "verify":
                values.update(scene_module(scene).deck_values(spec, model))
            text = render(f"{scene}.lmp.j2", **values)
            if plain_lmp and scene != "verify":
                values["restart_every"] = checkpoint_interval(spec, text)
                text = render(f"{scene}.lmp.j2", **values)
            (partial / "decks" / f"in.{scene}.lmp").write_text(text)
            decks[scene] = final / "decks" / f"in.{scene}.lmp"
        if finish is not None:
            finish(partial, model)
        if final.exists():
            shutil.rmtree(final)
        partial.rename(final)
    except BaseException:
        shutil.rmtree(partial, ignore_errors=True)
        raise
    return Build(final, model, step, contact_law(spec, model), decks)
