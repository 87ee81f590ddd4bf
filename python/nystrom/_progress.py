"""Progress display for long integrations: tqdm when installed, else one line on stderr."""

import sys
import time


class _Line:
    """A progress line on stderr, redrawn at most 10 times a second."""

    def __init__(self, t0, t1):
        self.t0, self.t1 = t0, t1
        self.last = 0.0

    def update(self, t):
        now = time.monotonic()
        if now - self.last < 0.1:
            return
        self.last = now
        frac = (t - self.t0) / (self.t1 - self.t0)
        sys.stderr.write(f"\rnystrom: t = {t:.6g} of {self.t1:.6g} ({100 * frac:5.1f}%)")
        sys.stderr.flush()

    def close(self):
        sys.stderr.write(f"\rnystrom: t = {self.t1:.6g} of {self.t1:.6g} (100.0%)\n")
        sys.stderr.flush()


class _Tqdm:
    def __init__(self, tqdm, t0, t1):
        self.t0 = t0
        self.bar = tqdm(total=t1 - t0, unit="t", desc="nystrom")

    def update(self, t):
        self.bar.n = t - self.t0
        self.bar.refresh()

    def close(self):
        self.bar.close()


class _Callback:
    def __init__(self, fn):
        self.fn = fn

    def update(self, t):
        self.fn(t)

    def close(self):
        pass


def make_progress(progress, t0, t1):
    """None (no progress), or an object with update(t) and close()."""
    if progress is None or progress is False:
        return None
    if callable(progress):
        return _Callback(progress)
    if progress is True:
        try:
            from tqdm import tqdm
        except ImportError:
            return _Line(t0, t1)
        return _Tqdm(tqdm, t0, t1)
    raise TypeError("progress must be True, False or a callable progress(t)")
