"""The shadow-time step's compiled kernels against the numpy formulation they replace.

Equality is exact (``array_equal``): the kernels do each pixel's arithmetic in the same
order as the numpy expressions.
"""

import numpy as np
import pytest

from shadowcam.lab.timing_kernels import neighbour_median, removed_light


def _removed_light_numpy(window, window_start, lit_level):
    with np.errstate(invalid="ignore", divide="ignore"):
        fraction = 1.0 - window.astype(np.float64) / lit_level[None]
    frames = window_start[None] + np.arange(window.shape[0])[:, None, None]
    held = np.isfinite(fraction)
    total = np.where(held, fraction, 0.0).sum(axis=0)
    moment = np.where(held, fraction * frames, 0.0).sum(axis=0)
    floor = np.where(held, fraction, -np.inf).max(axis=0)
    total = np.where(held.any(axis=0), total, np.nan)
    return total, moment, floor


def _neighbour_median_numpy(values):
    h, w = values.shape
    padded = np.pad(values, 1, constant_values=np.nan)
    neighbours = np.stack([padded[1 + dr:1 + dr + h, 1 + dc:1 + dc + w]
                           for dr in (-1, 0, 1) for dc in (-1, 0, 1) if (dr, dc) != (0, 0)])
    known = np.isfinite(neighbours).any(axis=0)
    reference = np.full(values.shape, np.nan)
    reference[known] = np.nanmedian(neighbours[:, known], axis=0)
    return reference


@pytest.mark.parametrize("seed", range(4))
def test_removed_light_equals_the_numpy_sums(seed):
    rng = np.random.default_rng(seed)
    k, h, w = 9, 17, 23
    window = rng.uniform(0.0, 1.2, (k, h, w)).astype(np.float32)
    window[rng.random(window.shape) < 0.15] = np.nan
    window[:, 0, 0] = np.nan  # no finite sample: NaN total, -inf floor
    window[rng.random(window.shape) < 0.02] = np.inf
    lit_level = rng.uniform(0.2, 1.5, (h, w))
    lit_level[1, 2] = 0.0  # every fraction infinite or NaN
    window_start = rng.integers(-5, 500, (h, w))
    expected = _removed_light_numpy(window, window_start, lit_level)
    got = removed_light(window.reshape(k, -1), window_start.ravel(), lit_level.ravel())
    for e, g in zip(expected, got):
        np.testing.assert_array_equal(g.reshape(h, w), e)
    assert np.isnan(got[0][0]) and got[2][0] == -np.inf


@pytest.mark.parametrize("seed", range(4))
def test_neighbour_median_equals_numpys_nanmedian(seed):
    rng = np.random.default_rng(seed)
    values = np.round(rng.normal(3.0, 1.0, (13, 19)), 1)  # ties on a coarse grid
    values[rng.random(values.shape) < 0.3] = np.nan
    values[rng.random(values.shape) < 0.03] = np.inf
    values[rng.random(values.shape) < 0.03] = -np.inf
    values[5:8, 5:8] = np.nan  # a pixel with no neighbour
    values[0:3, 15:18] = np.inf
    values[1, 16] = 2.0  # only infinite neighbours: no reference
    with np.errstate(invalid="ignore"):
        expected = _neighbour_median_numpy(values)
    got = neighbour_median(values)
    np.testing.assert_array_equal(got, expected)
    assert np.isnan(got[6, 6]) and np.isnan(got[1, 16])


def _crossings_numpy(window, threshold, window_start, h):
    k = window.shape[0]
    above = window >= threshold[None]
    idx = np.arange(k)[:, None, None]
    left = np.where(above & (idx < h), idx, -1).max(axis=0)
    right = np.where(above & (idx > h), idx, k).min(axis=0)
    rows, cols = np.indices(threshold.shape)

    def interpolate(a, b):
        ok = (a >= 0) & (a < k) & (b >= 0) & (b < k)
        a_c, b_c = np.clip(a, 0, k - 1), np.clip(b, 0, k - 1)
        va, vb = window[a_c, rows, cols], window[b_c, rows, cols]
        with np.errstate(invalid="ignore", divide="ignore"):
            frac = (va - threshold) / (va - vb)
            crossing = window_start + a_c + frac * (b_c - a_c)
        return np.where(ok & np.isfinite(frac), crossing, np.nan)

    below = window[h] < threshold
    return (np.where(below, interpolate(left, left + 1), np.nan),
            np.where(below, interpolate(right, right - 1), np.nan))


@pytest.mark.parametrize("seed", range(3))
def test_window_crossings_and_centroid_equal_the_numpy_formulation(seed):
    from types import SimpleNamespace

    from shadowcam.lab.shadow_time_methods import _centroid, _crossings, _removed_fraction

    rng = np.random.default_rng(seed)
    k, h, w, half = 9, 21, 27, 4
    window = np.round(rng.uniform(0.0, 1.0, (k, h, w)), 2).astype(np.float32)  # ties and equal samples
    window[half] *= 0.3
    window[rng.random(window.shape) < 0.1] = np.nan
    threshold = rng.uniform(0.2, 0.8, (h, w))
    threshold[0, :3] = np.nan
    start = rng.integers(-4, 300, (h, w))
    summary = SimpleNamespace(window=window, window_start=start, half_window=half)
    for got, expected in zip(_crossings(summary, threshold), _crossings_numpy(window, threshold, start, half)):
        np.testing.assert_array_equal(got, expected)
        assert np.isfinite(got).mean() > 0.3
    # the centroid's coverage is computed in its kernel; numpy's clipped fraction gives the same sums
    lit, noise = rng.uniform(0.5, 1.5, (h, w)), rng.uniform(0.01, 0.02, (h, w))
    coverage = _removed_fraction(window, lit)
    frames = start[None] + np.arange(k)[:, None, None]
    held = np.isfinite(coverage)
    total = np.where(held, coverage, 0.0).sum(axis=0)
    mean = np.where(held, coverage * frames, 0.0).sum(axis=0) / total
    time, _ = _centroid(window, lit, start, noise)
    np.testing.assert_allclose(time, mean, rtol=1e-12)
