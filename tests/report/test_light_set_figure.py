"""The several-lights figure: a row per light, time maps beside their ground truth."""

import numpy as np
import pytest

from shadowcam.report.light_set_figure import light_set_mosaic


def test_rows_per_light_and_shared_scale_per_sweep():
    s, n_lights, h, w = 2, 3, 6, 5
    truths = np.broadcast_to(np.arange(n_lights, dtype=float)[None, :, None, None] * 10 + 5,
                             (s, n_lights, h, w)).copy()
    times = truths.copy()
    times[0, 1] = np.nan  # flagged
    views = np.ones((n_lights, 4, 7, 3))
    out = light_set_mosaic(times, truths, views)
    tile_h, tile_w = 6, 7
    assert out.shape == (n_lights * (tile_h + 2) - 2, 5 * (tile_w + 2) - 2, 3)
    # estimated == exact where timed: the first two tiles of light 0 are identical
    a, b = out[0:h, 0:w], out[0:h, tile_w + 2:tile_w + 2 + w]
    np.testing.assert_array_equal(a, b)
    # one scale per sweep: lights' truth tiles differ in colour
    assert not np.array_equal(out[0, tile_w + 2], out[2 * (tile_h + 2), tile_w + 2])
    # the flagged map is drawn in the hole colour, not as its truth
    row1 = tile_h + 2
    assert not np.array_equal(out[row1:row1 + h, 0:w], out[row1:row1 + h, tile_w + 2:tile_w + 2 + w])
    with pytest.raises(ValueError, match="same L"):
        light_set_mosaic(times, truths, views[:2])
