"""The run loop of a deck: line by line, each plain ``run N`` in chunks, with checkpoints.

:func:`run_deck` does, in pseudocode (``every`` = ``checkpoint.every``, 0 without one)::

    stage, first = "setup", 0
    if resuming:                                  # see ncf2lammps.engine.journal.replay
        cut fix ave/time files and dumps back to the checkpoint's step
        re-run the journaled commands before the checkpoint's run (first read -> read_restart)
        finish that run from the checkpoint's step to its planned end (chunks, as below)
        first = the line after it
    for line in deck[first:]:
        if line is "# stage: NAME":
            stage = NAME; journal it; on_stage(NAME)          # the scene's stage checks
        elif line is "run N" (N > 0, no keywords):
            start, end = step, step + N
            pre = "yes"
            while step < end:
                n = min(chunk, end - step, every - step % every if every else inf)
                before = step
                run n start <start> stop <end> pre <pre> post <"yes" if last chunk else "no">
                pre = "no"
                NaN check of ke and pe; on_chunk(stage, step, start, end)
                if step < before + n or a halt fired at step: break   # a fix halt ended the run
                if every and step % every == 0:
                    write_restart, record the checkpoint; pre = "yes"
        elif line is not empty after its comment is cut:
            journal it as LAMMPS expands it; run it

Any other ``run`` (``run 0``, ``run N upto``, ...) is a command like the others. Relative paths
resolve against the process's working directory.
"""

from __future__ import annotations

import operator
import os
import re
from collections.abc import Callable
from pathlib import Path

from .core import Engine, EngineError
from .journal import Checkpoints, Journal, replay, strip_comment

__all__ = ["run_deck"]

_STAGE = re.compile(r"^#\s*stage:\s*([\w-]+)")
_RUN = re.compile(r"^run\s+(\d+)\s*$")
_HALT = re.compile(
    r"^fix\s+(\S+)\s+\S+\s+halt\s+(\d+)\s+v_(\w+)\s+(<=|>=|==|!=|<|>)\s+"
    r"([-+0-9.eE]+)\s+error\s+continue\b"
)
_UNFIX = re.compile(r"^unfix\s+(\S+)")
_FIX = re.compile(r"^fix\s+(\S+)\s")
_COMPARE = {
    "<": operator.lt,
    "<=": operator.le,
    ">": operator.gt,
    ">=": operator.ge,
    "==": operator.eq,
    "!=": operator.ne,
}


class _Halts:
    """The deck's ``fix ID group halt N v_name OP value error continue`` conditions in force.

    LAMMPS ends a run on the step such a halt fires. When that step is also a chunk's last,
    the chunk ends where it was planned to and only the condition tells that the ``run`` is
    over: :meth:`fired` evaluates it again there (its fixes and computes are current)."""

    def __init__(self) -> None:
        self.active: dict[str, tuple[int, str, Callable[[float, float], bool], float]] = {}

    def observe(self, line: str) -> None:
        """Follow a command as LAMMPS runs it (a halt defined, a fix ID redefined or unfixed).
        Raises EngineError on a continue-halt it cannot evaluate again."""
        if halt := _HALT.match(line):
            fix_id, every, name, op, value = halt.groups()
            self.active[fix_id] = (int(every), name, _COMPARE[op], float(value))
        elif fix := _FIX.match(line) or _UNFIX.match(line):
            self.active.pop(fix.group(1), None)
            words = line.split()
            if "halt" in words[3:4] and "continue" in words:
                raise EngineError(
                    f"deck line {line!r}: a 'fix ID group halt N v_name OP number error"
                    " continue' is the form the driver can end a chunked run on"
                )

    def fired(self, engine: Engine) -> bool:
        """Whether a halt's condition holds at this step, one of its checks."""
        step = engine.step
        return any(
            step % every == 0 and compare(engine.variable(name), value)
            for every, name, compare, value in self.active.values()
        )


def run_deck(
    engine: Engine,
    path: str | os.PathLike,
    chunk: int,
    on_stage: Callable[[str], None] | None = None,
    on_chunk: Callable[[str, int, int, int], None] | None = None,
    checkpoint: Checkpoints | None = None,
) -> None:
    """Run the deck at ``path`` line by line, each plain ``run N`` in chunks of ``chunk`` steps.

    Lines ``# stage: NAME`` call ``on_stage(NAME)`` before the stage's commands run. After every
    chunk the kinetic and potential energies are checked for NaN/inf and ``on_chunk(stage,
    step, run_start, run_end)`` is called. A run stopped early by ``fix halt`` (step short of
    the chunk's end) ends that ``run`` command; the deck continues.

    With ``checkpoint`` every command is journaled as LAMMPS expanded it, a restart file is
    written at every multiple of its interval, and ``checkpoint.resume`` continues the deck
    from the last one (stage markers before it call no ``on_stage``).
    """
    lines = Path(path).read_text().splitlines()
    journal = Journal(checkpoint, engine) if checkpoint is not None else None
    try:
        _deck(engine, lines, chunk, on_stage, on_chunk, journal)
    finally:
        if journal is not None:
            journal.close()


def _deck(engine, lines, chunk, on_stage, on_chunk, journal) -> None:
    stage, first = "setup", 0
    halts = _Halts()
    if journal is not None and journal.resume:
        stage, first = _resume(engine, journal, chunk, on_chunk, halts)
    for number, raw in enumerate(lines[first:], start=first):
        marker = _STAGE.match(raw.strip())
        if marker:
            stage = marker.group(1)
            if journal is not None:
                journal.stage(number, stage)
            if on_stage is not None:
                on_stage(stage)
            continue
        line = strip_comment(raw)
        if not line:
            continue
        match = _RUN.match(line)
        if match is not None and int(match.group(1)) > 0:
            start = engine.step
            end = start + int(match.group(1))
            if journal is not None:
                journal.run(number, start, end)
            _run(engine, number, start, end, chunk, stage, on_chunk, journal, halts)
            if journal is not None:
                journal.done(number, engine.step)
            continue
        if journal is not None:
            expanded = engine.expand(line)
            journal.command(number, expanded)
            line = expanded
        engine.command(line)
        halts.observe(line)


def _resume(engine, journal, chunk, on_chunk, halts) -> tuple[str, int]:
    """Replay the deck up to the last checkpoint, finish its run; returns (stage, next line)."""
    stage, (_, number, start, end), finished = replay(journal, engine, halts.observe)
    journal.run(number, start, end)
    if not finished:
        _run(engine, number, start, end, chunk, stage, on_chunk, journal, halts)
    journal.done(number, engine.step)
    return stage, number + 1


def _run(engine, number, start, end, chunk, stage, on_chunk, journal, halts) -> None:
    """Run from the current step to ``end`` (of a ``run`` begun at ``start``) in chunks,
    writing a checkpoint at every multiple of the journal's interval."""
    first = True
    every = journal.every if journal is not None else 0
    while engine.step < end:
        n = min(chunk, end - engine.step)
        if every:
            n = min(n, every - engine.step % every)
        before = engine.step
        pre = "yes" if first else "no"
        post = "yes" if engine.step + n >= end else "no"
        engine.command(f"run {n} start {start} stop {end} pre {pre} post {post}")
        first = False
        engine.check_finite(stage)
        if on_chunk is not None:
            on_chunk(stage, engine.step, start, end)
        if engine.step < before + n or halts.fired(engine):  # halted by a fix halt
            break
        if every and engine.step % every == 0:
            journal.checkpoint(stage, number)
            first = True  # write_restart migrates atoms: the next chunk needs its setup
