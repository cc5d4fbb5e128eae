"""Progress of a run, on stderr: a `rich <https://rich.readthedocs.io>`_ progress bar on a terminal,
a plain line every few seconds otherwise (logs, CI).

Every run function takes ``progress``: ``True`` shows this bar, a callable
``progress(t, t_end, steps, newton_iterations, rejected_steps)`` is called instead, and ``None``
(the default) shows nothing::

    >>> from railslosh import slosh
    >>> res = slosh.run(mesh, fluid, tank, motion, t_end=4.0, progress=True)   # doctest: +SKIP
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from rich.console import Console
from rich.progress import BarColumn, Progress, TaskID, TextColumn, TimeElapsedColumn, TimeRemainingColumn

__all__ = ["ProgressBar", "callback"]

#: The ``progress`` argument of the run functions.
ProgressArg = bool | Callable[[float, float, int, int, int], object] | None


class ProgressBar:
    """Simulated time against wall time, with the ETA and the Newton statistics of the run. Called
    as ``bar(t, t_end, steps, newton_iterations, rejected_steps)`` (the ``progress`` callback of the
    run functions). On a terminal a rich bar is redrawn in place; otherwise :meth:`line` is printed
    at most every ``every`` seconds and at the end. :meth:`close` stops the bar (also done at the
    end of the run)."""

    def __init__(self, stream: Any = None, every: float = 5.0, description: str = "run") -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.every = every
        self.start = time.perf_counter()
        self.last_print = -math.inf
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.calls = 0
        self.last = ""
        self._bar: Progress | None = None
        self._task: TaskID | None = None
        self.description = description

    def line(self, t: float, t_end: float, steps: int, newton: int, rejected: int) -> str:
        """The plain progress line: percentage, simulated and wall time, ETA (wall time so far
        scaled by the remaining fraction of simulated time), steps and Newton iterations per step."""
        wall = time.perf_counter() - self.start
        frac = min(max(t / t_end, 0.0), 1.0) if t_end > 0 else 1.0
        eta = wall * (1.0 - frac) / frac if frac > 0 else math.inf
        eta_s = f"{eta:6.1f} s" if math.isfinite(eta) else "     ? s"
        return (
            f"{100 * frac:5.1f}% t = {t:.3f}/{t_end:g} s | wall {wall:6.1f} s | ETA {eta_s} | "
            f"{_stats(steps, newton, rejected)}"
        )

    def __call__(self, t: float, t_end: float, steps: int, newton: int, rejected: int) -> None:
        self.calls += 1
        self.last = self.line(t, t_end, steps, newton, rejected)
        done = t >= t_end * (1 - 1e-12)
        if self.tty:
            if self._bar is None:
                self._bar = Progress(
                    TextColumn("{task.description}"),
                    BarColumn(),
                    TextColumn("{task.percentage:5.1f}% t = {task.completed:.3f}/{task.total:g} s"),
                    TimeElapsedColumn(),
                    TextColumn("ETA"),
                    TimeRemainingColumn(),
                    TextColumn("{task.fields[stats]}"),
                    console=Console(file=self.stream),
                )
                self._bar.start()
                self._task = self._bar.add_task(self.description, total=t_end, stats="")
            assert self._task is not None
            self._bar.update(self._task, completed=min(t, t_end), stats=_stats(steps, newton, rejected))
            if done:
                self.close()
            return
        now = time.perf_counter()
        if done or now - self.last_print >= self.every:
            self.last_print = now
            print(self.last, file=self.stream, flush=True)

    def close(self) -> None:
        """Stops the terminal bar (the last state stays on screen); no effect otherwise."""
        if self._bar is not None:
            self._bar.stop()
            self._bar = None


def _stats(steps: int, newton: int, rejected: int) -> str:
    return f"{steps} steps ({rejected} rejected) | Newton {newton / max(steps, 1):.2f}/step"


@contextmanager
def callback(progress: ProgressArg, description: str = "run") -> Iterator[Callable[..., object] | None]:
    """The callback for a run's ``progress`` argument (``True``: a :class:`ProgressBar`), closed
    when the run ends, also when it fails."""
    if progress is True:
        bar = ProgressBar(description=description)
        try:
            yield bar
        finally:
            bar.close()
    elif progress is False or progress is None:
        yield None
    elif callable(progress):
        yield progress
    else:
        raise ValueError(f"invalid `progress` = {progress!r}: expected True, False, None or a callable")
