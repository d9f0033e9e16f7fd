"""Progress of a long loop: items done, rate and time left, as log lines.

The command line logs to stderr, so a step run by hand shows its progress in
the terminal and a step run by the workflow in its log file.

Offers
------
Progress : count items and log ``<what>: 120/1000 frames, 35.2 frames/s, 25 s left``.
format_duration : seconds as ``42 s``, ``3 min 20 s`` or ``1 h 05 min``.
"""

import logging
import math
import time

log = logging.getLogger(__name__)


def format_duration(seconds):
    """Return `seconds` (>= 0) as ``42 s``, ``3 min 20 s`` or ``1 h 05 min``."""
    seconds = int(math.ceil(seconds))
    if seconds < 60:
        return f"{seconds} s"
    if seconds < 3600:
        return f"{seconds // 60} min {seconds % 60:02d} s"
    return f"{seconds // 3600} h {seconds % 3600 // 60:02d} min"


class Progress:
    """Log how far a loop of `total` items got, at most every `every_s` seconds and at the end.

    Parameters
    ----------
    total : int
        Number of items the loop will do (> 0).
    what : str
        What the loop does, the start of each line (e.g. ``"decode u"``).
    unit : str, keyword-only
        Name of the items, plural (default ``"frames"``).
    every_s : float, keyword-only
        Least time between two lines, seconds (default 5); the last item is always reported.
    logger : logging.Logger, keyword-only
        Where the lines go (default this module's logger).
    clock : callable, keyword-only
        Returns the time in seconds (default :func:`time.monotonic`, looked up at each call).

    Examples
    --------
    >>> progress = Progress(3, "decode u", every_s=0)
    >>> for k in range(3):
    ...     progress.update(k + 1)
    """

    def __init__(self, total, what, *, unit="frames", every_s=5.0, logger=None, clock=None):
        if int(total) != total or total < 1:
            raise ValueError(f"total must be a positive integer; got {total!r}")
        if not every_s >= 0:
            raise ValueError(f"every_s must be >= 0; got {every_s!r}")
        self.total, self.what, self.unit = int(total), what, unit
        self.every_s, self.logger = float(every_s), logger or log
        self.clock = clock or (lambda: time.monotonic())
        self.started = self.last = self.clock()

    def update(self, done):
        """Record that `done` items (of `total`) are finished; log a line when one is due."""
        now = self.clock()
        if done < self.total and now - self.last < self.every_s:
            return
        self.last = now
        elapsed = max(now - self.started, 1e-9)
        rate = done / elapsed
        left = (self.total - done) / rate if rate > 0 else math.inf
        tail = "done in " + format_duration(elapsed) if done >= self.total else (
            format_duration(left) + " left" if math.isfinite(left) else "time left unknown")
        self.logger.info("%s: %d/%d %s, %.3g %s/s, %s", self.what, done, self.total, self.unit, rate,
                         self.unit, tail)
