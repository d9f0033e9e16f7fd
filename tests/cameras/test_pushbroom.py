"""Pushbroom: colours along the edge, linear between the pixel centres; uniform-time resampling."""

import numpy as np
import pytest

from shadowcam.cameras.pushbroom import assemble_pushbroom, resample_uniform_time, sample_along_edge


def test_sample_along_edge_interpolates_between_centres():
    image = np.zeros((6, 3, 3), np.float32)
    image[:, :, 0] = np.arange(6)[:, None]  # red = row index
    edge = np.array([2.5, 3.0, np.nan])  # 2.5 = centre of row 2; 3.0 = halfway rows 2 and 3
    out = sample_along_edge(image, edge)
    assert out.dtype == np.float32
    np.testing.assert_allclose(out[:2, 0], [2.0, 2.5])
    assert np.isnan(out[2]).all()


def test_assemble_and_resample():
    image = np.random.default_rng(0).random((8, 4, 3)).astype(np.float32)
    edges = np.array([[4.5] * 4, [3.5] * 4])
    broom = assemble_pushbroom(image, edges)
    np.testing.assert_allclose(broom[0], image[4])
    np.testing.assert_allclose(broom[1], image[3])
    times, uniform = resample_uniform_time(broom, np.array([0.0, 20.0]), step_s=5.0)
    np.testing.assert_allclose(times, [0, 5, 10, 15, 20])
    np.testing.assert_allclose(uniform[2], 0.5 * (image[4] + image[3]), rtol=1e-6)
    with pytest.raises(ValueError, match="step_s"):
        resample_uniform_time(broom, np.array([0.0, 20.0]), step_s=0)
