"""Streaming per-pixel tracking of the deepest intensity dip of a sweep.

A moving mask's shadow shows at a camera pixel as a short dip of its
intensity over time (paper section II-A). Finding it needs neither the whole
video nor its length in memory: frames are fed in time order, one block at a
time, and each pixel keeps only

* exact running sums of its signal, its square and each channel (see
  :mod:`shadowcam.lab.dip_kernels`), from which the unshadowed level and the
  noise are computed with the dip removed;
* its deepest local minima of the temporally [1, 2, 1]-smoothed signal (a
  local minimum is not above any smoothed value within ``half_window``
  frames and is the middle of a flat minimum; ties between separate dips go
  to the earlier one; non-finite samples take no part), and the raw window of
  ``2 * half_window + 1`` samples around the deepest one.

The deepest minimum is the deepest smoothed value of the sweep; the second
dip is the deepest other local minimum (more than ``half_window`` frames
away from it: a second dip inside the window is seen too). Memory is ``O(H * W * window)``, independent of the
number of frames.

Time chunks: a tracker built with ``owned=(start, stop)`` is fed the frames
``[max(0, start - pad), min(n, stop + pad))`` (``pad = DipTracker.padding(h)``)
and contributes the centres and sums of frames ``[start, stop)`` only; its
:meth:`DipTracker.partial` is a :class:`DipPartial` (plain arrays, saved
atomically to ``.npz``), and :func:`merge_partials` of the chunks of a sweep
equals the single-pass :meth:`DipTracker.result` bit for bit, whatever the
chunking and block sizes (the sums are exact, the minima are a selection).

Offers
------
DipTracker : the streaming accumulator (``update`` with frame blocks, then ``result`` or ``partial``).
DipSummary : what the tracker hands to the timing methods (plain arrays).
DipPartial : the state of one time chunk (``save`` / ``load``).
merge_partials : the summary of a sweep from its time chunks.
IntervalTracker : second pass: each pixel's dip interval (entry and exit crossings), whatever its width.
DipInterval : entry, exit and their slopes per pixel; ``at(fraction)`` across the interval.
IntervalPartial, merge_intervals : the interval of a sweep from its time chunks.
half_depth : the default crossing level.
without_interval : the summary's lit statistics without the whole dip, and the crossings at its half depth.
lit_without : the lit level, noise and count with some lit samples taken out.
window_intervals : the interval of the pixels whose crossings lie in their stored window.
lit_colour : unshadowed colour per pixel from a summary with channel sums.
track_intervals : the interval of every pixel: from the window, else a pass over the sweep's frames.
"""

from dataclasses import dataclass, fields

import numpy as np

from shadowcam.lab import dip_kernels as _k


@dataclass
class DipSummary:
    """Per-pixel statistics of one sweep, enough to time and classify the dip.

    Attributes
    ----------
    window : (K, H, W) float32 ndarray
        Raw signal around the deepest smoothed minimum; ``window[k]`` is frame
        ``window_start + k``. Frames outside the sequence are NaN.
    window_start : (H, W) int64 ndarray
        Frame index of ``window[0]``.
    minimum_frame : (H, W) int64 ndarray
        Frame of the deepest smoothed minimum (-1 where no valid frame).
    minimum_value : (H, W) float32 ndarray
        Smoothed signal at `minimum_frame`.
    second_value : (H, W) float32 ndarray
        Deepest other smoothed local minimum (more than ``half_window``
        frames from `minimum_frame`) (``+inf`` when none).
    second_frame : (H, W) int64 ndarray
        Frame of `second_value` (negative when none).
    lit_level : (H, W) float64 ndarray
        Mean signal over the valid frames outside the window (unshadowed level).
    noise : (H, W) float64 ndarray
        Standard deviation of those frames (temporal noise).
    lit_count : (H, W) int64 ndarray
        Number of frames behind `lit_level`.
    mean_level : (H, W) float64 ndarray
        Mean signal over all valid frames.
    invalid_count : (H, W) int64 ndarray
        Number of non-finite samples seen.
    n_frames : int
        Frames seen.
    channel_sum : (H, W, C) float64 ndarray or None
        Sum over all frames of each channel (non-finite samples as 0), when
        the tracker was fed ``(T, H, W, C)`` blocks.
    saturated : (H, W) bool ndarray or None
        Whether any channel reached the saturation level in any frame.
    site : SiteWindow or None
        Demosaiced RAW: each pixel's own mosaic site in the window
        (:func:`shadowcam.lab.site_signal.track_site_window`), from which ``edge_fit``
        times it where its noise allows; None: timed from the tracked signal.
    tracked_site : SiteWindow or None
        RAW tracked with ``own_site`` (:class:`DipTracker`): each site's own value at the
        window's frames and its lit statistics (and its neighbours' part's) over the
        frames outside the window, from exact running sums (``colour`` None: the
        timing gives it, :func:`shadowcam.lab.site_signal.tracked_site_window`).
    """

    window: np.ndarray
    window_start: np.ndarray
    minimum_frame: np.ndarray
    minimum_value: np.ndarray
    second_value: np.ndarray
    second_frame: np.ndarray
    lit_level: np.ndarray
    noise: np.ndarray
    lit_count: np.ndarray
    mean_level: np.ndarray
    invalid_count: np.ndarray
    n_frames: int
    channel_sum: np.ndarray = None
    saturated: np.ndarray = None
    site: object = None
    tracked_site: object = None

    @property
    def half_window(self):
        """Half width of the stored window, in frames."""
        return (self.window.shape[0] - 1) // 2


