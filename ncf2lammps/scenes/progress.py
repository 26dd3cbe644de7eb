"""A one-line progress bar on stderr for chunked LAMMPS runs (no extra dependency)."""

from __future__ import annotations

import sys
import time

__all__ = ["Progress"]


class Progress:
    """Context manager; ``update(stage, step, run_end)`` redraws ``scene:stage step/end``."""

    def __init__(self, scene: str, stream=None):
        self.scene = scene
        self.stream = stream if stream is not None else sys.stderr
        self.start = time.perf_counter()
        self.tty = self.stream.isatty()
        self.last = 0.0

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        if self.tty:
            self.stream.write("\n")
        self.stream.flush()

    def update(self, stage: str, step: int, run_end: int) -> None:
        """Redraw (on a terminal) or print a line at most every 10 s (in a log)."""
        now = time.perf_counter()
        if not self.tty and now - self.last < 10.0:
            return
        self.last = now
        line = (
            f"{self.scene}:{stage:<12} step {step:>10d} / {run_end:<10d} {now - self.start:7.1f} s"
        )
        self.stream.write(f"\r{line}" if self.tty else f"{line}\n")
        self.stream.flush()
