"""The scene protocol: what the orchestration knows of a scene, and the one way a scene runs.

A scene is one virtual process or test with a deck of its own. Its module defines ``SCENE``, a
:class:`Scene`, and the registry (:data:`ncf2lammps.scenes.SCENES`) lists it in run order.
Adding a scene means adding one module and one registry entry.

How a scene runs (:func:`execute`, on every MPI rank of the scene's process)::

    deck = render(scene.template, base context + scene.deck_values(run))   # once, when built
    run_deck(engine, deck, chunk=scene.chunk, checkpoint=...)               # in the run folder
        at each "# stage: NAME" line: scene.stage_checks(engine, run, NAME) -> live attributes
    attrs, datasets = scene.collect(run, folder)                            # from its files
    scene.figures(results, folder)                                          # report
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..engine import Checkpoints, Engine, run_deck
from ..numerics import Prepared
from ..spec import FabricSpec

__all__ = ["Scene", "execute"]


@dataclass(frozen=True)
class Scene:
    """One scene's description.

    Attributes:
        name: the scene's name (``results.h5`` group, ``decks/in.<name>.lmp``, file prefixes).
        template: its deck template under ``templates/``.
        applies: whether a spec supports the scene (manufacture needs a stitch).
        requires: the scenes whose state it starts from (run before it).
        deck_values: the typed values of its template beyond the base context.
        periods: the recording periods (steps) of its deck, from its deck values; a checkpoint
            at a multiple of their least common multiple splits no recording window.
        collect: ``(attrs, datasets)`` of its results group, read from its files in a folder.
        figures: its figures in ``<folder>/figures`` from the read results; returns the paths.
        chunk: steps per chunk of a ``run`` (progress and NaN checks between chunks).
        stage_checks: live checks at a stage marker ``(engine, run, stage) -> attributes``
            (raising on a failed check), or None.
    """

    name: str
    template: str
    applies: Callable[[FabricSpec], bool]
    requires: Callable[[FabricSpec], tuple[str, ...]]
    deck_values: Callable[[Prepared], dict]
    periods: Callable[[dict], tuple[int, ...]]
    collect: Callable[[Prepared, Path], tuple[dict, dict]]
    figures: Callable[[dict, Path], list[Path]]
    chunk: int
    stage_checks: Callable[[Engine, Prepared, str], dict] | None = None


def execute(
    engine: Engine,
    scene: Scene,
    run: Prepared,
    progress: Callable[[str, int, int, int], None] | None = None,
    checkpoint: Checkpoints | None = None,
) -> dict:
    """Run ``decks/in.<scene>.lmp`` (relative to the process's working directory) in chunks of
    ``scene.chunk``; returns the live attributes of its stage checks."""
    attrs: dict = {}

    def on_stage(stage: str) -> None:
        if scene.stage_checks is not None:
            attrs.update(scene.stage_checks(engine, run, stage))

    run_deck(
        engine,
        f"decks/in.{scene.name}.lmp",
        chunk=scene.chunk,
        on_stage=on_stage,
        on_chunk=progress,
        checkpoint=checkpoint,
    )
    return attrs