@dataclass
class DipPartial:
    """State of a :class:`DipTracker` over its owned frames (one time chunk).

    Arrays are pixel-major; ``TOP`` = :data:`shadowcam.lab.dip_kernels.TOP`,
    ``K = 2 * half_window + 1``.

    Attributes
    ----------
    start, stop : int
        Owned frames ``[start, stop)`` (`stop` clipped to the frames fed).
    end : int
        One past the last frame fed.
    half_window : int
    top_value : (H, W, TOP) float32 ndarray
        Deepest smoothed local minima with centre in ``[start, stop)``, ascending
        (``+inf`` = empty slot).
    top_frame : (H, W, TOP) int64 ndarray
        Their frames (-1 = empty).
    window : (H, W, K) float32 ndarray
        Raw samples around ``top_frame[..., 0]``.
    signal_sum : (H, W) int64 ndarray
        Fixed-point sum (units ``2**-32``) of the finite signal samples.
    square_hi, square_lo : (H, W) float64 ndarray
        Exact-summing parts of the sum of squares.
    count, invalid : (H, W) int64 ndarray
        Finite and non-finite signal samples.
    channel_sum : (H, W, C) int64 ndarray
        Fixed-point per-channel sums (C = 0 if fed scalar frames).
    saturated : (H, W) bool ndarray
    own_window : (H, W, K) float32 ndarray or None
        Tracked with ``own_site``: each RAW site's own value at the frames of `window`.
    own_sums : (H, W, 7) int64 ndarray or None
        Count of the finite own values of the owned frames; their fixed-point sum and
        square parts (``2**-8`` and ``2**-40`` units); the same of the neighbours' part
        (signal less own) (:func:`shadowcam.lab.dip_kernels.own_site_block`).
    own_rest_invalid : (H, W) int64 ndarray or None
        Owned frames with a finite own value and a non-finite neighbours' part.
    """

    start: int
    stop: int
    end: int
    half_window: int
    top_value: np.ndarray
    top_frame: np.ndarray
    window: np.ndarray
    signal_sum: np.ndarray
    square_hi: np.ndarray
    square_lo: np.ndarray
    count: np.ndarray
    invalid: np.ndarray
    channel_sum: np.ndarray
    saturated: np.ndarray
    own_window: np.ndarray = None
    own_sums: np.ndarray = None
    own_rest_invalid: np.ndarray = None

    def save(self, path):
        """Write to `path` (ending ``.npz``) atomically: a temporary file, then a rename."""
        from shadowcam._shared.atomic import atomic_path

        with atomic_path(path) as tmp:
            np.savez(tmp, **{f.name: getattr(self, f.name) for f in fields(self) if getattr(self, f.name) is not None})

    @classmethod
    def load(cls, path):
        """Read a partial written by :meth:`save`."""
        with np.load(path) as data:
            missing = {f.name for f in fields(cls) if f.name not in _OWN_SITE_FIELDS} - set(data.files)
            if missing:
                raise ValueError(f"path {path} is not a DipPartial file: missing {sorted(missing)}")
            values = {f.name: data[f.name] for f in fields(cls) if f.name in data.files}
        for name in ("start", "stop", "end", "half_window"):
            values[name] = int(values[name])
        return cls(**values)


_OWN_SITE_FIELDS = ("own_window", "own_sums", "own_rest_invalid")


