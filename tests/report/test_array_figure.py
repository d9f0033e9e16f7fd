"""The camera-array figure: views and reciprocal renders tiled in the array's layout."""

import numpy as np
import pytest

from shadowcam.report.array_figure import array_mosaic


def test_tiles_sit_in_their_array_rows_and_columns():
    n, m, h, w = 2, 3, 5, 7
    views = np.zeros((n, m, h, w, 3))
    for i in range(n):
        for j in range(m):
            views[i, j] = 1 + i * m + j  # a distinct grey per camera
    out = array_mosaic(views, views[::-1])
    assert out.shape == (n * (h + 2) - 2, 2 * m * (w + 2) + 4, 3)
    left = [out[i * (h + 2), j * (w + 2), 0] for i in range(n) for j in range(m)]
    # brighter camera index -> brighter tile, in row-major order
    assert np.all(np.diff(left) > 0)
    right0 = m * (w + 2) + 4
    right = [out[i * (h + 2), right0 + j * (w + 2), 0] for i in range(n) for j in range(m)]
    assert right[:m] == left[m:] and right[m:] == left[:m]


def test_holes_and_shape_mismatch():
    views = np.ones((1, 1, 4, 4, 3))
    views[0, 0, 0, 0] = np.nan
    out = array_mosaic(views, np.ones_like(views))
    assert tuple(out[0, 0]) != tuple(out[1, 1])
    with pytest.raises(ValueError, match="views and reciprocal"):
        array_mosaic(views, np.ones((1, 2, 4, 4, 3)))
