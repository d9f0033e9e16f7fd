"""Compiled per-pixel kernels of the shadow-time step (numba, ``prange`` over pixels).

Each kernel does, pixel by pixel and in the same order, the arithmetic of the numpy
expression it replaces in :mod:`shadowcam.lab.shadow_time`, so that its results are the
same bit for bit; it reads each pixel's samples once instead of making one whole-image
pass per intermediate array.

Offers
------
removed_light : removed light of each pixel's window, its first moment in frames and its largest fraction.
neighbour_median : median of each pixel's 8-neighbours' values, NaN ones left out.
"""

import numba as nb
import numpy as np


@nb.njit(cache=True, parallel=True, error_model="numpy")
def removed_light(window, window_start, lit_level):
    """Removed light ``1 - I / I_lit`` of each pixel's window, summed over its finite samples.

    Parameters
    ----------
    window : (K, P) float32 ndarray
        Samples of each pixel's window, frame ``window_start + k`` in row ``k``.
    window_start : (P,) int64 ndarray
    lit_level : (P,) float64 ndarray

    Returns
    -------
    total : (P,) float64 ndarray
        Sum of the finite removed fractions in frame order; NaN where none is finite.
    moment : (P,) float64 ndarray
        Sum of frame times removed fraction.
    floor : (P,) float64 ndarray
        Largest finite removed fraction (``-inf`` where none is finite).
    """
    k, n_p = window.shape
    total = np.empty(n_p)
    moment = np.empty(n_p)
    floor = np.empty(n_p)
    for p in nb.prange(n_p):
        level = lit_level[p]
        start = window_start[p]
        held = False
        t = 0.0
        m = 0.0
        f = -np.inf
        for j in range(k):
            fraction = 1.0 - np.float64(window[j, p]) / level
            if np.isfinite(fraction):
                held = True
                t += fraction
                m += fraction * np.float64(start + j)
                if fraction > f:
                    f = fraction
        total[p] = t if held else np.nan
        moment[p] = m
        floor[p] = f
    return total, moment, floor


@nb.njit(cache=True, parallel=True)
def neighbour_median(values):
    """Median of each pixel's 8-neighbours' non-NaN values (infinite ones included).

    Parameters
    ----------
    values : (H, W) float64 ndarray

    Returns
    -------
    (H, W) float64 ndarray
        The middle value, or the mean of the two middle values for an even count
        (``(low + high) / 2``); NaN where no neighbour is finite or the image's edge
        leaves none.
    """
    h, w = values.shape
    out = np.full((h, w), np.nan)
    for r in nb.prange(h):
        found = np.empty(8)
        for c in range(w):
            n = 0
            finite = False
            for dr in range(-1, 2):
                rr = r + dr
                if rr < 0 or rr >= h:
                    continue
                for dc in range(-1, 2):
                    cc = c + dc
                    if (dr == 0 and dc == 0) or cc < 0 or cc >= w:
                        continue
                    v = values[rr, cc]
                    if not np.isnan(v):
                        finite |= np.isfinite(v)
                        # insertion into the sorted values so far
                        i = n
                        while i > 0 and found[i - 1] > v:
                            found[i] = found[i - 1]
                            i -= 1
                        found[i] = v
                        n += 1
            if finite:
                low = found[(n - 1) // 2]
                high = found[n // 2]
                out[r, c] = (low + high) / 2.0
    return out
