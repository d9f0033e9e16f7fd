"""Compiled per-pixel kernels of the streaming dip tracker (numba).

The tracker's state is laid out pixel-major (``(P, ...)`` with ``P = H * W``)
so that one pixel's state is contiguous; a block of frames is processed pixel
by pixel with time innermost, so the state is read and written once per block
and every frame sample is read once. Pixels run in parallel (``prange``).

Running sums are kept in forms whose addition is exact, hence independent of
the order and grouping of the frames (what makes time chunks merge bit for
bit):

* sums of the signal and of each channel: int64 fixed point, each sample
  rounded to a multiple of ``2**-32`` (exact while ``|sum| < 2**31``);
* sum of squares: each float64 square split into a part on a ``2**-8`` grid
  and a part on a ``2**-40`` grid, summed separately (exact while the sum is
  below ``2**45`` and for up to ``2**22`` frames); the remainder, under
  ``2**-41`` per sample, is dropped.

Offers
------
TOP : number of candidate minima kept per pixel.
SUM_SCALE : fixed-point scale of the integer sums (``2**32``).
quantise_sum : float samples -> int64 fixed point (numpy, same rounding as the kernel).
split_square : float samples -> (hi, lo) float64 parts of their squares (numpy).
track_block : feed a block of frames to the state (in place).
finish_centres : test the last centres of a sequence that ended.
"""

import numba as nb
import numpy as np

#: candidate local minima kept per pixel (at most 4 fit within a window of the deepest)
TOP = 5
#: fixed-point scale of the integer running sums
SUM_SCALE = 2.0**32
_SQ_HI = 1.5 * 2.0**44  # (q + c) - c rounds q to a multiple of 2**-8
_SQ_LO = 1.5 * 2.0**12  # ... and to a multiple of 2**-40
_HALF = np.float32(0.5)
_QUARTER = np.float32(0.25)


def quantise_sum(values):
    """Samples as int64 multiples of ``1 / SUM_SCALE`` (round half to even), NaN -> 0."""
    values = np.asarray(values, np.float64)
    return np.rint(np.where(np.isfinite(values), values, 0.0) * SUM_SCALE).astype(np.int64)


def split_square(values):
    """Squares of the samples as exact-summing ``(hi, lo)`` float64 parts, NaN -> 0."""
    values = np.asarray(values, np.float64)
    square = np.square(np.where(np.isfinite(values), values, 0.0))
    hi = (square + _SQ_HI) - _SQ_HI
    lo = ((square - hi) + _SQ_LO) - _SQ_LO
    return hi, lo


@nb.njit(cache=True, inline="always")
def _smoothed(ring, i, end):
    """[1, 2, 1]/4 smoothing at frame `i`; neighbours outside [0, end) replaced by frame i."""
    r = ring.shape[0]
    mid = ring[i % r]
    prev = ring[(i - 1) % r] if i >= 1 else mid
    nxt = ring[(i + 1) % r] if i + 1 < end else mid
    s = mid * _HALF
    s += _QUARTER * prev
    s += _QUARTER * nxt
    return s


@nb.njit(cache=True)
def _consider(ring, centre, end, half_window, top_value, top_frame, window):
    """Insert frame `centre` among the pixel's deepest local minima if it is one.

    A local minimum is smaller than every smoothed value in the ``half_window``
    frames before it and not larger than those after it (ties go to the
    earlier frame). When it becomes the deepest, its raw window is copied.
    """
    s = _smoothed(ring, centre, end)
    if not s < top_value[TOP - 1]:  # also rejects NaN
        return
    lo = max(centre - half_window, 0)
    hi = min(centre + half_window, end - 1)
    for i in range(lo, hi + 1):
        if i < centre:
            if _smoothed(ring, i, end) <= s:
                return
        elif i > centre:
            if _smoothed(ring, i, end) < s:
                return
    pos = TOP - 1
    while pos > 0 and s < top_value[pos - 1]:
        top_value[pos] = top_value[pos - 1]
        top_frame[pos] = top_frame[pos - 1]
        pos -= 1
    top_value[pos] = s
    top_frame[pos] = centre
    if pos == 0:
        r = ring.shape[0]
        for q in range(window.shape[0]):
            f = centre - half_window + q
            window[q] = ring[f % r] if 0 <= f < end else np.nan


@nb.njit(cache=True, parallel=True)
def track_block(block, first_index, start, stop, half_window, saturation_level,
                ring, top_value, top_frame, window, signal_sum, square_hi, square_lo,
                count, invalid, channel_sum, saturated):
    """Feed frames ``first_index + t`` of `block` ``(T, P, C)`` float32 to the state.

    The signal is the channel sum (float32, channels added in order). Sums,
    counts and saturation cover frames in ``[start, stop)`` only; centres in
    ``[start, stop)`` are tested once the frames up to ``centre + half_window + 1``
    are in the ring ``(P, 2 * half_window + 3)``.
    """
    n_t, n_p, n_c = block.shape
    r = ring.shape[1]
    for p in nb.prange(n_p):
        ring_p = ring[p]
        for t in range(n_t):
            j = first_index + t
            x = block[t, p, 0]
            for c in range(1, n_c):
                x += block[t, p, c]
            ring_p[j % r] = x
            if start <= j < stop:
                if np.isfinite(x):
                    x64 = np.float64(x)
                    signal_sum[p] += np.int64(np.rint(x64 * SUM_SCALE))
                    sq = x64 * x64
                    hi = (sq + _SQ_HI) - _SQ_HI
                    square_hi[p] += hi
                    square_lo[p] += ((sq - hi) + _SQ_LO) - _SQ_LO
                    count[p] += 1
                else:
                    invalid[p] += 1
                for c in range(n_c):
                    v = block[t, p, c]
                    if np.isfinite(v):
                        channel_sum[p, c] += np.int64(np.rint(np.float64(v) * SUM_SCALE))
                        # +inf is corrupt input (counted above), not a clipped channel
                        if v >= saturation_level:
                            saturated[p] = True
            centre = j - half_window - 1
            if centre >= start and centre >= 0 and centre < stop:
                _consider(ring_p, centre, j + 1, half_window, top_value[p], top_frame[p], window[p])


@nb.njit(cache=True, parallel=True)
def finish_centres(first, last, end, half_window, ring, top_value, top_frame, window):
    """Test centres ``first .. last - 1`` of a sequence whose last frame is ``end - 1``."""
    for p in nb.prange(ring.shape[0]):
        for centre in range(first, last):
            _consider(ring[p], centre, end, half_window, top_value[p], top_frame[p], window[p])
