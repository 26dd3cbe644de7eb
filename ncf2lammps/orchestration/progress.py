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
        self.label = scene
        self.first_step = 0
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
            self._start_run(stage, step, start, end)
            return
        if self.tty:
            self.bar.update(step - start - self.bar.n)
            return
        now = time.perf_counter()
        if now - self.last_line >= PLAIN_EVERY_S or step >= end:
            self._line(step, now)

    def _start_run(self, stage: str, step: int, start: int, end: int) -> None:
        """A new run: its first chunk (up to ``step``) is done; rates count from here on."""
        if self.bar is not None:
            self.bar.close()
        self.run = (start, end)
        self.label = self.scene if stage == self.scene else f"{self.scene}:{stage}"
        self.first_step = step
        self.started = time.perf_counter()
        if self.tty:
            self.bar = tqdm(
                total=end - start,
                initial=step - start,
                desc=self.label,
                unit=" steps",
                unit_scale=True,
                file=self.stream,
                dynamic_ncols=True,
            )
        else:
            self._line(step, self.started)

    def _line(self, step: int, now: float) -> None:
        """One plain progress line (percent, steps, elapsed, time left, rate)."""
        self.last_line = now
        elapsed = now - self.started
        rate = (
            (step - self.first_step) / elapsed if elapsed > 0 and step > self.first_step else None
        )
        start, end = self.run
        line = tqdm.format_meter(
            step - start,
            end - start,
            elapsed,
            prefix=self.label,
            unit=" steps",
            unit_scale=True,
            rate=rate,
        )
        self.stream.write(line + "\n")
        self.stream.flush()
