"""Compiled per-frame kernels of the outdoor passes (numba).

:func:`cubic_translate_rows` is the separable cubic translation of
:func:`shadowcam.outdoor.translation.translate` ``"cubic_Keys1981"`` one output row at a time:
the row pass (four rows of the source, edges replicated) into a one-row buffer, then the
column pass out of it, each with the same float32 operations in the same order as the
whole-array formulation (``total = x0 w0; total += x1 w1; ...``), so the bits are those
of the numpy version; while the row is in cache it is also added to the sums of its
``factor x factor`` blocks (float64), so that the block means of the translated frame
(:func:`shadowcam.outdoor.registration.block_mean`) cost no second pass over it.

:func:`normalise_smooth_minimum` divides a translated frame by its gain in place and, in the
same pass, takes the running minimum of the 3-frame smoothing ``0.25 a + 0.5 b + 0.25 c``
(float32, in that order) of the first pass's per-pixel shadow level
(:class:`shadowcam.outdoor.normalise.SequenceNormaliser`).

:func:`block_upper_quartiles` is the per-block loop of
:func:`shadowcam.outdoor.shade_field.block_levels`: each block's used ratios at or above the
reach threshold gathered, sorted, and their upper quartile interpolated as ``np.percentile``
(linear; ``a + d g`` below ``g = 0.5``, ``b - d (1 - g)`` from it, in the ratios' dtype), so
the levels are numpy's bit for bit.

None validates its inputs: :mod:`shadowcam.outdoor.translation`,
:mod:`shadowcam.outdoor.normalise` and :mod:`shadowcam.outdoor.shade_field` do.

Offers
------
cubic_translate_rows : separable cubic translation with the translated frame's block sums.
normalise_smooth_minimum : divide by the gain, then the running minimum of the 3-frame smoothing.
block_upper_quartiles : each block's upper quartile of its lit ratios, with the block's usability tests.
"""

import numba as nb
import numpy as np


@nb.njit(cache=True)
def cubic_translate_rows(image, row_weights, row_start, col_weights, col_start, out, factor, block_sums):
    """Translate `image` into `out` (separable cubic, edges replicated) and sum its blocks.

    Parameters
    ----------
    image : (H, W) float32 ndarray
    row_weights, col_weights : (4,) float32 ndarray
        Cubic weights of the row and column pass; ``None`` skips that pass (a zero shift
        along the axis: the source is copied).
    row_start, col_start : int
        Source index of the first tap of output index 0 (``floor(shift) - 1``).
    out : (H, W) float32 ndarray
        The translated frame (written).
    factor : int
        Block side of `block_sums`.
    block_sums : (H // factor, W // factor) float64 ndarray
        Zeroed on entry; the sums of the translated frame's whole blocks.
    """
    height, width = image.shape
    row = np.empty(width, dtype=np.float32)
    n_block_rows, n_block_cols = block_sums.shape
    last_row, last_col = height - 1, width - 1
    for r in range(height):
        if row_weights is None:
            row[:] = image[r]
        else:
            source = min(max(r + row_start, 0), last_row)
            weight = row_weights[0]
            for c in range(width):
                row[c] = image[source, c] * weight
            for tap in range(1, 4):
                source = min(max(r + row_start + tap, 0), last_row)
                weight = row_weights[tap]
                for c in range(width):
                    row[c] += image[source, c] * weight
        target = out[r]
        if col_weights is None:
            target[:] = row
        else:
            w0, w1, w2, w3 = col_weights[0], col_weights[1], col_weights[2], col_weights[3]
            for c in range(width):
                c0 = c + col_start
                if c0 >= 0 and c0 + 3 <= last_col:
                    total = row[c0] * w0
                    total += row[c0 + 1] * w1
                    total += row[c0 + 2] * w2
                    total += row[c0 + 3] * w3
                else:
                    total = row[min(max(c0, 0), last_col)] * w0
                    total += row[min(max(c0 + 1, 0), last_col)] * w1
                    total += row[min(max(c0 + 2, 0), last_col)] * w2
                    total += row[min(max(c0 + 3, 0), last_col)] * w3
                target[c] = total
        block_row = r // factor
        if block_row < n_block_rows:
            sums = block_sums[block_row]
            for block_col in range(n_block_cols):
                acc = 0.0
                for c in range(block_col * factor, block_col * factor + factor):
                    acc += target[c]
                sums[block_col] += acc


@nb.njit(cache=True)
def normalise_smooth_minimum(current, gain, earlier, previous, minimum):
    """``current /= gain`` in place; then, with `earlier` and `previous` given, the running minimum.

    Parameters
    ----------
    current : (H, W) float32 ndarray
        The frame's translated luminance; divided by `gain` in place.
    gain : float32
    earlier, previous : (H, W) float32 ndarray or None
        The two frames before, already divided by their gains; ``None``: no minimum is taken.
    minimum : (H, W) float32 ndarray
        ``min(minimum, 0.25 earlier + 0.5 previous + 0.25 current)``, in place.
    """
    height, width = current.shape
    quarter, half = np.float32(0.25), np.float32(0.5)
    for r in range(height):
        now = current[r]
        for c in range(width):
            now[c] = now[c] / gain
        if earlier is None or previous is None:
            continue
        first, second, low = earlier[r], previous[r], minimum[r]
        for c in range(width):
            smooth = first[c] * quarter
            smooth += second[c] * half
            smooth += now[c] * quarter
            if smooth < low[c] or smooth != smooth:  # NaN propagates, as np.minimum
                low[c] = smooth


@nb.njit(cache=True)
def block_upper_quartiles(ratio, use, above, row_edges, col_edges, levels):
    """Each block's upper quartile of its ratios ``above`` the reach threshold, where the block is usable.

    Parameters
    ----------
    ratio : (h, w) float ndarray
        ``luma / reference_luma`` where `use`.
    use, above : (h, w) bool ndarray
        Pixels used (lit in the reference, not near the ridge's shadow, positive reference) and,
        of those, the ones at or above the reach threshold.
    row_edges, col_edges : (By + 1,), (Bx + 1,) int ndarray
        Block boundaries.
    levels : (By, Bx) float64 ndarray
        Written where the block has 10 or more ratios above, those are more than three quarters
        of its used ones, and its used pixels are a quarter or more of the block; left as given
        elsewhere.
    """
    n_rows, n_cols = levels.shape
    gamma_cast = np.empty(1, dtype=ratio.dtype)
    for i in range(n_rows):
        r0, r1 = row_edges[i], row_edges[i + 1]
        for j in range(n_cols):
            c0, c1 = col_edges[j], col_edges[j + 1]
            size = (r1 - r0) * (c1 - c0)
            lit = np.empty(size, dtype=ratio.dtype)
            n_used, n_lit = 0, 0
            for r in range(r0, r1):
                for c in range(c0, c1):
                    if use[r, c]:
                        n_used += 1
                        if above[r, c]:
                            lit[n_lit] = ratio[r, c]
                            n_lit += 1
            if n_lit < 10 or 4 * (n_used - n_lit) >= n_used or 4 * n_used < size:
                continue
            values = np.sort(lit[:n_lit])
            virtual = (n_lit - 1) * 0.75
            below = int(np.floor(virtual))
            gamma = virtual - below
            low, high = values[below], values[min(below + 1, n_lit - 1)]
            diff = high - low
            if gamma >= 0.5:
                gamma_cast[0] = 1.0 - gamma
                levels[i, j] = high - diff * gamma_cast[0]
            else:
                gamma_cast[0] = gamma
                levels[i, j] = low + diff * gamma_cast[0]
