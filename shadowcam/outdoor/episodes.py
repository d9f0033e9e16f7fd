"""Dark episodes of every pixel, streamed: the final shadow and the transient ones before it.

A pixel's lit fraction (coverage) drops below 0.5 when a shadow covers it. The ridge
shadow at sunset stays: once a point is behind the ridge it remains there (except where the
geometry relights it, a sunlit tongue through a saddle). A cloud shadow passes: the pixel
relights when the cloud has drifted on. So the shadow-arrival candidate of a pixel is the
start of its **final** dark episode, one never followed by a sustained relighting; earlier
dark episodes are kept as events (start, end, depth) for the arrival step to explain
(:func:`shadowcam.outdoor.arrival.arrival_map`: a relit tongue or a transient shadow).

A change of state (lit -> dark or dark -> lit at level 0.5) counts when it lasts into the
next frame, or, lasting one frame only, when at least two of the pixel's four neighbours
make the same change in the same frame (a short shadow seen by a patch of pixels, not the
noise of one); a change in the last frame is kept. Its time is the level crossing, linear
in time between the two frames around it.

State is a few ``(H, W)`` arrays and ``max_events`` slots per pixel, so memory does not
depend on the number of frames; every step is per pixel but the neighbour count (one
pixel each side), so column strips with a halo give the same result as whole frames.

Offers
------
ShadowEpisodes : the streaming pass; :meth:`update` per frame, :meth:`result`.
"""

import numpy as np

from shadowcam._shared.validation import check_positive


def _neighbours_agree(change):
    """Pixels with at least two of their 4-neighbours also in `change`."""
    count = np.zeros(change.shape, dtype=np.int8)
    count[1:] += change[:-1]
    count[:-1] += change[1:]
    count[:, 1:] += change[:, :-1]
    count[:, :-1] += change[:, 1:]
    return change & (count >= 2)


