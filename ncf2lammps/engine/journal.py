"""The journal and checkpoints of a deck run, and the rules by which a resume replays a deck.

Files, in the process's working directory: ``<name>.journal`` (one JSON list a line: ``C``
command as LAMMPS expanded it, ``S`` stage marker, ``R`` run begun, ``E`` run ended),
``<name>.checkpoint.json`` (the last checkpoint's record, with the wall time spent on the
steps up to it, every segment of a resumed run included) and ``<name>.checkpoint.<step>.restart``
(only the last one is kept). Rank 0 writes the files; every rank writes the restart.
"""

from __future__ import annotations

import json
import math
import os
import re
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from .core import Engine, EngineError

__all__ = ["CheckpointError", "Checkpoints", "Journal", "replay", "strip_comment"]

#: Output files of fixes are appended to, not truncated, when a run is resumed.
_APPEND = re.compile(r"^(fix\s+\S+\s+\S+\s+(?:ave/time|print)\b.*\s)file(\s)")
_OUTPUT = re.compile(r"^fix\s+\S+\s+\S+\s+ave/time\b.*\s(?:file|append)\s+(\S+)")
_DUMP = re.compile(r"^dump\s+\S+\s+\S+\s+\S+\s+\d+\s+(\S+)")
_INTERNAL = re.compile(r"^variable\s+(\S+)\s+internal\b")
#: Commands not run again on resume: they changed or wrote a state the checkpoint already has,
#: and every ``run`` (``run 0`` too): the restart's fix state (a granular wall's contact history
#: and its moving region's last position) goes only to fixes defined again before the first run
#: after ``read_restart``; LAMMPS drops what is left at that run.
_NOT_REPLAYED = frozenset(
    (
        "run",
        "reset_timestep",
        "change_box",
        "displace_atoms",
        "velocity",
        "set",
        "create_atoms",
        "delete_atoms",
        "create_bonds",
        "delete_bonds",
        "write_restart",
        "write_data",
        "write_dump",
        "print",
    )
)


class CheckpointError(EngineError):
    """A checkpoint a run cannot resume from; ``str()`` is one line naming the file and why."""


#: The keys of a checkpoint record and their types (``wall_s``, a number, may be absent).
_RECORD = {"step": int, "restart": str, "line": int, "stage": str, "internal": dict}


def _read_record(path: Path) -> dict:
    """The checkpoint record in ``path``, checked against :data:`_RECORD`."""
    try:
        state = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
        raise CheckpointError(f"{path}: unreadable ({type(err).__name__})") from None
    if not isinstance(state, dict):
        raise CheckpointError(f"{path}: not a checkpoint record (a JSON object)")
    for key, kind in _RECORD.items():
        value = state.get(key)
        if not isinstance(value, kind) or isinstance(value, bool):
            raise CheckpointError(f"{path}: {key!r} is missing or not a {kind.__name__}")
    if state["step"] < 0 or state["line"] < 0 or Path(state["restart"]).name != state["restart"]:
        raise CheckpointError(f"{path}: a negative step or line, or a restart file elsewhere")
    numbers = [state.get("wall_s", 0.0), *state["internal"].values()]
    if not all(isinstance(v, int | float) and not isinstance(v, bool) for v in numbers):
        raise CheckpointError(f"{path}: 'wall_s' or an internal variable is not a number")
    return state


def _journal_entries(path: Path) -> list[list]:
    """The entries of a journal file (a line cut short by a kill is dropped)."""
    out = []
    for line in path.read_text().splitlines():
        try:
            out.append(json.loads(line))
        except json.JSONDecodeError:
            continue
    return out


def _recorded_wall(state: dict | None) -> float:
    """The wall time (s) a checkpoint record holds: 0 without one, NaN if it does not say."""
    return 0.0 if state is None else float(state.get("wall_s", math.nan))


def strip_comment(raw: str) -> str:
    """A deck line without its comment (``print`` lines are kept whole)."""
    if raw.lstrip().startswith("print"):
        return raw.strip()
    return raw.split("#", 1)[0].strip()


