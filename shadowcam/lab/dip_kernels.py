"""Compiled per-pixel kernels of the streaming dip tracker (numba).

The tracker's state is laid out pixel-minor (``(..., P)`` with ``P = H * W``);
a block of frames is processed in tiles of pixels, frames in order within a
tile and pixels innermost (vectorised), so that a tile's rings and state stay
in cache while the block streams through and every frame sample is read once.
Tiles run in parallel (``prange``).

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
split_square : float samples -> (hi, lo) float64 parts of their squares (numpy, as the kernels).
track_block : feed a block of frames to the state (in place).
finish_centres : test the last centres of a sequence that ended.
window_sums : the exact sums of stored windows (to take the dip out of the running sums).
merge_dips : the deepest and second dip of each pixel among its chunks' candidates, with its window and sums.
own_site_block, own_window_sums, copy_own_windows : RAW sites' own values beside the channel sum (window and sums).
interval_block : compare smoothed frames with a threshold around each pixel's deepest minimum (the dip's interval).
interval_from_window : the same for pixels whose crossings lie in their stored window (no pass over the frames).
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
def _smooth_frame(raw, smooth, p, i, end):
    """Store the [1, 2, 1]/4 smoothing of pixel `p`'s frame `i` (ring slot ``i % r``).

    Neighbours outside ``[0, end)`` are replaced by frame `i` itself.
    """
    r = raw.shape[0]
    mid = raw[i % r, p]
    prev = raw[(i - 1) % r, p] if i >= 1 else mid
    nxt = raw[(i + 1) % r, p] if i + 1 < end else mid
    s = mid * _HALF
    s += _QUARTER * prev
    s += _QUARTER * nxt
    smooth[i % r, p] = s


@nb.njit(cache=True)
def _ring_slots(centre, half_window, r, slots):
    """Fill `slots` ``(2 * half_window + 3,)`` with the ring slots of frames ``centre - half_window - 1 ..``.

    Frame ``f`` is in slot ``f % r``; the slots are computed once per centre
    so that the per-pixel tests need no integer division.
    """
    for k in range(slots.shape[0]):
        slots[k] = (centre - half_window - 1 + k) % r
    return slots


@nb.njit(cache=True)
def _is_candidate(smooth, p, centre, end, half_window, worst, slots):
    """Whether frame `centre` of pixel `p` is a local minimum deeper than `worst`.

    The ring `smooth` ``(r, P)`` must hold the smoothed values of frames
    ``centre - half_window - 1 .. centre + half_window``, frame ``centre + d``
    in slot ``slots[half_window + 1 + d]`` (see :func:`_ring_slots`).
    A local minimum is not larger than any smoothed value within
    ``half_window`` frames and, among the run of equal values around it (a
    flat minimum, seen within the window), is its middle frame (the later one
    of an even run). An equal value before the run, or a run reaching past
    the window's start, makes it no minimum (ties go to the earlier dip); a
    run longer than the window thus has one minimum, ``half_window`` frames
    after its first frame.
    """
    h = half_window
    o = h + 1  # slots[o + d] holds frame centre + d
    s = smooth[slots[o], p]
    if not s < worst:  # also rejects NaN
        return False
    first = centre  # the run of values equal to s, within the window
    open_run = True
    for d in range(1, h + 1):
        if centre - d < 0:
            break
        v = smooth[slots[o - d], p]
        if v < s:
            return False
        if v == s:
            if not open_run:
                return False
            first = centre - d
        else:
            open_run = False
    if open_run and first == centre - h and centre - h - 1 >= 0 and smooth[slots[0], p] == s:
        return False  # the run starts before the window: an earlier frame is its minimum
    last = centre
    open_run = True
    for d in range(1, h + 1):
        if centre + d >= end:
            break
        v = smooth[slots[o + d], p]
        if v < s:
            return False
        if v == s and open_run:
            last = centre + d
        elif v != s:
            open_run = False
    return centre == (first + last + 1) // 2


@nb.njit(cache=True, inline="always")
def _insert(top_value, top_frame, p, value, frame):
    """Insert `value` (at `frame`) into pixel `p`'s ascending lists ``(TOP, P)``, if below their last.

    Branch free: the entries above `value` (a suffix of the sorted list)
    move down one place, the last one drops out. Nothing changes for ``value = +inf``. Returns whether `value`
    became the first (deepest) entry.
    """
    deepest = value < top_value[0, p]
    carry_v = value
    carry_f = frame
    for k in range(TOP):
        old_v = top_value[k, p]
        old_f = top_frame[k, p]
        moves = value < old_v
        top_value[k, p] = carry_v if moves else old_v
        top_frame[k, p] = carry_f if moves else old_f
        carry_v = old_v if moves else carry_v
        carry_f = old_f if moves else carry_f
    return deepest


@nb.njit(cache=True)
def _copy_window(raw, p, centre, end, half_window, window, slots):
    """Copy pixel `p`'s raw frames ``centre - half_window .. centre + half_window`` to `window` ``(K, P)``.

    Frames outside ``[0, end)`` are NaN; `slots` as in :func:`_is_candidate`.
    """
    h = half_window
    for q in range(2 * h + 1):
        f = centre - h + q
        window[q, p] = raw[slots[q + 1], p] if 0 <= f < end else np.nan


@nb.njit(cache=True)
def _consider(raw, smooth, p, centre, end, half_window, top_value, top_frame, window, slots):
    """Insert frame `centre` among pixel `p`'s deepest local minima if it is one.

    The sorted lists are ``(TOP, P)``; the raw window ``(K, P)`` is copied when
    the centre becomes the deepest. `slots` as in :func:`_is_candidate`.
    """
    if not _is_candidate(smooth, p, centre, end, half_window, top_value[TOP - 1, p], slots):
        return
    if _insert(top_value, top_frame, p, smooth[slots[half_window + 1], p], centre):
        _copy_window(raw, p, centre, end, half_window, window, slots)


#: pixels per tile: the tile's rings and sums stay in cache while a block streams through
TILE = 1024
#: frames summed in float64 before the sums move to int64 (exact for |sample| < 2**17)
_FLUSH = 16
_EXACT_BELOW = 2.0**17


@nb.njit(cache=True)
def _exact_sums(block, t0, t1, p0, p1, signal_sum, channel_sum):
    """Fixed-point sums of frames ``t0 .. t1 - 1`` of a tile, one sample at a time."""
    n_c = block.shape[2]
    for p in range(p0, p1):
        for t in range(t0, t1):
            x = block[t, p, 0]
            for c in range(1, n_c):
                x += block[t, p, c]
            if np.isfinite(x):
                signal_sum[p] += _fixed(np.float64(x))
            for c in range(n_c):
                v = block[t, p, c]
                if np.isfinite(v):
                    channel_sum[c, p] += _fixed(np.float64(v))


@nb.njit(cache=True)
def _suffix_minima(smooth, u0, m, block_first, k_from, suffix):
    """Suffix minima ``suffix[k] = min(frames block_first + k .. block_first + K - 1)`` for ``k >= k_from``.

    Read from the smoothed ring ``(r, P)`` (frame ``f`` in slot ``f % r``),
    pixels ``u0 .. u0 + m - 1``, NaN ignored (+inf where all are NaN);
    `suffix` is ``(K, m)``.
    """
    r = smooth.shape[0]
    n_k = suffix.shape[0]
    row = np.uint64((block_first + n_k - 1) % r)
    for q in range(m):
        suffix[n_k - 1, q] = np.inf
    for q in range(m):
        v = smooth[row, u0 + np.uint64(q)]
        sv = suffix[n_k - 1, q]
        suffix[n_k - 1, q] = v if v < sv else sv
    for k in range(n_k - 2, k_from - 1, -1):
        row = np.uint64((block_first + k) % r)
        for q in range(m):
            v = smooth[row, u0 + np.uint64(q)]
            sv = suffix[k + 1, q]
            suffix[k, q] = v if v < sv else sv


@nb.njit(cache=True)
def _window_minima_start(smooth, u0, m, first_index, suffix, prefix):
    """The running minimum's state before frame `first_index` enters the rings.

    The minimum runs over the last ``K = suffix.shape[0]`` smoothed frames.
    Frames are grouped in blocks of ``K`` (block ``b``: frames
    ``b K .. b K + K - 1``). The first minimum computed (frames
    ``a .. a + K - 1``, ``a = first_index - K``) needs the suffix minima of
    ``a``'s block from ``a`` on, when that block ends before frame
    ``first_index - 1``, and the prefix minimum of frame ``first_index - 2``'s
    block up to it; both are read from the ring.
    """
    n_k = suffix.shape[0]
    a = first_index - n_k
    ka = a % n_k
    if ka > 0:  # a's block is complete before frame first_index - 1 is smoothed
        _suffix_minima(smooth, u0, m, a - ka, ka, suffix)
    e = first_index - 2
    ke = e % n_k
    for q in range(m):
        prefix[q] = np.inf
    for f in range(e - ke, e + 1):
        row = np.uint64(f % smooth.shape[0])
        for q in range(m):
            v = smooth[row, u0 + np.uint64(q)]
            pv = prefix[q]
            prefix[q] = v if v < pv else pv


@nb.njit(cache=True)
def _track_tile(block, p0, p1, first_index, start, stop, half_window, saturation_level,
                raw, smooth, top_value, top_frame, window, signal_sum, square_hi, square_lo,
                count, invalid, channel_sum, saturated):
    """:func:`track_block` for pixels ``p0 .. p1 - 1``.

    A serial function so that its pixel loops vectorise; pixel indices are
    unsigned (numba's negative-index wrap-around blocks vectorisation).
    """
    n_t, n_c = block.shape[0], block.shape[2]
    r = raw.shape[0]
    h = half_window
    m = p1 - p0
    u0 = np.uint64(p0)
    acc = np.zeros(m)
    cacc = np.zeros((n_c, m))
    hits = np.zeros(m, np.int64)
    hit = np.zeros((m + 7) // 8 * 8, np.uint8)  # 0: no candidate, 1: strict minimum, 2: equal values
    hit_words = hit.view(np.uint64)  # the codes of 8 pixels as one word
    slots = np.empty(2 * h + 3, np.uint64)
    # minimum of the smoothed values of frames e - h + 1 .. e (NaN ignored, +inf if none),
    # frame e's in row e % (h + 2): the h frames after a centre and the h before it
    n_w = h + 2
    half_min = np.full((n_w, m), np.inf, np.float32)
    for e in range(first_index - h - 2, first_index - 1):
        w_row = np.uint64(e % n_w)
        for f in range(e - h + 1, e + 1):
            f_row = np.uint64(f % r)
            for q in range(m):
                v = smooth[f_row, u0 + np.uint64(q)]
                cur = half_min[w_row, q]
                half_min[w_row, q] = v if v < cur else cur
    suffix = np.empty((h, m), np.float32)
    prefix = np.empty(m, np.float32)
    _window_minima_start(smooth, u0, m, first_index, suffix, prefix)
    t_flush = 0
    big = 0
    for t in range(n_t):
        j = first_index + t
        slot = np.uint64(j % r)
        owned = start <= j < stop
        for q in range(m):
            p = u0 + np.uint64(q)
            x = block[t, p, 0]
            if n_c > 1:
                x += block[t, p, 1]
            if n_c > 2:
                x += block[t, p, 2]
            raw[slot, p] = x if x - x == 0 else np.float32(np.nan)
        if j >= 1:  # smoothing of frame j - 1 (as _smooth_frame, slots hoisted)
            before = np.uint64((j - 2) % r if j >= 2 else (j - 1) % r)
            middle = np.uint64((j - 1) % r)
            for q in range(m):
                p = u0 + np.uint64(q)
                sm = raw[middle, p] * _HALF
                sm += _QUARTER * raw[before, p]
                sm += _QUARTER * raw[slot, p]
                smooth[middle, p] = sm
        if owned:
            for q in range(m):
                p = u0 + np.uint64(q)
                x = raw[slot, p]
                ok = x == x
                xd = np.float64(x) if ok else 0.0
                big += abs(xd) >= _EXACT_BELOW
                acc[q] += (xd * SUM_SCALE + _ROUND) - _ROUND
                sq = xd * xd
                hi = (sq + _SQ_HI) - _SQ_HI
                square_hi[p] += hi
                square_lo[p] += ((sq - hi) + _SQ_LO) - _SQ_LO
                count[p] += ok
                invalid[p] += not ok
            for c in range(n_c):
                for q in range(m):
                    p = u0 + np.uint64(q)
                    v = block[t, p, c]
                    # +inf is corrupt input (counted above), not a clipped channel
                    saturated[p] |= (v >= saturation_level) & (v < np.inf)
                    if n_c > 1:  # one channel's sum is the signal's (flushed below)
                        vd = np.float64(v) if v - v == 0 else 0.0
                        big += abs(vd) >= _EXACT_BELOW
                        cacc[c, q] += (vd * SUM_SCALE + _ROUND) - _ROUND
            if t + 1 == n_t or j + 1 == stop or t + 1 - t_flush == _FLUSH:
                if big:  # float64 sums may have rounded: redo these frames exactly
                    _exact_sums(block, t_flush, t + 1, p0, p1, signal_sum, channel_sum)
                else:
                    for q in range(m):
                        p = u0 + np.uint64(q)
                        signal_sum[p] += np.int64(acc[q])
                    if n_c == 1:
                        for q in range(m):
                            channel_sum[0, u0 + np.uint64(q)] += np.int64(acc[q])
                    else:
                        for c in range(n_c):
                            for q in range(m):
                                channel_sum[c, u0 + np.uint64(q)] += np.int64(cacc[c, q])
                acc[:] = 0.0
                cacc[:] = 0.0
                big = 0
                t_flush = t + 1
        else:
            t_flush = t + 1
        # running minimum of the last h smoothed values (van Herk / Gil-Werman): frame
        # e = j - 1 (just smoothed) enters the prefix minimum of its h-frame block; a
        # completed block gets its suffix minima; their minimum is that of frames e - h + 1 .. e
        e = j - 1
        ke = e % h
        if ke == 0:
            prefix[:] = np.inf
        erow = np.uint64(e % r)
        for q in range(m):
            p = u0 + np.uint64(q)
            v = smooth[erow, p]
            pv = prefix[q]
            prefix[q] = v if v < pv else pv
        if ke == h - 1:
            _suffix_minima(smooth, u0, m, e - h + 1, 0, suffix)
        ka = np.uint64((e - h + 1) % h)
        w_row = np.uint64(e % n_w)
        for q in range(m):
            sv = suffix[ka, q]
            pv = prefix[q]
            half_min[w_row, q] = pv if pv < sv else sv
        centre = j - h - 1
        if centre >= start and centre >= 0 and centre < stop:
            # vectorised test: below the pixel's current 5th candidate and not above the
            # least smoothed value within h frames (NaN decides nothing): after the first
            # few dips of a sweep rare, ever rarer as it goes on; the passing pixels are
            # gathered and inserted one by one (equal values: the flat-run rules)
            _ring_slots(centre, h, r, slots)
            cslot = slots[h + 1]
            before_row = np.uint64((centre - 1) % n_w)  # frames centre - h .. centre - 1
            after_row = np.uint64((centre + h) % n_w)  # frames centre + 1 .. centre + h
            worst = np.uint64(TOP - 1)
            for q in range(m):
                p = u0 + np.uint64(q)
                sc = smooth[cslot, p]
                lv = half_min[before_row, q]
                rv = half_min[after_row, q]
                low = lv if lv < rv else rv
                passes = (sc < top_value[worst, p]) & (not low < sc)
                hit[q] = np.uint8(passes) + np.uint8(passes & (low == sc))
            n_hits = 0  # gathered 8 flags at a time, skipping words without a hit
            for w in range(m // 8):
                if hit_words[w]:
                    for q in range(8 * w, 8 * w + 8):
                        hits[n_hits] = q
                        n_hits += hit[q] != 0
            for q in range(m - m % 8, m):
                hits[n_hits] = q
                n_hits += hit[q] != 0
            for i in range(n_hits):
                q = hits[i]
                p = u0 + np.uint64(q)
                if hit[q] == 1:
                    # a strict minimum is the middle of its own flat run: a local minimum
                    # (what _is_candidate finds)
                    if _insert(top_value, top_frame, p, smooth[cslot, p], centre):
                        _copy_window(raw, p0 + q, centre, j + 1, h, window, slots)
                else:  # equal values around: the flat-run rules decide
                    _consider(raw, smooth, p0 + q, centre, j + 1, h, top_value, top_frame, window, slots)


@nb.njit(cache=True, parallel=True)
def track_block(block, first_index, start, stop, half_window, saturation_level,
                raw, smooth, top_value, top_frame, window, signal_sum, square_hi, square_lo,
                count, invalid, channel_sum, saturated):
    """Feed frames ``first_index + t`` of `block` ``(T, P, C)`` float32 (C <= 3) to the state.

    The signal is the channel sum (float32, channels added in order); a
    non-finite signal enters the rings as NaN. Sums, counts and saturation
    cover frames in ``[start, stop)`` only; centres in ``[start, stop)`` are
    tested once the frames up to ``centre + half_window + 1`` are in the rings
    of raw and smoothed samples ``(2 * half_window + 3, P)`` (frame ``f`` in
    slot ``f % r``). State arrays are pixel-minor: lists ``(TOP, P)``, window
    ``(K, P)``, channel sums ``(C, P)``.

    Pixels are processed in tiles of :data:`TILE` (in parallel), frames in
    order within a tile, pixels innermost (vectorised). Fixed-point sums are
    accumulated as integer-valued float64 over :data:`_FLUSH` frames, then
    added to the int64 sums: exact for samples below ``2**17`` in magnitude;
    a tile and frame range with a larger sample is summed again one sample
    at a time. Centres are tested vectorised against the least smoothed
    value of the ``half_window`` frames before and of those after them
    (running minima over ``half_window`` frames, prefix and suffix minima of
    ``half_window``-frame groups, ~3 compares per pixel-frame): a centre
    below the pixel's last candidate and not above either is gathered; a
    strict minimum (both above it) is a local minimum and is inserted
    directly (:func:`_insert`); only centres with an equal value in their
    window take the full flat-run test (:func:`_is_candidate`).
    """
    n_p = block.shape[1]
    n_tiles = (n_p + TILE - 1) // TILE
    for tile in nb.prange(n_tiles):
        _track_tile(block, tile * TILE, min(tile * TILE + TILE, n_p), first_index, start, stop,
                    half_window, saturation_level, raw, smooth, top_value, top_frame, window,
                    signal_sum, square_hi, square_lo, count, invalid, channel_sum, saturated)


@nb.njit(cache=True, parallel=True)
def finish_centres(first, last, end, half_window, raw, smooth, top_value, top_frame, window):
    """Test centres ``first .. last - 1`` of a sequence whose last frame is ``end - 1``.

    The last frame's smoothed value (its next neighbour replaced by itself)
    is computed first.
    """
    if end < 1:
        return
    slots = np.empty((max(last - first, 0), 2 * half_window + 3), np.uint64)
    for centre in range(first, last):
        _ring_slots(centre, half_window, raw.shape[0], slots[centre - first])
    for p in nb.prange(raw.shape[1]):
        _smooth_frame(raw, smooth, p, end - 1, end)
        for centre in range(first, last):
            _consider(raw, smooth, p, centre, end, half_window, top_value, top_frame, window,
                      slots[centre - first])


@nb.njit(cache=True, inline="always")
def _window_sum(samples):
    """Count, fixed-point sum and square parts of the finite `samples` ``(K,)``, in order."""
    count = 0
    fixed_sum = 0
    square_hi = 0.0
    square_lo = 0.0
    for k in range(samples.shape[0]):
        x = np.float64(samples[k])
        if np.isfinite(x):
            count += 1
            fixed_sum += _fixed(x)
            sq = x * x
            hi = (sq + _SQ_HI) - _SQ_HI
            square_hi += hi
            square_lo += ((sq - hi) + _SQ_LO) - _SQ_LO
    return count, fixed_sum, square_hi, square_lo


@nb.njit(cache=True, parallel=True)
def window_sums(window, keep):
    """Exact sums of each kept pixel's window samples, as the running sums hold them.

    Parameters
    ----------
    window : (K, P) float32 ndarray
        Samples of each pixel's window (non-finite ones are skipped).
    keep : (P,) bool ndarray
        Pixels whose window is summed (others get zeros).

    Returns
    -------
    count, fixed_sum : (P,) int64 ndarray
        Finite samples and their fixed-point sum (as :func:`quantise_sum`).
    square_hi, square_lo : (P,) float64 ndarray
        Sums of the two parts of their squares (as :func:`split_square`).
    """
    n_p = window.shape[1]
    count = np.zeros(n_p, np.int64)
    fixed_sum = np.zeros(n_p, np.int64)
    square_hi = np.zeros(n_p)
    square_lo = np.zeros(n_p)
    for p in nb.prange(n_p):
        if keep[p]:
            count[p], fixed_sum[p], square_hi[p], square_lo[p] = _window_sum(window[:, p])
    return count, fixed_sum, square_hi, square_lo


@nb.njit(cache=True, inline="always")
def _before(value, frame, other_value, other_frame):
    """Whether ``(value, frame)`` precedes ``(other_value, other_frame)``."""
    return value < other_value or (value == other_value and frame < other_frame)


@nb.njit(cache=True, parallel=True)
def merge_dips(values, frames, windows, half_window):
    """The deepest and the second dip of each pixel among its time chunks' candidates, with the window.

    The chunks' lists are read side by side (entry ``i`` is chunk ``i // TOP``'s slot
    ``i % TOP``): the deepest dip is the smallest finite (value, frame), the earliest
    entry among equals; the second the smallest one further than `half_window`
    frames from it. The deepest dip's window is its chunk's, and its samples' exact
    sums are those :func:`window_sums` gives.

    Parameters
    ----------
    values : tuple of (P, TOP) float32 ndarray
        Each chunk's candidate minima (non-finite = empty).
    frames : tuple of (P, TOP) int64 ndarray
        Their frames.
    windows : tuple of (P, K) float32 ndarray
        Each chunk's samples around its deepest candidate.
    half_window : int

    Returns
    -------
    minimum_value : (P,) float32 ndarray
        The deepest dip's value (the first chunk's first entry where there is none).
    minimum_frame : (P,) int64 ndarray
        Its frame, -1 where there is none.
    second_value, second_frame : (P,) float32 and int64 ndarray
        The second dip (``+inf`` and ``-(K + 1)`` where there is none).
    found : (P,) bool ndarray
        Whether there is a deepest dip.
    window : (K, P) float32 ndarray
        The deepest dip's window (NaN where there is none).
    count, fixed_sum, square_hi, square_lo : (P,) ndarray
        Its finite samples' :func:`window_sums` (zeros where there is none).
    chunk : (P,) int64 ndarray
        The chunk whose window it is (-1 where there is none).
    """
    n_p, k = windows[0].shape
    minimum_value = np.empty(n_p, np.float32)
    minimum_frame = np.full(n_p, -1, np.int64)
    second_value = np.full(n_p, np.inf, np.float32)
    second_frame = np.full(n_p, -(k + 1), np.int64)
    found = np.zeros(n_p, np.bool_)
    window = np.empty((k, n_p), np.float32)
    count = np.zeros(n_p, np.int64)
    fixed_sum = np.zeros(n_p, np.int64)
    square_hi = np.zeros(n_p)
    square_lo = np.zeros(n_p)
    chunk = np.full(n_p, -1, np.int64)
    for p in nb.prange(n_p):
        best = -1
        best_value = np.float32(0.0)
        best_frame = 0
        for c in range(len(values)):
            chunk_values = values[c]
            chunk_frames = frames[c]
            for slot in range(TOP):
                value = chunk_values[p, slot]
                frame = chunk_frames[p, slot]
                if np.isfinite(value) and (best < 0 or _before(value, frame, best_value, best_frame)):
                    best, best_value, best_frame = c * TOP + slot, value, frame
        if best < 0:
            minimum_value[p] = values[0][p, 0]
            window[:, p] = np.nan
            continue
        found[p] = True
        minimum_value[p] = best_value
        minimum_frame[p] = best_frame
        chunk[p] = best // TOP
        samples = windows[best // TOP][p]
        window[:, p] = samples
        count[p], fixed_sum[p], square_hi[p], square_lo[p] = _window_sum(samples)
        other = False
        for c in range(len(values)):
            chunk_values = values[c]
            chunk_frames = frames[c]
            for slot in range(TOP):
                value = chunk_values[p, slot]
                frame = chunk_frames[p, slot]
                if (np.isfinite(value) and abs(frame - best_frame) > half_window
                        and (not other or _before(value, frame, second_value[p], second_frame[p]))):
                    other = True
                    second_value[p] = value
                    second_frame[p] = frame
    return (minimum_value, minimum_frame, second_value, second_frame, found, window, count, fixed_sum,
            square_hi, square_lo, chunk)


@nb.njit(cache=True, parallel=True)
def interval_block(ext, ext_first, j_from, j_to, start, stop, end, centre_frame, threshold, half_window,
                   before_frame, before_values, before_invalid, after_frame, after_values, after_invalid,
                   before_sums, after_sums, previous, wants_next):
    """Compare smoothed frames ``j_from .. j_to - 1`` with each pixel's threshold around its centre.

    `ext` ``(T, P)`` float32 holds the raw signal of frames ``ext_first + t``,
    including each computed frame's neighbours inside ``[0, end)``. The
    smoothed value (``[1, 2, 1] / 4``, a neighbour outside ``[0, end)``
    replaced by the frame itself, as in the dip tracker) of each frame ``j``
    is compared with the pixel's `threshold` around its `centre_frame` (its
    deepest minimum; -1 = none): the last owned frame (``start <= j < stop``)
    before the centre at or above the threshold is kept with its smoothed
    value and the next frame's (``before_frame``, ``before_values (P, 2)``),
    and the first owned frame after the centre at or above it with the
    previous frame's value and its own (``after_frame``, ``after_values``).
    Non-finite smoothed values are neither above nor below; those of owned
    frames are counted since the last frame above (`before_invalid`, reset
    there) and before the first frame above (`after_invalid`). The raw
    samples of the same frames that lie more than `half_window` frames from
    the centre (the dip outside the tracker's window) are summed exactly, as
    the running sums hold them, into `before_sums` / `after_sums` ``(P, 4)``
    int64: count, fixed-point sum, and the two parts of the sum of squares
    (:func:`split_square`) as int64 multiples of ``2**-8`` and ``2**-40``.
    `previous` ``(P,)`` (smoothed value of frame ``j_from - 1``) and
    `wants_next` ``(P,)`` (the next frame's value is still to be stored in
    ``before_values[:, 1]``) carry the state across blocks.
    """
    n_p = ext.shape[1]
    for p in nb.prange(n_p):
        c = centre_frame[p]
        if c < 0:
            continue
        theta = threshold[p]
        for j in range(j_from, j_to):
            t = j - ext_first
            mid = ext[t, p]
            prev = ext[t - 1, p] if j >= 1 else mid
            nxt = ext[t + 1, p] if j + 1 < end else mid
            s = mid * _HALF
            s += _QUARTER * prev
            s += _QUARTER * nxt
            if wants_next[p]:
                before_values[p, 1] = s
                wants_next[p] = False
            owned = start <= j < stop
            finite = s - s == 0
            outside = (j < c - half_window or j > c + half_window) and mid - mid == 0
            x = np.float64(mid)
            sq = x * x
            hi = (sq + _SQ_HI) - _SQ_HI
            lo = ((sq - hi) + _SQ_LO) - _SQ_LO
            if owned and j < c:
                if not finite:
                    before_invalid[p] += 1
                elif s >= theta:
                    before_frame[p] = j
                    before_values[p, 0] = s
                    before_invalid[p] = 0
                    wants_next[p] = True
                    for q in range(4):
                        before_sums[p, q] = 0
                    outside = False
                if outside:
                    before_sums[p, 0] += 1
                    before_sums[p, 1] += _fixed(x)
                    before_sums[p, 2] += np.int64(hi * 256.0)
                    before_sums[p, 3] += np.int64(lo * 2.0**40)
            elif owned and j > c and after_frame[p] < 0:
                if not finite:
                    after_invalid[p] += 1
                elif s >= theta:
                    after_frame[p] = j
                    after_values[p, 0] = previous[p] if j >= 1 else s
                    after_values[p, 1] = s
                    outside = False
                if outside:
                    after_sums[p, 0] += 1
                    after_sums[p, 1] += _fixed(x)
                    after_sums[p, 2] += np.int64(hi * 256.0)
                    after_sums[p, 3] += np.int64(lo * 2.0**40)
            previous[p] = s


@nb.njit(cache=True, inline="always")
def _window_smooth(window, p, j, lo, end):
    """Smoothed value of frame `j` from pixel `p`'s window ``(K, P)`` (frame ``lo + k`` in row k), as :func:`interval_block`."""
    mid = window[j - lo, p]
    prev = window[j - 1 - lo, p] if j >= 1 else mid
    nxt = window[j + 1 - lo, p] if j + 1 < end else mid
    s = mid * _HALF
    s += _QUARTER * prev
    s += _QUARTER * nxt
    return s


@nb.njit(cache=True, parallel=True)
def interval_from_window(window, centre_frame, threshold, end, before_frame, before_values, after_frame,
                         after_values, resolved):
    """What :func:`interval_block` over a whole sweep finds, for pixels whose crossings lie in their window.

    `window` ``(K, P)`` float32 holds each pixel's raw signal of frames
    ``centre - h .. centre + h`` (``K = 2h + 1``; NaN outside ``[0, end)``),
    `centre_frame` ``(P,)`` its deepest minimum (negative: no dip), `threshold`
    ``(P,)`` float32. A frame's smoothed value needs its neighbours inside the
    window (or outside the sweep), so frames ``centre - h + 1 .. centre + h - 1``
    (and the sweep's first / last frame) are known. A pixel is resolved when
    its window has no non-finite sample inside the sweep and, on each side of
    the centre, a known frame at or above the threshold is met before an
    unknown one (or the sweep's end): then no frame beyond the window can
    change the crossings, the invalid counts are 0 and nothing lies inside the
    interval beyond the window. Resolved pixels get the crossing frames and
    values (the arrays' other pixels are left as they are); pixels without a
    dip are resolved with nothing found.
    """
    n_k, n_p = window.shape
    h = (n_k - 1) // 2
    for p in nb.prange(n_p):
        c = centre_frame[p]
        if c < 0:
            resolved[p] = True
            continue
        lo = c - h
        clean = True
        for k in range(n_k):
            f = lo + k
            if 0 <= f < end and not window[k, p] - window[k, p] == 0:
                clean = False
        if not clean:
            resolved[p] = False
            continue
        theta = threshold[p]
        done_before = c == 0  # nothing before the sweep's first frame
        for j in range(c - 1, max(0, lo) - 1, -1):
            if j >= 1 and j - 1 < lo:
                break  # its previous frame is outside the window
            s = _window_smooth(window, p, j, lo, end)
            if not s - s == 0:
                break
            if s >= theta:
                before_frame[p] = j
                before_values[p, 0] = s
                before_values[p, 1] = _window_smooth(window, p, j + 1, lo, end)
                done_before = True
                break
            if j == 0:
                done_before = True  # the sweep starts inside the dip: nothing before
        done_after = c + 1 >= end  # the sweep ends at the centre
        for j in range(c + 1, min(end, c + h + 1)):
            if j + 1 < end and j + 1 > c + h:
                break  # its next frame is outside the window
            s = _window_smooth(window, p, j, lo, end)
            if not s - s == 0:
                break
            if s >= theta:
                after_frame[p] = j
                after_values[p, 0] = _window_smooth(window, p, j - 1, lo, end)
                after_values[p, 1] = s
                done_after = True
                break
            if j == end - 1:
                done_after = True  # the sweep ends inside the dip
        resolved[p] = done_before and done_after


@nb.njit(cache=True, parallel=True)
def own_site_block(block, own, first_index, start, stop, sums, rest_invalid):
    """Add the owned frames of a block to each RAW site's own-value and neighbours' running sums.

    For the frames ``first_index + t`` in ``[start, stop)`` with a finite own value,
    the own value and the neighbours' part (the tracked signal, channels added in
    order in float32 as :func:`track_block`, less the own value, in float32) enter the
    sums in the exact forms of the tracker's (fixed-point sums, squares split in two).

    Parameters
    ----------
    block : (T, P, C) float32 ndarray
        The frames fed to :func:`track_block`.
    own : (T, P) float32 ndarray
        Each site's own value in those frames.
    first_index, start, stop : int
    sums : (7, P) int64 ndarray
        Count; own fixed-point sum, square parts (``2**-8`` and ``2**-40`` units);
        the neighbours' part's three likewise (in place).
    rest_invalid : (P,) int64 ndarray
        Frames whose neighbours' part is not finite (in place).
    """
    n_t, n_p, n_c = block.shape
    for p in nb.prange(n_p):
        for t in range(n_t):
            j = first_index + t
            if j < start or j >= stop:
                continue
            value = own[t, p]
            if not np.isfinite(value):
                continue
            x = block[t, p, 0]
            for c in range(1, n_c):
                x += block[t, p, c]
            _add_own(value, np.float32(x - value), sums, rest_invalid, p)


@nb.njit(cache=True, inline="always")
def _add_own(value, rest, sums, rest_invalid, p):
    """Count a finite own value and add it and its neighbours' part `rest` (if finite) to pixel `p`'s sums."""
    sums[0, p] += 1
    _add_sample(np.float64(value), sums, 1, p)
    if np.isfinite(rest):
        _add_sample(np.float64(rest), sums, 4, p)
    else:
        rest_invalid[p] += 1


@nb.njit(cache=True, inline="always")
def _add_sample(x, sums, row, p):
    """Add `x` to the fixed-point sum ``sums[row, p]`` and its square's parts to the next two rows."""
    sums[row, p] += _fixed(x)
    sq = x * x
    hi = (sq + _SQ_HI) - _SQ_HI
    sums[row + 1, p] += np.int64(hi * 256.0)
    sums[row + 2, p] += np.int64((((sq - hi) + _SQ_LO) - _SQ_LO) * 2.0**40)


@nb.njit(cache=True, parallel=True)
def own_window_sums(own_window, signal_window, keep):
    """The :func:`own_site_block` sums of each kept pixel's own and signal windows ``(K, P)``.

    Returns
    -------
    sums : (7, P) int64 ndarray
        As :func:`own_site_block`'s, over the window's frames with a finite own value.
    rest_invalid : (P,) int64 ndarray
        Window frames with a finite own value and a non-finite neighbours' part.
    """
    n_k, n_p = own_window.shape
    sums = np.zeros((7, n_p), np.int64)
    rest_invalid = np.zeros(n_p, np.int64)
    for p in nb.prange(n_p):
        if not keep[p]:
            continue
        for k in range(n_k):
            value = own_window[k, p]
            if not np.isfinite(value):
                continue
            _add_own(value, np.float32(signal_window[k, p] - value), sums, rest_invalid, p)
    return sums, rest_invalid


@nb.njit(cache=True, parallel=True)
def copy_own_windows(tail, block, first_index, centre, changed, end, half_window, own_window):
    """Copy the own values of frames ``centre - half_window .. centre + half_window`` of the changed pixels.

    Parameters
    ----------
    tail : (K, P) float32 ndarray
        Own values of the ``K`` frames before `first_index`.
    block : (T, P) float32 ndarray
        Own values of frames ``first_index + t``.
    first_index : int
    centre : (P,) int64 ndarray
        Each pixel's deepest centre.
    changed : (P,) bool ndarray
        Pixels whose channel-sum window was copied since the last call.
    end : int
        One past the last frame fed (frames outside ``[0, end)`` are NaN, as the
        channel sum's window).
    half_window : int
    own_window : (K, P) float32 ndarray
        Written in place for the changed pixels.
    """
    n_k, n_p = tail.shape
    n_t = block.shape[0]
    for p in nb.prange(n_p):
        if not changed[p]:
            continue
        for q in range(2 * half_window + 1):
            f = centre[p] - half_window + q
            s = f - first_index
            value = np.float32(np.nan)
            if 0 <= f < end and 0 <= s < n_t:
                value = block[s, p]
            elif 0 <= f < end and -n_k <= s < 0:
                value = tail[n_k + s, p]
            own_window[q, p] = value
