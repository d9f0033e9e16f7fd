"""Frame differencing: the band holds exactly the pixels the edge swept, widened by the margin."""

import numpy as np
import pytest

from shadowcam.outdoor.frame_difference import difference_band


def test_band_is_the_swept_rows_plus_margin():
    previous = np.ones((20, 10), np.float32)
    previous[12:] = 0
    current = np.ones_like(previous)
    current[9:] = 0  # the edge climbed from row 12 to row 9
    band = difference_band(previous, current, margin=2)
    expected = np.zeros_like(band)
    expected[7:14] = True
    assert np.array_equal(band, expected)


def test_rises_and_small_drops_are_not_in_the_band_and_sky_is_excluded():
    previous = np.full((6, 6), 0.5, np.float32)
    current = previous.copy()
    current[0] = 0.9  # brighter: not a shadow arriving
    current[1] = 0.4  # small drop (noise)
    current[4] = 0.0
    valid = np.ones((6, 6), bool)
    valid[4, :3] = False
    band = difference_band(previous, current, valid=valid, margin=0)
    assert band[4, 3:].all() and not band[4, :3].any() and band.sum() == 3
    with pytest.raises(ValueError, match="min_drop"):
        difference_band(previous, current, min_drop=0)
