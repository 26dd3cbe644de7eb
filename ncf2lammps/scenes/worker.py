"""One scene's deck under ``mpiexec -n N python -m ncf2lammps.scenes.worker DIR SCENE EVERY RESUME``.

Every rank runs the same Python driver (:meth:`~ncf2lammps.engine.Engine.run_deck`) on one
LAMMPS instance spread over all ranks; rank 0 writes ``<SCENE>.worker.json`` with the scene's
live attributes or its error, which :func:`~ncf2lammps.scenes.run.run_scenes` reads back.
The spec is ``DIR/decks/spec.<SCENE>.toml``; EVERY is the checkpoint interval (steps), RESUME
0 or 1.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from ..engine import Checkpoints, Engine, EngineError
from ..model import build_model
from ..spec import load_spec
from .build import scene_module
from .progress import Progress


def main(argv: list[str]) -> int:
    """Run the scene; returns the exit code (1 if the run failed)."""
    directory, scene, every, resume = Path(argv[0]), argv[1], int(argv[2]), argv[3] == "1"
    spec = load_spec(directory / "decks" / f"spec.{scene}.toml")
    model = build_model(spec)
    checkpoint = Checkpoints(scene, every, resume)
    outcome: dict = {}
    rank = 0
    try:
        with Engine(directory, log=f"log.{scene}.lammps") as engine:
            rank = engine.rank
            with Progress(scene, stream=sys.stderr if rank == 0 else _Silent()) as bar:
                outcome["attrs"] = scene_module(scene).execute(
                    engine, spec, model, bar.update, checkpoint
                )
    except EngineError as err:
        outcome = {"error": str(err), "kind": type(err).__name__}
    if rank == 0:
        (directory / f"{scene}.worker.json").write_text(json.dumps(outcome))
    return 1 if "error" in outcome else 0


class _Silent:
    """A stream for the ranks that do not report progress."""

    def isatty(self) -> bool:
        return False

    def write(self, text: str) -> None:
        pass

    def flush(self) -> None:
        pass


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
