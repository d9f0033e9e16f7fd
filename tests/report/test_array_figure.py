"""The camera-array figure: views and reciprocal renders in the array's layout, on dual axes."""

import numpy as np
import pytest

from shadowcam.io.images import HOLE_COLOUR, tone_map
from shadowcam.report.array_figure import array_figure


def _panel_pixels(figure, axes):
    """RGB (0-1) of the rendered figure inside `axes`' image area."""
    figure.canvas.draw()
    rgba = np.asarray(figure.canvas.buffer_rgba(), np.float64)[..., :3] / 255
    x0, y0, x1, y1 = axes.get_window_extent().extents
    height = rgba.shape[0]
    inset = 3  # away from the spines
    return rgba[int(height - y1) + inset:int(height - y0) - inset, int(x0) + inset:int(x1) - inset]


def test_panels_sit_in_their_array_rows_and_columns_with_labelled_dual_axes():
    n, m, h, w = 2, 3, 5, 7
    views = np.zeros((n, m, h, w, 3))
    for i in range(n):
        for j in range(m):
            views[i, j] = 1 + i * m + j  # a distinct grey per camera
    figure = array_figure(views, views[::-1])
    assert len(figure.axes) == 2 * n * m
    # in reading order: array row by array row, the m views then the m reciprocal renders
    spec = [a.get_subplotspec() for a in figure.axes]
    axes = [a for _, a in sorted(zip([(s.rowspan.start, s.colspan.start) for s in spec], figure.axes))]
    assert [a.get_title() for a in axes[:m]] == [f"camera (0, {j})" for j in range(m)]
    assert [a.get_title() for a in axes[m:2 * m]] == [f"reciprocal (0, {j})" for j in range(m)]
    assert all(a.get_xlabel() == "u (dual px)" for a in axes[-2 * m:])
    assert axes[0].get_ylabel() == "v (dual px)" and axes[m].get_ylabel() == "v (dual px)"
    greys = np.array([np.median(_panel_pixels(figure, a)[..., 0]) for a in axes])
    left = np.concatenate([greys[i * 2 * m:i * 2 * m + m] for i in range(n)])
    right = np.concatenate([greys[i * 2 * m + m:(i + 1) * 2 * m] for i in range(n)])
    # one white point per block: brighter camera index -> brighter panel, in row-major order
    assert np.all(np.diff(left) > 0)
    # the reciprocal block is the views with the array rows swapped
    np.testing.assert_allclose(right, np.concatenate([left[m:], left[:m]]), atol=1 / 255)
    expected = tone_map(np.array([[[6.0, 6.0, 6.0]]]), scale=None, percentile=99.5)[0, 0, 0]
    assert left[-1] == pytest.approx(expected, abs=2 / 255)


def test_holes_are_drawn_in_the_hole_colour_and_shapes_must_match():
    views = np.ones((1, 1, 4, 4, 3))
    views[0, 0] = np.nan
    figure = array_figure(views, np.ones_like(views))
    hole = np.median(_panel_pixels(figure, figure.axes[0]).reshape(-1, 3), axis=0)
    np.testing.assert_allclose(hole, HOLE_COLOUR, atol=1.5 / 255)
    with pytest.raises(ValueError, match="views and reciprocal"):
        array_figure(views, np.ones((1, 2, 4, 4, 3)))