@dataclass(frozen=True)
class Checkpoints:
    """Checkpointing of one deck run by :func:`~ncf2lammps.engine.run_deck`.

    Attributes: ``name`` prefixes the files (``<name>.journal``, ``<name>.checkpoint.json``,
    ``<name>.checkpoint.<step>.restart``); ``every`` = steps between restart files (0: none,
    the journal is still kept); ``resume`` continues from the last checkpoint.
    """

    name: str
    every: int = 0
    resume: bool = False

    def state(self, directory: str | os.PathLike = ".") -> dict | None:
        """The last checkpoint's record (step, restart file, run line, internal variables);
        None without one or when its restart file is gone. Raises :class:`CheckpointError`
        for a damaged record."""
        path = self.record(directory)
        if not path.is_file():
            return None
        state = _read_record(path)
        return state if (Path(directory) / state["restart"]).is_file() else None

    def record(self, directory: str | os.PathLike = ".") -> Path:
        """Path of the last checkpoint's record (``<name>.checkpoint.json``), present or not."""
        return Path(directory) / f"{self.name}.checkpoint.json"

    def check(self, directory: str | os.PathLike = ".") -> None:
        """Raise :class:`CheckpointError` unless a resume can use the last checkpoint (if any):
        a sound record whose run the deck's journal holds."""
        state = self.state(directory)
        if state is None:
            return
        journal = Path(directory) / f"{self.name}.journal"
        entries = _journal_entries(journal) if journal.is_file() else []
        if not any(e[:2] == ["R", state["line"]] for e in entries if isinstance(e, list)):
            raise CheckpointError(
                f"{journal}: holds no run at the checkpoint's deck line {state['line']}"
            )

    def wall_before(self, directory: str | os.PathLike = ".") -> float:
        """Wall time (s) spent on the steps up to the last checkpoint, every segment of a resumed
        run included (0 without a checkpoint; NaN if its record does not say)."""
        return _recorded_wall(self.state(directory))

    @property
    def files(self) -> str:
        """Glob pattern of this deck's checkpoint record and restart files."""
        return f"{self.name}.checkpoint.*"

    def clear(self, directory: str | os.PathLike = ".") -> None:
        """Remove this deck's checkpoint record and restart files from ``directory``."""
        for old in Path(directory).glob(self.files):
            old.unlink()


class Journal:
    """Commands as LAMMPS expanded them, runs and their ends, stage markers: one JSON list a
    line in ``<name>.journal`` (rank 0 writes), and the restart files of the checkpoints."""

    def __init__(self, checkpoints: Checkpoints, engine: Engine):
        self.name = checkpoints.name
        self.every = checkpoints.every
        self.resume = checkpoints.resume
        self.engine = engine
        self.writer = engine.rank == 0
        self.path = Path(f"{self.name}.journal")
        self.state_path = checkpoints.record()
        self.internal: list[str] = []
        self.previous: str | None = None
        self.fh = None
        self.started = time.perf_counter()
        self.wall_before = 0.0
        if not checkpoints.resume:
            if self.writer:
                checkpoints.clear()
            self.reopen()

    def reopen(self) -> None:
        """Start the journal file afresh (after :meth:`entries` was read, on resume)."""
        if self.writer:
            self.fh = open(self.path, "w", buffering=1)

    def _write(self, *entry) -> None:
        if self.fh is not None:
            self.fh.write(json.dumps(entry) + "\n")

    def command(self, number: int, text: str) -> None:
        if match := _INTERNAL.match(text):
            self.internal.append(match.group(1))
        self._write("C", number, text)

    def stage(self, number: int, name: str) -> None:
        self._write("S", number, name)

    def run(self, number: int, start: int, end: int) -> None:
        self._write("R", number, start, end)

    def done(self, number: int, step: int) -> None:
        self._write("E", number, step)

    def entries(self) -> list[list]:
        """The journal's entries (a line cut short by a kill is dropped)."""
        return _journal_entries(self.path)

    def load(self) -> dict:
        state = Checkpoints(self.name).state()
        if state is None:
            raise EngineError(f"{self.name}: no checkpoint to resume from")
        self.previous = state["restart"]
        self.wall_before = _recorded_wall(state)
        return state

    def checkpoint(self, stage: str, number: int) -> None:
        """write_restart now; then (rank 0) the record, replaced atomically, and the old file."""
        step = self.engine.step
        restart = f"{self.name}.checkpoint.{step}.restart"
        self.engine.command(f"write_restart {restart}")
        values = {name: self.engine.variable(name) for name in dict.fromkeys(self.internal)}
        if not self.writer:
            return
        wall = self.wall_before + time.perf_counter() - self.started
        state = {"step": step, "restart": restart, "line": number, "stage": stage, "wall_s": wall}
        temporary = self.state_path.with_suffix(".tmp")
        temporary.write_text(json.dumps({**state, "internal": values}))
        os.replace(temporary, self.state_path)
        if self.previous and self.previous != restart:
            Path(self.previous).unlink(missing_ok=True)
        self.previous = restart

    def close(self) -> None:
        if self.fh is not None:
            self.fh.close()
            self.fh = None

    def truncate_outputs(self, step: int) -> None:
        """Drop rows of ``fix ave/time`` files and dump frames written after ``step``."""
        if not self.writer:
            return
        for entry in self.entries():
            if entry[0] != "C":
                continue
            if match := _OUTPUT.match(entry[2]):
                _keep_rows(Path(match.group(1)), step)
            elif match := _DUMP.match(entry[2]):
                _keep_frames(Path(match.group(1)), step)


