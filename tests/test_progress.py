"""The progress display: percent of a run's planned steps, steps/s and time left (tqdm)."""

from __future__ import annotations

import io

from ncf2lammps.orchestration import progress
from ncf2lammps.orchestration.progress import Progress


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_plain_lines_without_a_terminal(monkeypatch):
    """Without a terminal: a line when a run starts, then at most every PLAIN_EVERY_S seconds,
    and one at its planned end; each names scene and stage and gives the percent done."""
    clock = iter([0.0, 1.0, 2.0, 30.0, 31.0, 32.0])
    monkeypatch.setattr(progress.time, "perf_counter", lambda: next(clock))
    stream = io.StringIO()
    with Progress("manufacture", stream=stream) as bar:
        bar.update("needles", 2000, 0, 8000)  # t = 1 after the run's first chunk (t = 0 init)
        bar.update("needles", 4000, 0, 8000)  # t = 2: within 10 s of the last line
        bar.update("needles", 6000, 0, 8000)  # t = 30: a line
        bar.update("needles", 8000, 0, 8000)  # t = 31: the planned end
    lines = stream.getvalue().splitlines()
    assert len(lines) == 3, lines
    assert lines[0].startswith("manufacture:needles:  25%")
    assert " 75%" in lines[1] and "steps/s" in lines[1]
    assert "100%" in lines[2]


def test_a_bar_per_run_on_a_terminal():
    """On a terminal: a tqdm bar per run, labelled by the scene alone when the stage is named
    after it, redrawn in place (carriage returns), ending at the run's planned steps."""
    stream = Terminal()
    with Progress("shear", stream=stream) as bar:
        for step in range(2000, 12000, 2000):
            bar.update("shear", step, 0, 10000)
    text = stream.getvalue()
    assert "\r" in text and "shear: 100%" in text and "10.0k/10.0k" in text


def test_silent_on_the_other_ranks():
    stream = Terminal()
    with Progress("compaction", enabled=False, stream=stream) as bar:
        bar.update("compaction", 5000, 0, 10000)
    assert stream.getvalue() == ""