class DipTracker:
    """Streaming tracker of each pixel's deepest dip.

    Parameters
    ----------
    shape : tuple of int
        ``(H, W)`` of the frames.
    half_window : int, optional
        Frames kept on each side of the minimum; the dip must fit in
        ``2 * half_window + 1`` frames for entry and exit to be seen.
    owned : (int, int), optional
        Time chunk ``(start, stop)`` this tracker contributes; feed it frames
        ``[max(0, start - pad), min(n, stop + pad))`` with
        ``pad = DipTracker.padding(half_window)`` and take :meth:`partial`.
        Default: the whole sequence.
    saturation_level : float, optional
        Channel value at or above which a pixel counts as saturated.
    own_site : bool, optional
        RAW: :meth:`update` also takes each site's own value of the frames, kept at
        the window's frames beside the signal (the frames whose signal the window
        holds) and in exact running sums with its neighbours' part, so that the
        summary carries ``tracked_site`` (no second pass over the frames for it).

    Examples
    --------
    >>> tracker = DipTracker((2, 3), half_window=2)
    >>> frames = np.ones((20, 2, 3), np.float32); frames[7] = 0.1
    >>> tracker.update(frames)
    >>> int(tracker.result().minimum_frame[0, 0])
    7
    """

    def __init__(self, shape, *, half_window=4, owned=None, saturation_level=0.999, own_site=False):
        if len(shape) != 2 or min(shape) < 1:
            raise ValueError(f"shape must be (H, W) with positive sizes; got {shape!r}")
        if int(half_window) < 1:
            raise ValueError(f"half_window must be >= 1; got {half_window!r}")
        start, stop = (0, np.iinfo(np.int64).max) if owned is None else (int(owned[0]), int(owned[1]))
        if not 0 <= start < stop:
            raise ValueError(f"owned must be (start, stop) with 0 <= start < stop; got {owned!r}")
        self.shape = tuple(int(s) for s in shape)
        self.half_window = h = int(half_window)
        self.owned = (start, stop)
        self.saturation_level = float(saturation_level)
        k = 2 * h + 1
        p = self.shape[0] * self.shape[1]
        self._first = max(0, start - self.padding(h))
        self._next = self._first
        # pixel-minor state (see dip_kernels.track_block)
        self._raw = np.full((k + 2, p), np.nan, np.float32)
        self._smooth = np.full((k + 2, p), np.nan, np.float32)
        self._top_value = np.full((_k.TOP, p), np.inf, np.float32)
        self._top_frame = np.full((_k.TOP, p), -1, np.int64)
        self._window = np.full((k, p), np.nan, np.float32)
        self._signal_sum = np.zeros(p, np.int64)
        self._square_hi = np.zeros(p, np.float64)
        self._square_lo = np.zeros(p, np.float64)
        self._count = np.zeros(p, np.int64)
        self._invalid = np.zeros(p, np.int64)
        self._channel_sum = None
        self._saturated = np.zeros(p, bool)
        self._partial = None
        self.own_site = bool(own_site)
        if self.own_site:
            self._own_window = np.full((k, p), np.nan, np.float32)
            # own values of the last K frames fed: a window copied in the next block may start there
            self._own_tail = np.full((k, p), np.nan, np.float32)
            self._own_sums = np.zeros((7, p), np.int64)
            self._own_rest_invalid = np.zeros(p, np.int64)

    @staticmethod
    def padding(half_window):
        """Frames needed on each side of an owned time chunk: ``half_window + 2``.

        A centre's test reads the smoothed values from ``half_window + 1`` frames
        before it (one raw frame more) to ``half_window`` after it (one more).
        """
        return int(half_window) + 2

    @property
    def n_frames(self):
        """One past the last frame fed so far (the frames seen, for a whole sweep)."""
        return self._next

    def update(self, block, *, first_index=None, own=None):
        """Feed the next frames.

        Parameters
        ----------
        block : (T, H, W), (H, W) or (T, H, W, C) array_like
            Signal of the next frames, in time order; with channels, the
            signal is their sum and per-channel sums and saturation are kept
            too. Non-finite samples are counted and ignored.
        first_index : int, optional
            Frame index of ``block[0]``; blocks must follow each other without
            gaps. Default: the next frame.
        own : (T, H, W) array_like, optional
            Each RAW site's own value in these frames; required with ``own_site``
            (and only then).
        """
        if self._partial is not None:
            raise ValueError("update() called after result()/partial(); start a new DipTracker")
        block = np.asarray(block, dtype=np.float32)
        if block.ndim == 2:
            block = block[None]
        if block.ndim == 3:
            block = block[..., None]
        if block.ndim != 4 or block.shape[1:3] != self.shape:
            raise ValueError(
                f"block must have shape (T, {self.shape[0]}, {self.shape[1]}[, C]), got {block.shape}"
            )
        first = self._next if first_index is None else int(first_index)
        if first != self._next:
            raise ValueError(
                f"first_index must be {self._next} (the frame after the last one fed, or "
                f"max(0, start - padding) at first), got {first}"
            )
        n_c = block.shape[3]
        if n_c > 3:
            raise ValueError(f"block must have at most 3 channels, got {n_c}")
        if self._channel_sum is None:
            self._channel_sum = np.zeros((n_c, self._raw.shape[1]), np.int64)
        elif self._channel_sum.shape[0] != n_c:
            raise ValueError(f"block has {n_c} channels but earlier blocks had {self._channel_sum.shape[0]}")
        if self.own_site != (own is not None):
            raise ValueError("own (each site's own value of the frames) must be given if and only if the "
                             f"tracker was built with own_site=True; own_site={self.own_site}")
        flat = np.ascontiguousarray(block).reshape(block.shape[0], -1, n_c)
        if own is not None:
            own = np.ascontiguousarray(own, np.float32)
            if own.shape != block.shape[:3]:
                raise ValueError(f"own must have shape {block.shape[:3]} (the block's frames), got {own.shape}")
            own = own.reshape(block.shape[0], -1)
            deepest = self._top_frame[0].copy()
        _k.track_block(flat, first, *self.owned, self.half_window, np.float32(self.saturation_level),
                       self._raw, self._smooth, self._top_value, self._top_frame, self._window, self._signal_sum,
                       self._square_hi, self._square_lo, self._count, self._invalid,
                       self._channel_sum, self._saturated)
        self._next = first + block.shape[0]
        if own is not None:
            _k.own_site_block(flat, own, first, *self.owned, self._own_sums, self._own_rest_invalid)
            self._copy_own_windows(deepest, own, first)
            k = self._own_tail.shape[0]
            if own.shape[0] >= k:
                self._own_tail[...] = own[-k:]
            else:
                self._own_tail = np.concatenate([self._own_tail[own.shape[0]:], own])

    def _copy_own_windows(self, deepest, own, first):
        """Give the pixels whose deepest centre moved from `deepest` the own values of its window.

        `own` ``(T, P)`` holds frames ``first ..``, the tail the ``K`` frames before.
        """
        changed = self._top_frame[0] != deepest
        _k.copy_own_windows(self._own_tail, own, first, self._top_frame[0], changed, self._next,
                            self.half_window, self._own_window)

    def partial(self):
        """Finish the owned chunk and return its :class:`DipPartial`.

        Centres whose window runs past the last frame fed are tested as the
        end of the sequence. The tracker cannot be updated afterwards.
        """
        if self._partial is None:
            start, stop = self.owned
            end = self._next
            first = max(end - self.half_window - 1, start)  # centres not yet tested
            deepest = self._top_frame[0].copy() if self.own_site else None
            _k.finish_centres(first, min(stop, end), end, self.half_window, self._raw, self._smooth,
                              self._top_value, self._top_frame, self._window)
            own = {}
            if self.own_site:
                self._copy_own_windows(deepest, self._own_tail[:0], end)
                h, w = self.shape
                own = dict(own_window=np.ascontiguousarray(self._own_window.T).reshape(h, w, -1),
                           own_sums=np.ascontiguousarray(self._own_sums.T).reshape(h, w, -1),
                           own_rest_invalid=self._own_rest_invalid.reshape(h, w))
            h, w = self.shape
            channels = self._channel_sum if self._channel_sum is not None else np.zeros((0, h * w), np.int64)

            def pixel_major(state):
                return np.ascontiguousarray(state.T).reshape(h, w, -1)

            self._partial = DipPartial(
                start=start, stop=max(min(stop, end), start), end=end, half_window=self.half_window,
                top_value=pixel_major(self._top_value), top_frame=pixel_major(self._top_frame),
                window=pixel_major(self._window), signal_sum=self._signal_sum.reshape(h, w),
                square_hi=self._square_hi.reshape(h, w), square_lo=self._square_lo.reshape(h, w),
                count=self._count.reshape(h, w), invalid=self._invalid.reshape(h, w),
                channel_sum=pixel_major(channels), saturated=self._saturated.reshape(h, w), **own,
            )
            self._raw = self._smooth = None
        return self._partial

    def result(self):
        """Finish the sweep and return its :class:`DipSummary` (the tracker must own it all)."""
        partial = self.partial()
        if partial.start != self._first:
            raise ValueError("result() needs a tracker owning the whole sweep; use partial() and merge_partials()")
        return merge_partials([partial], n_frames=partial.end)


