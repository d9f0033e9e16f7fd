"""Edge-aware plane fit: exact on planes, sharp at discontinuities, averages noise."""

import numpy as np
import pytest

from shadowcam.lab.edge_refine import refine_times


def test_plane_is_reproduced_exactly_including_borders():
    rows, cols = np.mgrid[0:20, 0:30]
    plane = 3.0 + 0.4 * cols - 0.25 * rows
    refined, std = refine_times(plane, np.full(plane.shape, 0.2))
    np.testing.assert_allclose(refined, plane, atol=1e-9)
    assert np.all(std < 0.2)


def test_depth_discontinuity_stays_sharp():
    rows, cols = np.mgrid[0:20, 0:30]
    times = np.where(cols < 15, 0.5 * cols, 40.0 + 0.5 * cols)
    refined, _ = refine_times(times, np.full(times.shape, 0.1))
    np.testing.assert_allclose(refined, times, atol=1e-6)


def test_staircase_quantisation_is_averaged_out():
    # a pixel's own estimate rounds to the frame centre: floor(t) + 0.5
    rows, cols = np.mgrid[0:40, 0:40]
    truth = 0.5 * cols + 0.13 * rows
    staircase = np.floor(truth) + 0.5
    refined, _ = refine_times(staircase, np.full(truth.shape, 0.15))
    inner = (slice(4, -4), slice(4, -4))
    assert np.percentile(np.abs(staircase - truth)[inner], 95) > 0.4
    assert np.percentile(np.abs(refined - truth)[inner], 95) < 0.1


def test_noise_is_reduced_and_missing_pixels_stay_missing():
    rng = np.random.default_rng(0)
    rows, cols = np.mgrid[0:40, 0:40]
    truth = 0.3 * cols
    noisy = truth + rng.normal(0, 0.4, truth.shape)
    noisy[10, 10] = np.nan
    refined, _ = refine_times(noisy.astype(np.float32), np.full(truth.shape, 0.4))
    assert refined.dtype == np.float32
    assert np.isnan(refined[10, 10])
    inner = (slice(4, -4), slice(4, -4))
    assert np.nanstd((refined - truth)[inner]) < 0.4 / 3


def test_rejects_bad_parameters():
    with pytest.raises(ValueError, match="radius"):
        refine_times(np.zeros((4, 4)), 1.0, radius=0)
    with pytest.raises(ValueError, match="range_sigma"):
        refine_times(np.zeros((4, 4)), 1.0, range_sigma=0)
    with pytest.raises(ValueError, match="time"):
        refine_times(np.zeros(4), 1.0)