class ShadowEpisodes:
    """Streaming dark episodes of the per-pixel coverage.

    Parameters
    ----------
    shape : tuple of int
        ``(H, W)``.
    eligible : (H, W) bool ndarray
        Pixels that may receive an arrival (lit at start, not sky); those whose coverage
        is below `level` in the first frame are dropped (shadowed from the start: no
        arrival, even if they are lit and shadowed again later).
    level : float, keyword-only
        Coverage below which the pixel is dark (0.5 = half the footprint shadowed).
    max_events : int, keyword-only
        Closed episodes kept per pixel (the first ones; :attr:`n_events` counts all).

    Notes
    -----
    Feed frames in time order with :meth:`update`; read :meth:`result`.
    """

    def __init__(self, shape, *, eligible, level=0.5, max_events=2):
        shape = tuple(int(n) for n in shape)
        self.eligible = np.asarray(eligible, dtype=bool)
        if self.eligible.shape != shape:
            raise ValueError(f"eligible {self.eligible.shape} must have shape {shape}")
        check_positive(level, "level")
        if int(max_events) < 1:
            raise ValueError(f"max_events must be >= 1; got {max_events}")
        self.level = float(level)
        self.dark = np.zeros(shape, dtype=bool)  # accepted state
        # times are float32 (1 ms resolution up to ~2 h after the first frame)
        self.start = np.full(shape, np.nan, dtype=np.float32)  # start of the current dark episode (NaN: lit)
        self._sum = np.zeros(shape, dtype=np.float32)  # coverage summed over the current episode
        self._count = np.zeros(shape, dtype=np.int32)  # frames of the current episode
        self._pending = np.zeros(shape, dtype=bool)  # a one-frame change waiting for the next frame
        self._pending_t = np.full(shape, np.nan, dtype=np.float32)
        self._pending_cover = np.zeros(shape, dtype=np.float32)
        self.event_start = np.full((*shape, int(max_events)), np.nan, dtype=np.float32)
        self.event_end = np.full((*shape, int(max_events)), np.nan, dtype=np.float32)
        self.event_depth = np.full((*shape, int(max_events)), np.nan, dtype=np.float32)
        self.n_events = np.zeros(shape, dtype=np.int16)
        self._previous = None
        self._time = None

    def _crossing_time(self, previous, cover, where, time_s):
        prev = previous[where].astype(np.float64)
        curr = cover[where].astype(np.float64)
        frac = (prev - self.level) / np.where(prev != curr, prev - curr, 1.0)
        return self._time + np.clip(frac, 0.0, 1.0) * (time_s - self._time)

    def _accept(self, change, times, cover_sum, cover_count):
        """Switch the state of `change` pixels at `times` (their crossing times); an episode
        that starts holds `cover_sum` over `cover_count` frames so far."""
        to_dark = change & ~self.dark
        to_lit = change & self.dark
        # closing: an episode that had a start (not dark since frame 0)
        close = to_lit & np.isfinite(self.start)
        if close.any():
            slot = self.n_events[close]
            keep = slot < self.event_start.shape[-1]
            r, c = np.nonzero(close)
            r, c, slot = r[keep], c[keep], slot[keep].astype(np.intp)
            self.event_start[r, c, slot] = self.start[r, c]
            self.event_end[r, c, slot] = times[r, c]
            mean = self._sum[r, c] / np.maximum(self._count[r, c], 1)
            self.event_depth[r, c, slot] = np.clip(1.0 - mean, 0.0, 1.0)
            self.n_events[close] += 1
        self.start[to_lit] = np.nan
        self.start[to_dark] = times[to_dark]
        self._sum[to_dark] = cover_sum[to_dark]
        self._count[to_dark] = cover_count
        self.dark ^= change

    def update(self, cover, time_s):
        """Add the coverage ``(H, W)`` of the next frame, taken at `time_s` seconds."""
        cover = np.asarray(cover)
        if cover.shape != self.dark.shape:
            raise ValueError(f"cover {cover.shape} must have shape {self.dark.shape}")
        if self._previous is None:
            with np.errstate(invalid="ignore"):
                # shadowed in the first frame: no arrival, whatever comes later
                self.eligible = self.eligible & (cover >= self.level)
            self._previous, self._time = cover.copy(), float(time_s)
            return
        if time_s <= self._time:
            raise ValueError(f"time_s must increase: got {time_s} after {self._time}")
        with np.errstate(invalid="ignore"):
            known = np.isfinite(cover)
            raw_dark = np.where(known, cover < self.level, self.dark ^ self._pending)
        value = np.where(known, cover, np.float32(0.0)).astype(np.float32)
        # a change pending from the previous frame is confirmed when it lasts into this one
        confirmed = self._pending & (raw_dark != self.dark)
        if confirmed.any():
            pend_sum = self._pending_cover + value
            self._accept(confirmed, self._pending_t, pend_sum, 2)
        self._pending[:] = False
        change = (raw_dark != self.dark) & self.eligible
        # the dark episode accumulates its coverage (a frame that may end it does not count)
        in_dark = self.dark & ~confirmed & ~change & known
        self._sum[in_dark] += value[in_dark]
        self._count[in_dark] += 1
        # changes in this frame
        if change.any():
            times = np.full(cover.shape, np.nan, dtype=np.float32)
            times[change] = self._crossing_time(self._previous, cover, change, time_s)
            agree = _neighbours_agree(change & raw_dark) | _neighbours_agree(change & ~raw_dark)
            if agree.any():
                self._accept(agree, times, value, 1)
            wait = change & ~agree
            self._pending[wait] = True
            self._pending_t[wait] = times[wait]
            self._pending_cover[wait] = value[wait]
        self._previous, self._time = cover.copy(), float(time_s)

    def result(self):
        """The episodes, after the last frame (a change pending in it is kept; no copies).

        Returns
        -------
        dict
            ``final_start_s (H, W)``: start of the final dark episode (NaN: lit at the
            end, or not eligible) and ``final_depth (H, W)`` (1 - its mean coverage);
            ``event_start_s``, ``event_end_s``, ``event_depth`` ``(H, W, max_events)``: the
            closed (relit) episodes in time order, depth = 1 - their mean coverage;
            ``n_events (H, W)``: how many there were.
        """
        # in the last frame a change is kept: to dark starts the final episode, to lit ends it
        pending = self._pending
        if pending.any():
            self._accept(pending, self._pending_t, self._pending_cover, 1)
            pending[:] = False
        start = self.start
        final_depth = np.full(start.shape, np.nan, dtype=np.float32)
        open_ = np.isfinite(start) & (self._count > 0)
        final_depth[open_] = np.clip(1.0 - self._sum[open_] / self._count[open_], 0.0, 1.0)
        return {"final_start_s": start, "final_depth": final_depth, "event_start_s": self.event_start,
                "event_end_s": self.event_end, "event_depth": self.event_depth, "n_events": self.n_events}