def _check_tiling(partials, n_frames):
    """Raise ValueError unless the partials' owned chunks tile ``[0, n_frames)`` and were fed enough."""
    if not partials:
        raise ValueError("partials is empty: give the partials of every time chunk")
    ordered = sorted(partials, key=lambda part: part.start)
    expected = 0
    for part in ordered:
        if part.start != expected:
            raise ValueError(
                f"partials must tile frames [0, {n_frames}) without gaps or overlaps; "
                f"a chunk starts at {part.start} where {expected} was expected"
            )
        pad = DipTracker.padding(part.half_window)
        if part.end < min(n_frames, part.stop + pad):
            raise ValueError(
                f"the chunk owning [{part.start}, {part.stop}) was fed frames up to {part.end} only; "
                f"feed it up to min(n_frames, stop + {pad})"
            )
        expected = part.stop
    if expected != n_frames:
        raise ValueError(f"n_frames is {n_frames} but the partials cover frames [0, {expected})")
    if len({part.half_window for part in ordered}) != 1:
        raise ValueError("partials have different half_window values; track every chunk alike")
    if len({part.channel_sum.shape[2] for part in ordered}) != 1:
        raise ValueError("partials have different channel counts; feed every chunk alike")


def merge_partials(partials, *, n_frames):
    """The :class:`DipSummary` of a sweep from the partials of its time chunks.

    Parameters
    ----------
    partials : sequence of DipPartial
        One per chunk, in any order; their owned chunks must tile ``[0, n_frames)``.
    n_frames : int
        Frames of the sweep.

    Returns
    -------
    DipSummary
        Equal bit for bit to the single-pass :meth:`DipTracker.result`.
    """
    n_frames = int(n_frames)
    _check_tiling(partials, n_frames)
    h = partials[0].half_window
    k = 2 * h + 1
    shape = partials[0].top_value.shape[:2]

    def flat(name, width):
        return tuple(np.ascontiguousarray(getattr(p, name)).reshape(-1, width) for p in partials)

    merged = list(_k.merge_dips(flat("top_value", _k.TOP), flat("top_frame", _k.TOP), flat("window", k), h))
    chunk = merged.pop()
    tracked_site = None
    if all(p.own_window is not None for p in partials):
        tracked_site = _tracked_site(partials, merged[5], chunk, shape)
    window = merged.pop(5).reshape((k,) + shape)
    minimum_value, minimum_frame, second_value, second_frame, found, win_count, win_sum, win_hi, win_lo = (
        part.reshape(shape) for part in merged)

    def total(name):
        return sum(getattr(p, name) for p in partials)

    lit_count = total("count") - win_count
    lit_sum = (total("signal_sum") - win_sum) / _k.SUM_SCALE
    lit_sumsq = (total("square_hi") - win_hi) + (total("square_lo") - win_lo)
    count = total("count")
    with np.errstate(invalid="ignore", divide="ignore"):
        lit_level = np.where(lit_count > 0, lit_sum / lit_count, np.nan)
        variance = lit_sumsq / lit_count - lit_level**2
        # unbiased, and never negative from round-off
        variance = np.maximum(variance, 0) * lit_count / np.maximum(lit_count - 1, 1)
        mean_level = np.where(count > 0, total("signal_sum") / _k.SUM_SCALE / count, np.nan)
    channel_sum = total("channel_sum")
    saturated = np.logical_or.reduce([p.saturated for p in partials])
    return DipSummary(
        window=window,
        window_start=np.where(found, minimum_frame - h, 0),
        minimum_frame=minimum_frame.astype(np.int64),
        minimum_value=minimum_value.astype(np.float32),
        second_value=second_value.astype(np.float32),
        second_frame=second_frame.astype(np.int64),
        lit_level=lit_level,
        noise=np.sqrt(variance),
        lit_count=lit_count.astype(np.int64),
        mean_level=mean_level,
        invalid_count=total("invalid").astype(np.int64),
        n_frames=n_frames,
        channel_sum=channel_sum / _k.SUM_SCALE if channel_sum.shape[-1] else None,
        saturated=saturated,
        tracked_site=tracked_site,
    )


def _tracked_site(partials, window, chunk, shape):
    """The own-site :class:`~shadowcam.lab.site_signal.SiteWindow` (``colour`` None) of merged partials.

    Each pixel's own window is its deepest dip's chunk's (as the signal's `window`
    ``(K, P)``); its lit statistics are the chunks' running sums less the window's
    samples' (exact, so independent of the chunking).
    """
    from shadowcam.lab.site_signal import SiteWindow

    k, n_p = window.shape
    own_window = np.full((n_p, k), np.nan, np.float32)
    for index, part in enumerate(partials):
        take = chunk == index
        own_window[take] = part.own_window.reshape(n_p, k)[take]
    own_window = np.ascontiguousarray(own_window.T)
    in_window, window_invalid = _k.own_window_sums(own_window, window, chunk >= 0)
    sums = sum(np.ascontiguousarray(part.own_sums).reshape(n_p, 7).T for part in partials) - in_window
    rest_invalid = sum(part.own_rest_invalid.reshape(n_p) for part in partials) - window_invalid
    count = sums[0]
    level, noise = _level_noise(sums[1], sums[2], sums[3], count)
    rest_level, rest_noise = _level_noise(sums[4], sums[5], sums[6], count)
    rest_level[rest_invalid > 0] = np.nan
    rest_noise[rest_invalid > 0] = np.nan
    own_window[~np.isfinite(own_window)] = np.nan
    return SiteWindow(window=own_window.reshape((k,) + shape), level=level.reshape(shape),
                      noise=noise.reshape(shape), count=count.reshape(shape),
                      neighbour_level=rest_level.reshape(shape), neighbour_noise=rest_noise.reshape(shape),
                      colour=None)