def _keep_rows(path: Path, step: int) -> None:
    """Keep the comment lines and the rows of a ``fix ave/time`` file up to ``step``."""
    if not path.is_file():
        return
    kept = [
        line
        for line in path.read_text().splitlines(keepends=True)
        if line.startswith("#") or not line.strip() or int(float(line.split()[0])) <= step
    ]
    path.write_text("".join(kept))


def _keep_frames(path: Path, step: int) -> None:
    """Keep the frames of a text dump written up to ``step``."""
    if not path.is_file():
        return
    lines = path.read_text().splitlines(keepends=True)
    starts = [i for i, line in enumerate(lines) if line.startswith("ITEM: TIMESTEP")]
    cut = next((i for i in starts if int(lines[i + 1]) > step), len(lines))
    path.write_text("".join(lines[:cut]))


def replay(
    journal: Journal, engine: Engine, on_command: Callable[[str], None] | None = None
) -> tuple[str, list, bool]:
    """Rebuild the state at the last checkpoint; returns (stage, the journal's ``R`` entry
    ``[R, line, start, end]`` of the run that wrote it, whether that run had ended there).

    Output files are first cut back to the checkpoint's step. The commands journaled before
    that run are run again as LAMMPS expanded them the first time (every ``$(...)`` keeps its
    original value), with
    ``read_restart`` of the checkpoint for the first read and without any run (``run 0``
    included) and the commands that changed or wrote the state (:data:`_NOT_REPLAYED`);
    internal variables are defined with their checkpointed values; ``fix ave/time``/``print``
    files and dumps are appended to. ``on_command`` sees each command run again.
    """
    state = journal.load()
    step = int(state["step"])
    journal.truncate_outputs(step)
    entries = journal.entries()
    holding = next(e for e in entries if e[0] == "R" and e[1] == state["line"])
    finished = [e for e in entries if e[0] == "E" and e[1] == state["line"]]
    journal.reopen()
    read = False
    stage = "setup"
    for entry in entries[: entries.index(holding)]:
        if entry[0] == "S":
            stage = entry[2]
            journal.stage(entry[1], stage)
        if entry[0] != "C":
            continue
        text = strip_comment(entry[2])
        words = text.split()
        if words[0] in ("read_data", "read_restart") and not read:
            read = True
            text = f"read_restart {state['restart']}"
        elif not read or words[0] in _NOT_REPLAYED:
            continue
        elif (internal := _INTERNAL.match(text)) and internal.group(1) in state["internal"]:
            # Defined with its checkpointed value, so that a fix created after it (fix
            # controller reads its control variable once, when defined) starts from it too.
            name = internal.group(1)
            text = f"variable {name} internal {state['internal'][name]!r}"
        journal.command(entry[1], entry[2])
        engine.command(_APPEND.sub(r"\1append\2", text))
        if on_command is not None:
            on_command(text)
        if words[0] == "dump":
            engine.command(f"dump_modify {words[1]} append yes")
    return stage, holding, bool(finished and finished[0][2] == step)
