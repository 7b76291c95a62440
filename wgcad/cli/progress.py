"""A progress bar on stderr (fraction, elapsed time, ETA) that follows any ``progress(done, total, stage)`` sequence."""

from __future__ import annotations

import math
import sys
import time

__all__ = ["Progress", "format_seconds"]


def format_seconds(s: float) -> str:
    """``7s``, ``1m05s``, ``2h03m``: short, for the ETA."""
    s = max(0, int(round(s)))
    if s < 60:
        return f"{s}s"
    if s < 3600:
        return f"{s // 60}m{s % 60:02d}s"
    return f"{s // 3600}h{(s % 3600) // 60:02d}m"


class Progress:
    """One-line progress bar with fraction and ETA on a stream (stderr by default).

    Callable as the engines' ``progress(done, total, stage)`` callback. The
    bar is robust to whatever it is given: totals that change, ``done`` past
    ``total``, a zero, negative or non-finite total, non-numbers (then only
    the stage moves); the shown fraction never goes backwards. Work is split
    into spans (:meth:`span`) so that several phases (reading the design,
    the audit, writing files) fill one bar from 0 to 100 %. Redraws are
    limited to ``1 / min_interval_s`` per second.

    Parameters
    ----------
    enabled : bool
        False: every call does nothing (the usual case when stderr is not a
        terminal).
    stream : file, optional
        Default ``sys.stderr``.
    clock : callable, optional
        Seconds, monotonic (tests pass a fake clock).
    min_interval_s : float
        Smallest time between two redraws.

    Examples
    --------
    >>> import io
    >>> buf = io.StringIO()
    >>> bar = Progress(True, stream=buf, clock=iter(range(100)).__next__, min_interval_s=0)
    >>> bar.start("reading")
    >>> bar(1, 4, "audit")
    >>> round(bar.fraction, 2)
    0.25
    """

    WIDTH = 24

    def __init__(self, enabled: bool, stream=None, clock=time.monotonic, min_interval_s: float = 0.1):
        self.enabled = bool(enabled)
        self.stream = stream if stream is not None else sys.stderr
        self.clock = clock
        self.min_interval_s = float(min_interval_s)
        self.fraction = 0.0
        self.stage = ""
        self._lo, self._hi = 0.0, 1.0
        self._t0 = None
        self._ref = None  # (time, fraction) of the first move: the ETA's rate leaves out the start-up
        self._last_draw = -math.inf
        self._width_drawn = 0
        self._interactive = bool(getattr(self.stream, "isatty", lambda: False)())

    # -- feeding -----------------------------------------------------------
    def start(self, stage: str = "starting") -> None:
        """Show the bar at 0 % at once (a bar that appears only at the end tells nothing)."""
        if not self.enabled:
            return
        self._t0 = self.clock()
        self.stage = str(stage)
        self._draw(force=True)

    def span(self, lo: float, hi: float, stage: str | None = None) -> Progress:
        """Map the following ``(done, total)`` calls onto ``[lo, hi]`` of the whole bar; returns self."""
        self._lo, self._hi = float(lo), float(hi)
        self.set(self._lo, stage)
        return self

    def set(self, fraction: float, stage: str | None = None) -> None:
        """Move the whole bar to ``fraction`` (0..1) of the work (never backwards)."""
        if not self.enabled:
            return
        try:
            f = float(fraction)
        except (TypeError, ValueError):
            f = math.nan
        if math.isfinite(f):
            f = min(1.0, max(0.0, f))
            if f > self.fraction and self._ref is None:
                self._ref = (self.clock(), f)
            self.fraction = max(self.fraction, f)
        if stage is not None:
            self.stage = str(stage)
        self._draw(force=self.fraction >= 1.0)

    def __call__(self, done, total, stage=None) -> None:
        """The engines' callback: ``done`` of ``total`` units of the current span."""
        if not self.enabled:
            return
        try:
            f = float(done) / float(total)
        except (TypeError, ValueError, ZeroDivisionError, OverflowError):
            f = math.nan
        if math.isfinite(f):
            f = min(1.0, max(0.0, f))
            self.set(self._lo + (self._hi - self._lo) * f, stage)
        else:
            self.set(math.nan, stage)

    def close(self) -> None:
        """Erase the bar on a terminal (the summary follows on a clean line); end the line otherwise."""
        if not self.enabled or self._width_drawn == 0:
            return
        try:
            if self._interactive:
                self.stream.write("\r" + " " * self._width_drawn + "\r")
            else:
                self.stream.write("\n")
            self.stream.flush()
        except (OSError, ValueError):
            pass
        self._width_drawn = 0

    # -- drawing -----------------------------------------------------------
    def line(self) -> str:
        """The bar as text: ``[#####.......]  42 %  3.1s  ETA 4s  clearance``."""
        now = self.clock()
        elapsed = 0.0 if self._t0 is None else max(0.0, now - self._t0)
        n = int(self.WIDTH * self.fraction)
        eta = "ETA --"
        if self.fraction >= 1.0:
            eta = "done"
        elif self._ref is not None:
            # rate measured from the first move on (imports and reading the design are not work done)
            t_ref, f_ref = self._ref
            df, dt = self.fraction - f_ref, now - t_ref
            if df >= 0.01 and dt >= 0.5:
                eta = "ETA " + format_seconds(dt * (1.0 - self.fraction) / df)
        # at the end the ETA column says "done": a stage also named "done" is not said twice
        stage = "" if (self.fraction >= 1.0 and self.stage == "done") else self.stage
        return f"[{'#' * n}{'.' * (self.WIDTH - n)}] {100 * self.fraction:3.0f} %  {elapsed:5.1f}s  {eta:<10s} {stage}".rstrip()

    def _draw(self, force: bool = False) -> None:
        now = self.clock()
        if not force and now - self._last_draw < self.min_interval_s:
            return
        self._last_draw = now
        text = self.line()
        pad = max(0, self._width_drawn - len(text))
        try:
            self.stream.write("\r" + text + " " * pad)
            self.stream.flush()
        except (OSError, ValueError):
            self.enabled = False  # a closed or full stderr must not stop the run
            return
        self._width_drawn = len(text)
