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
_ZERO = np.float32(0.0)


_ROUND = 1.5 * 2.0**52  # (q + c) - c rounds q to an integer (half to even)


def quantise_sum(values):
    """Samples as int64 multiples of ``1 / SUM_SCALE`` (round half to even), NaN -> 0."""
    values = np.asarray(values, np.float64)
    scaled = np.where(np.isfinite(values), values, 0.0) * SUM_SCALE
    return ((scaled + _ROUND) - _ROUND).astype(np.int64)


def split_square(values):
    """Squares of the samples as exact-summing ``(hi, lo)`` float64 parts, NaN -> 0."""
    values = np.asarray(values, np.float64)
    square = np.square(np.where(np.isfinite(values), values, 0.0))
    hi = (square + _SQ_HI) - _SQ_HI
    lo = ((square - hi) + _SQ_LO) - _SQ_LO
    return hi, lo


@nb.njit(cache=True, inline="always")
def _fixed(x):
    """float64 `x` -> int64 multiple of 1 / SUM_SCALE, as :func:`quantise_sum`."""
    return np.int64((x * SUM_SCALE + _ROUND) - _ROUND)


@nb.njit(cache=True, inline="always")
def _smooth_into(raw, smooth, p, slots, row, e, i, end):
    """Store the [1, 2, 1]/4 smoothing of pixel `p`'s frame `i` (ring slot ``slots[row, e]``).

    Neighbours outside ``[0, end)`` are replaced by frame `i` itself.
    """
    mid = raw[p, slots[row, e]]
    prev = raw[p, slots[row, e - 1]] if i >= 1 else mid
    nxt = raw[p, slots[row, e + 1]] if i + 1 < end else mid
    s = mid * _HALF
    s += _QUARTER * prev
    s += _QUARTER * nxt
    smooth[p, slots[row, e]] = s


@nb.njit(cache=True)
def _is_candidate(smooth, p, slots, row, centre, end, half_window, worst):
    """Whether frame `centre` of pixel `p` is a local minimum deeper than `worst`.

    `slots[row, e]` is the ring slot of frame ``centre - half_window - 1 + e``;
    the smoothed values of frames ``centre - half_window - 1 .. centre + half_window``
    must be in `smooth`. A local minimum is not larger than any smoothed value
    within ``half_window`` frames and, among the run of equal values around it
    (a flat minimum, seen within the window), is its middle frame (the later
    one of an even run). An equal value before the run, or a run reaching past
    the window's start, makes it no minimum (ties go to the earlier dip); a run
    longer than the window thus has one minimum, ``half_window`` frames after
    its first frame.
    """
    h = half_window
    s = smooth[p, slots[row, h + 1]]
    if not s < worst:  # also rejects NaN
        return False
    first = centre  # the run of values equal to s, within the window
    open_run = True
    for d in range(1, h + 1):
        if centre - d < 0:
            break
        v = smooth[p, slots[row, h + 1 - d]]
        if v < s:
            return False
        if v == s:
            if not open_run:
                return False
            first = centre - d
        else:
            open_run = False
    if open_run and first == centre - h and centre - h - 1 >= 0 and smooth[p, slots[row, 0]] == s:
        return False  # the run starts before the window: an earlier frame is its minimum
    last = centre
    open_run = True
    for d in range(1, h + 1):
        if centre + d >= end:
            break
        v = smooth[p, slots[row, h + 1 + d]]
        if v < s:
            return False
        if v == s and open_run:
            last = centre + d
        elif v != s:
            open_run = False
    return centre == (first + last + 1) // 2


@nb.njit(cache=True)
def _insert(raw, smooth, p, slots, row, centre, end, half_window, top_value, top_frame, window):
    """Insert local minimum `centre` into pixel `p`'s sorted list; copy its raw window if deepest."""
    h = half_window
    s = smooth[p, slots[row, h + 1]]
    pos = TOP - 1
    while pos > 0 and s < top_value[p, pos - 1]:
        top_value[p, pos] = top_value[p, pos - 1]
        top_frame[p, pos] = top_frame[p, pos - 1]
        pos -= 1
    top_value[p, pos] = s
    top_frame[p, pos] = centre
    if pos == 0:
        for q in range(2 * h + 1):
            f = centre - h + q
            window[p, q] = raw[p, slots[row, q + 1]] if 0 <= f < end else np.nan


@nb.njit(cache=True, inline="always")
def _consider(raw, smooth, p, slots, row, centre, end, half_window, top_value, top_frame, window):
    """Insert frame `centre` among pixel `p`'s deepest local minima if it is one."""
    if _is_candidate(smooth, p, slots, row, centre, end, half_window, top_value[p, TOP - 1]):
        _insert(raw, smooth, p, slots, row, centre, end, half_window, top_value, top_frame, window)


