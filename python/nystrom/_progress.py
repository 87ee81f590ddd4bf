"""Progress display for long integrations: tqdm when installed, else one line on stderr."""

import sys
import time


class _Line:
    """A progress line on stderr, redrawn at most 10 times a second."""

    def __init__(self, t0, t1):
        self.t0, self.t1 = t0, t1
        self.t = t0  # the last time reported
        self.drawn = 0.0

    def _draw(self, t, end=""):
        frac = (t - self.t0) / (self.t1 - self.t0)
        sys.stderr.write(f"\rnystrom: t = {t:.6g} of {self.t1:.6g} ({100 * frac:5.1f}%){end}")
        sys.stderr.flush()

    def update(self, t):
        self.t = t
        now = time.monotonic()
        if now - self.drawn < 0.1:
            return
        self.drawn = now
        self._draw(t)

    def close(self, t=None):
        self._draw(self.t1 if t is None else t, "\n")


class _Tqdm:
    def __init__(self, tqdm, t0, t1):
        self.t0 = self.t = t0
        self.bar = tqdm(total=t1 - t0, unit="t", desc="nystrom")

    def update(self, t):
        self.t = t
        self.bar.n = t - self.t0
        self.bar.refresh()

    def close(self, t=None):
        if t is not None:
            self.bar.n = t - self.t0
            self.bar.refresh()
        self.bar.close()


class _Callback:
    def __init__(self, fn, t0):
        self.fn = fn
        self.t = t0

    def update(self, t):
        self.t = t
        self.fn(t)

    def close(self, t=None):
        pass


def make_progress(progress, t0, t1):
    """None (no progress), or an object with update(t), close(t=None) and t, the last time reported.
    close() ends the display at t1 (a complete run); close(t) at t, where the run actually stopped (an
    interruption, a terminal event, a failure)."""
    if progress is None or progress is False:
        return None
    if callable(progress):
        return _Callback(progress, t0)
    if progress is True:
        try:
            from tqdm import tqdm
        except ImportError:
            return _Line(t0, t1)
        return _Tqdm(tqdm, t0, t1)
    raise TypeError("progress must be True, False or a callable progress(t)")


def counted_progress(progress):
    """``(update, close)`` for a run that reports how many of its ``total`` units (steps, paths) are done:
    ``(None, None)`` without progress; a callable ``progress(done, total)`` is called as it is; True draws a
    progress display, opened at the first report. ``close(done)`` ends the display at the units the run
    took; ``close(None)`` (an interrupted run) at the last count reported, never at the total."""
    if progress is None or progress is False:
        return None, None
    if callable(progress):
        return progress, None
    if progress is True:
        bar = None

        def update(done, total):
            nonlocal bar
            if bar is None:
                bar = make_progress(True, 0, total)
            bar.update(done)

        def close(done):
            if bar is not None:
                bar.close(bar.t if done is None else done)

        return update, close
    raise TypeError("progress must be True, False or a callable progress(done, total)")