def _level_noise(fixed_sum, square_hi, square_lo, count):
    """Mean and sample standard deviation from exact sums (units as :func:`~shadowcam.lab.dip_kernels.own_site_block`'s)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        level = np.where(count > 0, fixed_sum / _k.SUM_SCALE / count, np.nan)
        variance = (square_hi / 256.0 + square_lo / 2.0**40) / count - level**2
        variance = np.maximum(variance, 0) * count / np.maximum(count - 1, 1)
    return level, np.sqrt(variance)


@dataclass
class IntervalPartial:
    """Where one time chunk's smoothed signal is at or above each pixel's threshold around its dip.

    Attributes
    ----------
    start, stop : int
        Owned frames ``[start, stop)``.
    before_frame : (H, W) int64 ndarray
        Last owned frame before the pixel's centre at or above the threshold (-1 = none).
    before_values : (H, W, 2) float32 ndarray
        Smoothed values at `before_frame` and the frame after it.
    before_invalid : (H, W) int64 ndarray
        Owned frames with a non-finite smoothed value after `before_frame`
        (after `start` when there is none) and before the centre.
    after_frame : (H, W) int64 ndarray
        First owned frame after the centre at or above the threshold (-1 = none).
    after_values : (H, W, 2) float32 ndarray
        Smoothed values at the frame before `after_frame` and at it.
    after_invalid : (H, W) int64 ndarray
        Owned frames after the centre with a non-finite smoothed value before `after_frame`.
    before_sums, after_sums : (H, W, 4) int64 ndarray
        Count, fixed-point sum and square parts of the raw samples counted
        like `before_invalid` / `after_invalid` but more than ``half_window``
        frames from the centre (see :func:`shadowcam.lab.dip_kernels.interval_block`).
    """

    start: int
    stop: int
    before_frame: np.ndarray
    before_values: np.ndarray
    before_invalid: np.ndarray
    after_frame: np.ndarray
    after_values: np.ndarray
    after_invalid: np.ndarray
    before_sums: np.ndarray
    after_sums: np.ndarray


@dataclass
class DipInterval:
    """Each pixel's dip interval: where its smoothed signal stays below the threshold around its minimum.

    Times are in frames, sub-frame by linear interpolation of the smoothed
    signal between the last frame at or above the threshold and the next one
    (entry), and between the last one below and the first one at or above
    (exit). NaN where the interval reaches the sweep's start or end (no
    frame above the threshold on that side) or where the pixel has no dip.

    Attributes
    ----------
    entry, exit : (H, W) float64 ndarray
        Threshold crossings before and after the minimum.
    entry_open, exit_open : (H, W) bool ndarray
        The interval reaches the sweep's start (end): no frame above the threshold on that side.
    entry_slope, exit_slope : (H, W) float64 ndarray
        Change of the smoothed signal over the crossing frame (signal units
        per frame; positive), for the time uncertainty ``noise / slope``.
    invalid : (H, W) int64 ndarray
        Frames inside the interval with a non-finite smoothed value.
    threshold : (H, W) float64 ndarray
        The level the crossings were taken at.
    beyond_count, beyond_sum, beyond_square : (H, W) ndarray
        Count (int64), sum and sum of squares (float64) of the finite raw
        samples inside the interval but outside the tracker's window (the
        part of a wide dip that the :class:`DipSummary` counted as lit).
    """

    entry: np.ndarray
    exit: np.ndarray
    entry_open: np.ndarray
    exit_open: np.ndarray
    entry_slope: np.ndarray
    exit_slope: np.ndarray
    invalid: np.ndarray
    threshold: np.ndarray
    beyond_count: np.ndarray
    beyond_sum: np.ndarray
    beyond_square: np.ndarray

    def at(self, fraction):
        """Time at `fraction` across the interval (0 = entry, 0.5 = centre, 1 = exit), ``(H, W)``."""
        return self.entry + float(fraction) * (self.exit - self.entry)


class IntervalTracker:
    """Streaming measurement of each pixel's dip interval, whatever its width.

    The dip's frame and depth come from a first pass (a :class:`DipSummary`:
    its deepest smoothed minimum and lit level); this pass streams the frames
    again and keeps, per pixel, only the last frame before the minimum and
    the first one after it where the smoothed signal is at or above
    `threshold`, with the values either side of each crossing: O(1) state per
    pixel, independent of the frames and of the dip's width (a plateau of
    any length, penumbrae either side).

    Parameters
    ----------
    centre_frame : (H, W) int ndarray
        Frame of each pixel's deepest minimum (negative = no dip: skipped).
    half_window : int
        The dip tracker's: samples further than this from the centre inside the
        interval are summed (``beyond_*`` of :class:`DipInterval`).
    threshold : (H, W) float ndarray
        Level of the crossings (e.g. half depth, :func:`half_depth`).
    n_frames : int
        Frames of the sweep.
    owned : (int, int), optional
        Time chunk ``(start, stop)``; feed frames ``[max(0, start - 2), min(n_frames, stop + 2))``
        and take :meth:`partial`; :func:`merge_intervals` of the chunks equals the
        single-pass :meth:`result` bit for bit. Default: the whole sweep.
    """

    PAD = 2

    def __init__(self, centre_frame, threshold, *, half_window, n_frames, owned=None):
        centre_frame = np.asarray(centre_frame)
        threshold = np.asarray(threshold, np.float64)
        if centre_frame.ndim != 2 or threshold.shape != centre_frame.shape:
            raise ValueError(f"centre_frame and threshold must be (H, W) arrays of one shape; "
                             f"got {centre_frame.shape} and {threshold.shape}")
        n_frames = int(n_frames)
        if int(half_window) < 1:
            raise ValueError(f"half_window must be >= 1; got {half_window!r}")
        self.half_window = int(half_window)
        if n_frames < 1:
            raise ValueError(f"n_frames must be >= 1; got {n_frames}")
        start, stop = (0, n_frames) if owned is None else (int(owned[0]), min(int(owned[1]), n_frames))
        if not 0 <= start < stop:
            raise ValueError(f"owned must be (start, stop) with 0 <= start < stop <= n_frames; got {owned!r}")
        self.shape = centre_frame.shape
        self.n_frames = n_frames
        self.owned = (start, stop)
        p = centre_frame.size
        self._centre = np.where(np.isfinite(threshold), centre_frame, -1).astype(np.int64).ravel()
        # float32 comparison with the float32 smoothed signal
        self._threshold = threshold.astype(np.float32).ravel()
        self._first = max(0, start - self.PAD)
        self._next = self._first
        self._done = max(0, start - 1)  # next frame whose smoothed value is computed
        self._last = min(n_frames, stop + 1)  # one past the last one
        self._carry = np.empty((0, p), np.float32)
        self._state = dict(
            before_frame=np.full(p, -1, np.int64), before_values=np.full((p, 2), np.nan, np.float32),
            before_invalid=np.zeros(p, np.int64), after_frame=np.full(p, -1, np.int64),
            after_values=np.full((p, 2), np.nan, np.float32), after_invalid=np.zeros(p, np.int64),
            before_sums=np.zeros((p, 4), np.int64), after_sums=np.zeros((p, 4), np.int64))
        self._previous = np.full(p, np.nan, np.float32)
        self._wants_next = np.zeros(p, bool)

    def update(self, block):
        """Feed the next frames, ``(T, H, W)`` signal or ``(T, H, W, C)`` channels (summed)."""
        block = np.asarray(block, np.float32)
        if block.ndim == 4:
            # the channel sum in order, as the dip tracker forms it
            signal = block[..., 0].copy()
            for c in range(1, block.shape[3]):
                signal += block[..., c]
            block = signal
        if block.ndim != 3 or block.shape[1:] != self.shape:
            raise ValueError(f"block must have shape (T, {self.shape[0]}, {self.shape[1]}[, C]), "
                             f"got {block.shape}")
        # non-finite samples stay as they are: the kernel counts them (never above nor below)
        block = block.reshape(block.shape[0], -1)
        ext = np.concatenate([self._carry, block])
        ext_first = self._next - self._carry.shape[0]
        self._next += block.shape[0]
        if self._next > self.n_frames:
            raise ValueError(f"more frames fed than n_frames={self.n_frames}")
        # frame j is computable once j + 1 is in (or j is the sweep's last frame)
        upto = min(self._last, self._next - 1 if self._next < self.n_frames else self._next)
        if upto > self._done:
            s = self._state
            _k.interval_block(ext, ext_first, self._done, upto, *self.owned, self.n_frames, self._centre,
                              self._threshold, self.half_window, s["before_frame"], s["before_values"],
                              s["before_invalid"], s["after_frame"], s["after_values"], s["after_invalid"],
                              s["before_sums"], s["after_sums"], self._previous, self._wants_next)
            self._done = upto
        self._carry = ext[-2:]

    def partial(self):
        """The :class:`IntervalPartial` of the owned chunk (all its frames must have been fed)."""
        if self._done < self._last:
            raise ValueError(f"frames up to {min(self.n_frames, self.owned[1] + self.PAD)} must be fed "
                             f"before partial(); fed up to {self._next}")
        h, w = self.shape
        s = {k: v.reshape((h, w) + v.shape[1:]) for k, v in self._state.items()}
        return IntervalPartial(start=self.owned[0], stop=self.owned[1], **s)

    def result(self):
        """The :class:`DipInterval` of the whole sweep (the tracker must own it all)."""
        if self.owned != (0, self.n_frames):
            raise ValueError("result() needs a tracker owning the whole sweep; use partial() and merge_intervals()")
        return merge_intervals([self.partial()], n_frames=self.n_frames,
                               threshold=self._threshold.reshape(self.shape))


def half_depth(summary):
    """Threshold halfway between each pixel's lit level and its smoothed minimum, ``(H, W)``."""
    return 0.5 * (summary.lit_level + summary.minimum_value.astype(np.float64))


