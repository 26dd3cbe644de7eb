"""One scene's deck in a process of its own: ``python -m ncf2lammps.orchestration.worker SCENE
EVERY RESUME``, started in the run folder (under ``mpiexec -n N`` for N ranks).

Every rank runs the same Python driver (:func:`~ncf2lammps.scenes.execute`) on one LAMMPS
instance spread over all ranks; rank 0 shows the progress and writes ``<SCENE>.worker.json``
with the scene's live attributes or its error, which
:func:`~ncf2lammps.orchestration.run.run_scenes` reads back. The spec is
``decks/spec.<SCENE>.toml``; EVERY is the checkpoint interval (steps), RESUME 0 or 1. A scene's
process never outlives the run that started it (:func:`watch_driver`): a killed run stops
writing into its folder at once, so ``--resume`` finds it as the kill left it.
"""

from __future__ import annotations

import json
import os
import socket
import sys
import threading
import time
from pathlib import Path

from ..engine import Checkpoints, Engine, EngineError
from ..numerics import prepare
from ..scenes import SCENES, execute
from ..spec import load_spec
from .folder import process_alive
from .progress import Progress

#: Seconds between two looks of a scene's process at the process that started the run.
WATCH_EVERY_S = 0.2


def watch_driver(identity: str | None) -> None:
    """End this process (exit 137, like a kill) as soon as the run's driver, ``pid@host`` from
    ``NCF2LAMMPS_DRIVER``, is gone; only on the driver's host (a rank on another node cannot
    see it, and mpiexec ends those)."""
    if not identity:
        return
    pid, _, host = identity.partition("@")
    if host != socket.gethostname():
        return

    def watch() -> None:
        while True:
            time.sleep(WATCH_EVERY_S)
            if not process_alive(int(pid)):
                os._exit(137)

    threading.Thread(target=watch, name="watch-driver", daemon=True).start()


def main(argv: list[str]) -> int:
    """Run the scene in the working directory; returns the exit code (1 if the run failed)."""
    watch_driver(os.environ.get("NCF2LAMMPS_DRIVER"))
    scene, every, resume = SCENES[argv[0]], int(argv[1]), argv[2] == "1"
    run = prepare(load_spec(Path("decks") / f"spec.{scene.name}.toml"))
    checkpoint = Checkpoints(scene.name, every, resume)
    outcome: dict = {}
    rank = 0
    try:
        with Engine(log=f"log.{scene.name}.lammps") as engine:
            rank = engine.rank
            with Progress(scene.name, enabled=rank == 0) as bar:
                outcome["attrs"] = execute(engine, scene, run, bar.update, checkpoint)
    except EngineError as err:
        outcome = {"error": str(err), "kind": type(err).__name__}
    if rank == 0:
        Path(f"{scene.name}.worker.json").write_text(json.dumps(outcome))
    return 1 if "error" in outcome else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
