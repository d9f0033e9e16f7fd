"""Tests of shadowcam.io.luminance: the luminance straight from a Bayer mosaic equals that of its demosaic."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from shadowcam.io.decode import mosaic_image
from shadowcam.io.luminance import channel_mean, mosaic_luminance


def test_channel_mean_is_the_mean_over_channels():
    image = np.arange(2 * 3 * 3, dtype=np.float32).reshape(2, 3, 3)
    np.testing.assert_array_equal(channel_mean(image), image.mean(axis=-1, dtype=np.float32))
    with pytest.raises(ValueError, match="trailing channel axis"):
        channel_mean(np.zeros((4, 4)))


levels = st.sampled_from([
    ((256.0,) * 4, (4095.0,) * 4),  # one black and white level for the whole sensor
    ((512.0,) * 4, (16383.0,) * 4),  # 14-bit
    ((0.0,) * 4, (65535.0,) * 4),  # no headroom scaling (k = 1)
    ((500.0, 510.0, 510.0, 520.0), (4095.0,) * 4),  # per-channel blacks (green sites equal)
    ((0.0,) * 4, (4000.0, 4095.0, 4095.0, 3900.0)),  # per-channel whites
    ((500.0, 510.0, 530.0, 520.0), (4095.0,) * 4),  # the two green sites differ: the colour path
])


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(["RGGB", "BGGR", "GRBG", "GBRG"]), st.integers(3, 23), st.integers(3, 23), levels,
       st.integers(0, 2**31 - 1))
def test_mosaic_luminance_is_the_demosaics_channel_mean_bit_for_bit(pattern, rows, cols, level, seed):
    black, white = (np.array(v).reshape(2, 2) for v in level)
    mosaic = np.random.default_rng(seed).integers(0, int(white.max()) + 1, size=(rows, cols)).astype(np.uint16)
    got = mosaic_luminance(mosaic, cfa_pattern=pattern, black_sites=black, white_sites=white)
    want = channel_mean(mosaic_image(mosaic, cfa_pattern=pattern, black_sites=black, white_sites=white))
    assert got.dtype == np.float32 and got.shape == (rows, cols)
    np.testing.assert_array_equal(got, want)  # every pixel, borders included


def test_mosaic_luminance_of_a_flat_grey_field_is_its_level():
    # a white-balanced grey card: every site at 1/4 of the way from black to white
    mosaic = np.full((8, 10), 256 + (4095 - 256) // 4, dtype=np.uint16)
    got = mosaic_luminance(mosaic, cfa_pattern="RGGB", black_sites=np.full((2, 2), 256.0),
                           white_sites=np.full((2, 2), 4095.0))
    np.testing.assert_allclose(got, ((4095 - 256) // 4) / (4095 - 256), rtol=1e-6)


def test_mosaic_luminance_validates_its_input():
    levels = dict(cfa_pattern="RGGB", black_sites=np.zeros((2, 2)), white_sites=np.full((2, 2), 4095.0))
    with pytest.raises(ValueError, match="at least 3x3"):
        mosaic_luminance(np.zeros((2, 8), np.uint16), **levels)
    with pytest.raises(ValueError, match="integers"):
        mosaic_luminance(np.zeros((4, 4), np.float32), **levels)
