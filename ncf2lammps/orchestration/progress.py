"""Progress of a scene's chunked runs on stderr, drawn by tqdm.

On a terminal: one bar per run of the deck (``scene:stage``, percent of the run's planned steps,
steps/s, time left), redrawn after each chunk. Elsewhere (a log file, a batch job): a plain line
in the same format at most every :data:`PLAIN_EVERY_S` seconds, and one when a run ends.
A run stopped early by its own criterion (``fix halt``) ends before its planned steps.
"""

from __future__ import annotations

import sys
import time

from tqdm import tqdm

__all__ = ["PLAIN_EVERY_S", "Progress"]

#: Seconds between plain progress lines when stderr is not a terminal.
PLAIN_EVERY_S = 10.0


class Progress:
    """Context manager; :meth:`update` after each chunk of a ``run``."""

    def __init__(self, scene: str, enabled: bool = True, stream=None):
        self.scene = scene
        self.enabled = enabled
        self.stream = stream if stream is not None else sys.stderr
        self.tty = enabled and self.stream.isatty()
        self.bar: tqdm | None = None
        self.run: tuple[int, int] | None = None
        self.started = time.perf_counter()
        self.last_line = 0.0

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        if self.bar is not None:
            self.bar.close()

    def update(self, stage: str, step: int, start: int, end: int) -> None:
        """The current run of ``stage``, planned from step ``start`` to ``end``, is at ``step``."""
        if not self.enabled:
            return
        if (start, end) != self.run:
            self._start_run(stage, start, end)
        if self.tty:
            self.bar.update(step - start - self.bar.n)
            return
        now = time.perf_counter()
        if now - self.last_line >= PLAIN_EVERY_S or step >= end:
            self.last_line = now
            line = tqdm.format_meter(
                step - start,
                end - start,
                now - self.started,
                prefix=f"{self.scene}:{stage}",
                unit=" steps",
                unit_scale=True,
            )
            self.stream.write(line + "\n")
            self.stream.flush()

    def _start_run(self, stage: str, start: int, end: int) -> None:
        if self.bar is not None:
            self.bar.close()
        self.run = (start, end)
        self.started = time.perf_counter()
        if self.tty:
            self.bar = tqdm(
                total=end - start,
                desc=f"{self.scene}:{stage}",
                unit=" steps",
                unit_scale=True,
                file=self.stream,
                dynamic_ncols=True,
            )