def merge_intervals(partials, *, n_frames, threshold):
    """The :class:`DipInterval` of a sweep from the :class:`IntervalPartial` of its time chunks.

    Parameters
    ----------
    partials : sequence of IntervalPartial
        One per chunk, in any order, tiling ``[0, n_frames)``.
    n_frames : int
    threshold : (H, W) array_like
        The threshold the chunks were tracked with.

    Returns
    -------
    DipInterval
        Equal bit for bit to the single-pass :meth:`IntervalTracker.result`.
    """
    if not partials:
        raise ValueError("partials is empty: give the partials of every time chunk")
    ordered = sorted(partials, key=lambda part: part.start)
    expected = 0
    for part in ordered:
        if part.start != expected:
            raise ValueError(f"partials must tile frames [0, {n_frames}) without gaps or overlaps; "
                             f"a chunk starts at {part.start} where {expected} was expected")
        expected = part.stop
    if expected != int(n_frames):
        raise ValueError(f"n_frames is {n_frames} but the partials cover frames [0, {expected})")
    shape = ordered[0].before_frame.shape
    before = np.full(shape, -1, np.int64)
    before_values = np.full(shape + (2,), np.nan, np.float32)
    before_invalid = np.zeros(shape, np.int64)
    before_sums = np.zeros(shape + (4,), np.int64)
    for part in ordered:  # in time order: a later frame above resets the counts
        found = part.before_frame >= 0
        before = np.where(found, part.before_frame, before)
        before_values = np.where(found[..., None], part.before_values, before_values)
        before_invalid = np.where(found, part.before_invalid, before_invalid + part.before_invalid)
        before_sums = np.where(found[..., None], part.before_sums, before_sums + part.before_sums)
    after = np.full(shape, -1, np.int64)
    after_values = np.full(shape + (2,), np.nan, np.float32)
    after_invalid = np.zeros(shape, np.int64)
    after_sums = np.zeros(shape + (4,), np.int64)
    for part in ordered:
        open_ = after < 0
        after_invalid = np.where(open_, after_invalid + part.after_invalid, after_invalid)
        after_sums = np.where(open_[..., None], after_sums + part.after_sums, after_sums)
        take = open_ & (part.after_frame >= 0)
        after = np.where(take, part.after_frame, after)
        after_values = np.where(take[..., None], part.after_values, after_values)
    threshold = np.asarray(threshold, np.float32).astype(np.float64)
    b0, b1 = (before_values[..., i].astype(np.float64) for i in (0, 1))
    a0, a1 = (after_values[..., i].astype(np.float64) for i in (0, 1))
    with np.errstate(invalid="ignore", divide="ignore"):
        entry_slope = b0 - b1
        exit_slope = a1 - a0
        entry = np.where(before >= 0, before + (b0 - threshold) / entry_slope, np.nan)
        exit_ = np.where(after >= 0, after - 1 + (threshold - a0) / exit_slope, np.nan)
    # a crossing next to a non-finite value has no sub-frame position
    entry = np.where(np.isfinite(b1), entry, np.nan)
    exit_ = np.where(np.isfinite(a0), exit_, np.nan)
    sums = before_sums + after_sums
    return DipInterval(entry=entry, exit=exit_, entry_open=before < 0, exit_open=after < 0,
                       entry_slope=entry_slope, exit_slope=exit_slope,
                       invalid=before_invalid + after_invalid, threshold=threshold,
                       beyond_count=sums[..., 0], beyond_sum=sums[..., 1] / _k.SUM_SCALE,
                       beyond_square=sums[..., 2] / 256.0 + sums[..., 3] / 2.0**40)


