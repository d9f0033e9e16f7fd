"""Streaming per-pixel tracking of the deepest intensity dip of a sweep.

A moving mask's shadow shows at a camera pixel as a short dip of its
intensity over time (paper section II-A). Finding it needs neither the whole
video nor its length in memory: frames are fed in time order, one block at a
time, and each pixel keeps only

* running sums of its signal (float64: exact over 10,000+ frames), from which
  the unshadowed level and the noise are computed with the dip removed;
* the window of ``2 * half_window + 1`` raw samples around the deepest point of
  its temporally smoothed signal, plus the depth and position of the deepest
  point that lies at least one window away from it (a second dip).

Memory is ``O(H * W * window)``, independent of the number of frames, and the
result equals that of a single pass over the whole sequence whatever the
block sizes (blocks are processed frame by frame inside).

Offers
------
DipTracker : the streaming accumulator (``update`` with frame blocks, then ``result``).
DipSummary : what the tracker hands to the timing methods (plain arrays).
"""

from dataclasses import dataclass

import numpy as np

#: temporal smoothing kernel used to locate minima (binomial [1, 2, 1] / 4)
_SMOOTHING = np.array([0.25, 0.5, 0.25], dtype=np.float32)


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
        Deepest smoothed value at least one window away from `minimum_frame`
        (``+inf`` when none).
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

    @property
    def half_window(self):
        """Half width of the stored window, in frames."""
        return (self.window.shape[0] - 1) // 2