@nb.njit(cache=True)
def _slot_table(first_centre, n_centres, r):
    """Ring slots of frames ``centre - h - 1 .. centre + h + 1`` for consecutive centres."""
    table = np.empty((n_centres, r), np.int64)
    for t in range(n_centres):
        for e in range(r):
            table[t, e] = (first_centre + t - (r - 1) // 2 + e) % r
    return table


@nb.njit(cache=True, parallel=True)
def track_block(block, first_index, start, stop, half_window, saturation_level,
                raw, smooth, top_value, top_frame, window, signal_sum, square_hi, square_lo,
                count, invalid, channel_sum, saturated):
    """Feed frames ``first_index + t`` of `block` ``(T, P, C)`` float32 (C <= 3) to the state.

    The signal is the channel sum (float32, channels added in order). Sums,
    counts and saturation cover frames in ``[start, stop)`` only; centres in
    ``[start, stop)`` are tested once the frames up to ``centre + half_window + 1``
    are in the rings of raw and smoothed samples ``(P, 2 * half_window + 3)``.
    """
    n_t, n_p, n_c = block.shape
    r = raw.shape[1]
    # frame j = first_index + t is the last of centre j - h - 1's slots
    slots = _slot_table(first_index - half_window - 1, n_t, r)
    for p in nb.prange(n_p):
        total = signal_sum[p]
        hi_sum = square_hi[p]
        lo_sum = square_lo[p]
        n_ok = count[p]
        n_bad = invalid[p]
        sat = saturated[p]
        c0 = channel_sum[p, 0]
        c1 = channel_sum[p, 1] if n_c > 1 else 0
        c2 = channel_sum[p, 2] if n_c > 2 else 0
        for t in range(n_t):
            j = first_index + t
            v0 = block[t, p, 0]
            v1 = block[t, p, 1] if n_c > 1 else _ZERO
            v2 = block[t, p, 2] if n_c > 2 else _ZERO
            x = v0
            if n_c > 1:
                x += v1
            if n_c > 2:
                x += v2
            # non-finite samples (also -inf) never take part in the minimum search
            raw[p, slots[t, r - 1]] = x if np.isfinite(x) else np.float32(np.nan)
            if j >= 1:
                _smooth_into(raw, smooth, p, slots, t, r - 2, j - 1, j + 1)
            if start <= j < stop:
                if np.isfinite(x):
                    x64 = np.float64(x)
                    total += _fixed(x64)
                    sq = x64 * x64
                    hi = (sq + _SQ_HI) - _SQ_HI
                    hi_sum += hi
                    lo_sum += ((sq - hi) + _SQ_LO) - _SQ_LO
                    n_ok += 1
                else:
                    n_bad += 1
                if np.isfinite(v0):
                    c0 += _fixed(np.float64(v0))
                if np.isfinite(v1):
                    c1 += _fixed(np.float64(v1))
                if np.isfinite(v2):
                    c2 += _fixed(np.float64(v2))
                # +inf is corrupt input (counted above), not a clipped channel
                sat |= (((v0 >= saturation_level) & (v0 < np.inf)) | ((v1 >= saturation_level) & (v1 < np.inf))
                        | ((v2 >= saturation_level) & (v2 < np.inf)))
            centre = j - half_window - 1
            if centre >= start and centre >= 0 and centre < stop:
                _consider(raw, smooth, p, slots, t, centre, j + 1, half_window, top_value, top_frame,
                          window)
        signal_sum[p] = total
        square_hi[p] = hi_sum
        square_lo[p] = lo_sum
        count[p] = n_ok
        invalid[p] = n_bad
        saturated[p] = sat
        channel_sum[p, 0] = c0
        if n_c > 1:
            channel_sum[p, 1] = c1
        if n_c > 2:
            channel_sum[p, 2] = c2


@nb.njit(cache=True, parallel=True)
def finish_centres(first, last, end, half_window, raw, smooth, top_value, top_frame, window):
    """Test centres ``first .. last - 1`` of a sequence whose last frame is ``end - 1``.

    The last frame's smoothed value (its next neighbour replaced by itself)
    is computed first.
    """
    if end < 1:
        return
    r = raw.shape[1]
    # row 0: slots around centre end - h - 1, whose slot r - 2 is frame end - 1
    last_frame = _slot_table(end - half_window - 1, 1, r)
    slots = _slot_table(first, max(last - first, 0), r)
    for p in nb.prange(raw.shape[0]):
        _smooth_into(raw, smooth, p, last_frame, 0, r - 2, end - 1, end)
        for centre in range(first, last):
            _consider(raw, smooth, p, slots, centre - first, centre, end, half_window, top_value,
                      top_frame, window)
