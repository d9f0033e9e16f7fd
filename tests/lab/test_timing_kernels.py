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