def window_intervals(summary, threshold):
    """The whole-sweep :class:`IntervalPartial` of the pixels whose crossings lie in their window.

    Parameters
    ----------
    summary : DipSummary
    threshold : (H, W) array_like

    Returns
    -------
    partial : IntervalPartial
        Over ``[0, summary.n_frames)``; equal to the interval pass's for the
        resolved pixels (see :func:`shadowcam.lab.dip_kernels.interval_from_window`).
    resolved : (H, W) bool ndarray
        Pixels that need no pass over the frames.
    """
    threshold = np.asarray(threshold, np.float64)
    shape = summary.minimum_frame.shape
    if threshold.shape != shape:
        raise ValueError(f"threshold must have the summary's shape {shape}, got {threshold.shape}")
    p = summary.minimum_frame.size
    centre = np.where(np.isfinite(threshold), summary.minimum_frame, -1).astype(np.int64).ravel()
    before_frame, after_frame = np.full(p, -1, np.int64), np.full(p, -1, np.int64)
    before_values, after_values = np.full((p, 2), np.nan, np.float32), np.full((p, 2), np.nan, np.float32)
    resolved = np.zeros(p, bool)
    _k.interval_from_window(np.ascontiguousarray(summary.window, np.float32).reshape(summary.window.shape[0], -1),
                            centre, threshold.astype(np.float32).ravel(), int(summary.n_frames),
                            before_frame, before_values, after_frame, after_values, resolved)
    zeros = np.zeros(shape, np.int64)
    partial = IntervalPartial(start=0, stop=int(summary.n_frames), before_frame=before_frame.reshape(shape),
                              before_values=before_values.reshape(shape + (2,)), before_invalid=zeros,
                              after_frame=after_frame.reshape(shape), after_values=after_values.reshape(shape + (2,)),
                              after_invalid=zeros.copy(), before_sums=np.zeros(shape + (4,), np.int64),
                              after_sums=np.zeros(shape + (4,), np.int64))
    return partial, resolved.reshape(shape)


def track_intervals(blocks, summary, *, threshold=None, measure=None):
    """The dip interval of every pixel of `summary`: from its window, else by a second pass over the frames.

    Pixels whose crossings lie in the stored window (:func:`window_intervals`)
    need no frame; only if some pixel is left are the frames read again
    (`blocks` iterated: a lazy iterable, e.g. a generator reading the frames,
    then costs nothing) and that pixel measured by an :class:`IntervalTracker`.
    The result equals the tracker's over all pixels bit for bit.

    Parameters
    ----------
    blocks : iterable of (T, H, W[, C]) ndarray
        The same frames as fed to the :class:`DipTracker`, in time order
        (unused with `measure`).
    summary : DipSummary
    threshold : (H, W) ndarray, optional
        Default :func:`half_depth`.
    measure : callable, optional
        ``measure(centre_frame, threshold)`` -> the :class:`IntervalPartial` of
        every time chunk of an :class:`IntervalTracker` with these arguments
        (``threshold`` NaN for the pixels already measured), e.g. chunks
        tracked in parallel; replaces the pass over `blocks`.

    Returns
    -------
    DipInterval
    """
    threshold = half_depth(summary) if threshold is None else np.asarray(threshold, np.float64)
    partial, resolved = window_intervals(summary, threshold)
    interval = merge_intervals([partial], n_frames=summary.n_frames, threshold=threshold)
    if resolved.all():
        return interval
    left = np.where(resolved, np.nan, threshold)
    if measure is None:
        tracker = IntervalTracker(summary.minimum_frame, left, half_window=summary.half_window,
                                  n_frames=summary.n_frames)
        for block in blocks:
            tracker.update(block)
        parts = [tracker.partial()]
    else:
        parts = measure(summary.minimum_frame, left)
    rest = merge_intervals(parts, n_frames=summary.n_frames, threshold=threshold)
    # merge_intervals works pixel by pixel: each pixel's result from its own partial
    return DipInterval(**{f.name: np.where(resolved, getattr(interval, f.name), getattr(rest, f.name))
                          for f in fields(DipInterval)})