class DipTracker:
    """Streaming tracker of each pixel's deepest dip.

    Parameters
    ----------
    shape : tuple of int
        ``(H, W)`` of the frames.
    half_window : int, optional
        Frames kept on each side of the minimum; the dip must fit in
        ``2 * half_window + 1`` frames for entry and exit to be seen.

    Examples
    --------
    >>> tracker = DipTracker((2, 3), half_window=2)
    >>> frames = np.ones((20, 2, 3), np.float32); frames[7] = 0.1
    >>> tracker.update(frames)
    >>> int(tracker.result().minimum_frame[0, 0])
    7
    """

    def __init__(self, shape, *, half_window=4):
        if len(shape) != 2 or min(shape) < 1:
            raise ValueError(f"shape must be (H, W) with positive sizes, got {shape!r}")
        if int(half_window) < 1:
            raise ValueError(f"half_window must be >= 1, got {half_window!r}")
        self.shape = tuple(int(s) for s in shape)
        self.half_window = int(half_window)
        k = 2 * self.half_window + 1
        h, w = self.shape
        # ring buffer of the last k raw frames (NaN = not yet seen)
        self._ring = np.full((k, h, w), np.nan, np.float32)
        self._window = np.full((k, h, w), np.nan, np.float32)
        self._min_value = np.full((h, w), np.inf, np.float32)
        self._min_frame = np.full((h, w), -1, np.int64)
        self._second_value = np.full((h, w), np.inf, np.float32)
        self._second_frame = np.full((h, w), -(k + 1), np.int64)
        self._sum = np.zeros((h, w), np.float64)
        self._sumsq = np.zeros((h, w), np.float64)
        self._count = np.zeros((h, w), np.int64)
        self._invalid = np.zeros((h, w), np.int64)
        self._n = 0
        self._finished = False
        self._scratch = np.empty((h, w), np.float32)
        self._mask = np.empty((h, w), bool)

    @property
    def n_frames(self):
        """Number of frames fed so far."""
        return self._n

    def update(self, block):
        """Feed the next frames.

        Parameters
        ----------
        block : (T, H, W) or (H, W) array_like
            Scalar signal of the next frames, in time order. Non-finite
            samples are counted and ignored.
        """
        block = np.asarray(block, dtype=np.float32)
        if block.ndim == 2:
            block = block[None]
        if block.ndim != 3 or block.shape[1:] != self.shape:
            raise ValueError(
                f"block must have shape (T, {self.shape[0]}, {self.shape[1]}), got {block.shape}"
            )
        for frame in block:
            self._push(frame)

    def _push(self, frame):
        if self._finished:
            raise ValueError("update() called after result(); start a new DipTracker")
        k = self._ring.shape[0]
        finite = np.isfinite(frame)
        clean = np.where(finite, frame, 0.0)
        self._sum += clean
        self._sumsq += np.square(clean, dtype=np.float64)
        self._count += finite
        self._invalid += ~finite

        self._ring[self._n % k] = frame
        self._n += 1
        centre = self._n - 1 - self.half_window  # newest frame whose window is complete
        if centre >= 0:
            self._consider(centre)

    def _consider(self, centre):
        """Test frame `centre` as the minimum; its window must be in the ring.

        Neighbours outside the sequence are replaced by the centre itself in
        the smoothing, and by NaN in the stored window.
        """
        k = self._ring.shape[0]
        h = self.half_window
        mid = self._ring[centre % k]
        prev = self._ring[(centre - 1) % k] if centre >= 1 else mid
        nxt = self._ring[(centre + 1) % k] if centre + 1 < self._n else mid
        smoothed = self._scratch
        np.multiply(mid, _SMOOTHING[1], out=smoothed)
        smoothed += _SMOOTHING[0] * prev
        smoothed += _SMOOTHING[2] * nxt

        better = self._mask
        np.less(smoothed, self._min_value, out=better)
        far_from_min = (centre - self._min_frame) >= k
        # a deeper minimum a window away: the old one becomes the second dip
        demote = better & far_from_min
        # a deeper minimum close to the second dip absorbs it (same dip)
        absorb = better & ((centre - self._second_frame) < k)
        self._second_value[absorb] = np.inf
        self._second_frame[absorb] = -(k + 1)
        take = demote & (self._min_value < self._second_value)
        self._second_value[take] = self._min_value[take]
        self._second_frame[take] = self._min_frame[take]
        # a shallower dip a window away from the minimum is a second-dip candidate
        second = ~better & far_from_min & (smoothed < self._second_value)
        self._second_value[second] = smoothed[second]
        self._second_frame[second] = centre
        if not better.any():
            return
        self._min_value[better] = smoothed[better]
        self._min_frame[better] = centre
        for j in range(k):
            frame_index = centre - h + j
            if 0 <= frame_index < self._n:
                self._window[j][better] = self._ring[frame_index % k][better]
            else:
                self._window[j][better] = np.nan

    def result(self):
        """Finish the sweep and return its :class:`DipSummary`.

        The last ``half_window`` frames, whose windows run past the end of the
        sequence, are tested too. The tracker cannot be updated afterwards.
        """
        if not self._finished:
            for centre in range(max(self._n - self.half_window, 0), self._n):
                self._consider(centre)
            self._finished = True
        return self._summary()

    def _summary(self):
        k = self._window.shape[0]
        h = self.half_window
        win = self._window
        win_finite = np.isfinite(win)
        win_sum = np.where(win_finite, win, 0).sum(axis=0, dtype=np.float64)
        win_sumsq = np.square(np.where(win_finite, win, 0), dtype=np.float64).sum(axis=0)
        win_count = win_finite.sum(axis=0)
        found = self._min_frame >= 0
        lit_count = self._count - np.where(found, win_count, 0)
        lit_sum = self._sum - np.where(found, win_sum, 0)
        lit_sumsq = self._sumsq - np.where(found, win_sumsq, 0)
        with np.errstate(invalid="ignore", divide="ignore"):
            lit_level = np.where(lit_count > 0, lit_sum / lit_count, np.nan)
            variance = lit_sumsq / lit_count - lit_level**2
            # unbiased, and never negative from round-off
            variance = np.maximum(variance, 0) * lit_count / np.maximum(lit_count - 1, 1)
            mean_level = np.where(self._count > 0, self._sum / self._count, np.nan)
        return DipSummary(
            window=win.copy(),
            window_start=np.where(found, self._min_frame - h, 0),
            minimum_frame=self._min_frame.copy(),
            minimum_value=self._min_value.copy(),
            second_value=self._second_value.copy(),
            second_frame=self._second_frame.copy(),
            lit_level=lit_level,
            noise=np.sqrt(variance),
            lit_count=lit_count,
            mean_level=mean_level,
            invalid_count=self._invalid.copy(),
            n_frames=self._n,
        )