def _ramp_deficit(level, minimum, crossing, slope, first, last):
    """Light missing from the frames ``first..last`` of a straight penumbra ramp above half depth.

    The ramp reaches half depth ``(level + minimum) / 2`` at `crossing` with `slope`
    (signal per frame, positive) and the lit level ``R = (level - minimum) / (2 slope)``
    frames further out; a frame ``j`` of it lacks ``slope * (R - |j - crossing|)``.
    `first` and `last` bound the frames on the ramp's lit side of the crossing (in any
    order). Returns the sum over the integer frames within both (0 where none).
    """
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        reach = 0.5 * (level - minimum) / slope
        lo = np.maximum(np.minimum(first, last), np.ceil(crossing - reach))
        hi = np.minimum(np.maximum(first, last), np.floor(crossing + reach))
        count = hi - lo + 1
        # sum of |j - crossing| over j in lo..hi, all on one side of the crossing
        distance = np.abs(0.5 * (lo + hi) - crossing) * count
        deficit = slope * (reach * count - distance)
    return np.where(np.isfinite(deficit) & (count > 0) & (slope > 0), deficit, 0.0)


def _without_ramps(lit_level, lit_count, summary, interval, *, iterations=8):
    """Lit level with the penumbra frames above half depth (outside the window) taken out.

    The frames between the lit level and the half-depth crossing on each side of a dip
    wider than the tracker's window count as lit in its running sums although the light
    is partly hidden there. The lit level is the unoccluded irradiance: the counted mean
    plus the light those ramp frames lack, on a straight ramp through each crossing with
    its measured slope (:func:`_ramp_deficit`), solved with the level it depends on by
    fixed-point iteration (the ramp frames are a fraction of the counted ones, so it
    contracts). Pixels with no ramp frame outside the window keep `lit_level` exactly.
    """
    centre = summary.minimum_frame.astype(np.float64)
    h, n_frames = summary.half_window, summary.n_frames
    minimum = summary.minimum_value.astype(np.float64)
    count = np.maximum(lit_count, 1).astype(np.float64)
    level = lit_level
    for _ in range(iterations):
        deficit = (_ramp_deficit(level, minimum, interval.entry, interval.entry_slope,
                                 np.zeros_like(centre), np.minimum(np.floor(interval.entry), centre - h - 1))
                   + _ramp_deficit(level, minimum, interval.exit, interval.exit_slope,
                                   np.maximum(np.ceil(interval.exit), centre + h + 1), np.full_like(centre, n_frames - 1)))
        level = np.where(deficit > 0, lit_level + deficit / count, lit_level)
    return level


def lit_without(summary, count, total, square):
    """The lit level, noise and count of `summary` with some of its lit samples taken out.

    Parameters
    ----------
    summary : DipSummary
    count : (H, W) int ndarray
        Samples taken out of each pixel's lit ones.
    total, square : (H, W) float ndarray
        Their sum and sum of squares.

    Returns
    -------
    lit_level, noise : (H, W) float64 ndarray
    lit_count : (H, W) int64 ndarray
    changed : (H, W) bool ndarray
        Pixels with samples taken out and at least 3 left; the others keep their values.
    """
    n = summary.lit_count.astype(np.float64)
    k = np.asarray(count).astype(np.float64)
    level, noise = summary.lit_level, summary.noise
    with np.errstate(invalid="ignore", divide="ignore"):
        lit_sum = level * n - total
        variance = noise**2 * np.maximum(n - 1, 1) / n
        lit_square = (variance + level**2) * n - square
        new_level = lit_sum / (n - k)
        new_variance = np.maximum(lit_square / (n - k) - new_level**2, 0) * (n - k) / np.maximum(n - k - 1, 1)
    changed = (k > 0) & (n - k >= 3)
    lit_level = np.where(changed, new_level, level)
    lit_count = np.where(changed, summary.lit_count - count, summary.lit_count)
    return lit_level, np.where(changed, np.sqrt(new_variance), noise), lit_count, changed


def without_interval(summary, interval):
    """The lit statistics of `summary` with the whole dip interval taken out, and the crossings moved to match.

    The tracker's lit level and noise count the frames of a dip wider than
    its window as lit (lower level, higher noise). This removes those frames
    (``beyond_*`` of `interval`) from the running sums, adds back the light the
    penumbra frames above half depth outside the window lack (a straight ramp
    through each crossing with its measured slope, :func:`_without_ramps`; only
    where the dip runs beyond the window), and
    moves each crossing along its local slope to the half depth of the corrected
    level (first order; exact on a linear penumbra). Pixels with nothing beyond
    the window keep their values bit for bit.

    Returns
    -------
    summary : DipSummary
        With `lit_level`, `noise` and `lit_count` corrected.
    interval : DipInterval
        With `entry`, `exit` and `threshold` corrected.
    """
    from dataclasses import replace

    lit_level, new_noise, lit_count, changed = lit_without(
        summary, interval.beyond_count, interval.beyond_sum, interval.beyond_square)
    # only a dip that runs beyond the window has its ramps' frames counted as lit to first
    # order; a narrower one's ramp beyond the window is at most a noisy frame's worth
    ramp_level = np.where(changed, _without_ramps(lit_level, lit_count, summary, interval), lit_level)
    new_summary = replace(summary, lit_level=ramp_level, noise=new_noise, lit_count=lit_count)
    threshold = np.where(changed, half_depth(new_summary), interval.threshold)
    shift = threshold - interval.threshold
    with np.errstate(invalid="ignore", divide="ignore"):
        entry = np.where(changed, interval.entry - shift / interval.entry_slope, interval.entry)
        exit_ = np.where(changed, interval.exit + shift / interval.exit_slope, interval.exit)
    return new_summary, replace(interval, entry=entry, exit=exit_, threshold=threshold)


def lit_colour(summary):
    """Unshadowed colour per pixel, ``(H, W, C)`` float32.

    The channel means scaled by the ratio of the lit level to the mean level
    (the mask removes light from all channels alike).
    """
    if summary.channel_sum is None:
        raise ValueError("summary has no channel sums: feed the tracker (T, H, W, C) blocks")
    with np.errstate(invalid="ignore", divide="ignore"):
        # a pixel with no light at all (mean 0) has no colour, not an infinite one
        scale = np.where(summary.mean_level > 0, summary.lit_level / summary.mean_level, 0.0)
        lit_image = summary.channel_sum / summary.n_frames * scale[..., None]
    return np.nan_to_num(lit_image, nan=0.0).astype(np.float32)
