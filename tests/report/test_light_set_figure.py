"""The several-lights figure: a row per light, time maps beside their exact times, dual views."""

import numpy as np
import pytest
from matplotlib import colormaps

from shadowcam.io.images import HOLE_COLOUR
from shadowcam.report.figures import NAN_GREY
from shadowcam.report.light_set_figure import light_set_figure, light_titles


def _pixels(figure, axes):
    """RGB (0-1) of the rendered figure inside `axes`, rows top to bottom."""
    figure.canvas.draw()
    rgba = np.asarray(figure.canvas.buffer_rgba(), np.float64)[..., :3] / 255
    x0, y0, x1, y1 = axes.get_window_extent().extents
    height = rgba.shape[0]
    return rgba[int(np.ceil(height - y1)):int(height - y0), int(np.ceil(x0)):int(x1)]


def _at(figure, axes, fx, fy):
    """RGB at fractions (`fx` right, `fy` down) of `axes`' area."""
    block = _pixels(figure, axes)
    return block[int(fy * (block.shape[0] - 1)), int(fx * (block.shape[1] - 1))]


def _scene(s=2, n_lights=3, h=6, w=5):
    truths = np.broadcast_to(np.arange(n_lights, dtype=float)[None, :, None, None] * 10 + 5,
                             (s, n_lights, h, w)).copy()
    truths[1:] += 2.0  # the v sweep's scale differs from the u sweep's
    views = np.ones((n_lights, 4, 7, 3))
    return truths, views


def test_rows_per_light_titles_axes_and_one_colour_bar_per_sweep():
    truths, views = _scene()
    figure = light_set_figure(truths, truths, views, titles=light_titles(["point", "point", "tube"],
                                                                        axes=[None, None, "v"]),
                              truth_views=views)
    bars = [a for a in figure.axes if a.get_ylabel() == "shadow time (frame)"]
    panels = [a for a in figure.axes if a not in bars]
    assert len(bars) == 2 and [b.get_title() for b in bars] == ["u sweep", "v sweep"]
    assert len(panels) == 3 * (2 * 2 + 2)
    titles = [a.get_title() for a in panels]
    for light in ("point 0", "point 1", "tube along e_v"):
        for sweep in "uv":
            assert f"{light}:\n{sweep} estimated" in titles and f"{light}:\n{sweep} exact" in titles
        assert f"{light}:\ndual view" in titles and f"{light}:\nfrom exact times" in titles
    dual = [a for a in panels if a.get_title().endswith("dual view")]
    assert dual[-1].get_xlabel() == "u (dual px)" and all(a.get_ylabel() == "v (dual px)" for a in dual)
    times = [a for a in panels if a.get_title().endswith("estimated")]
    assert all(a.get_ylabel() == "y (px)" for a in times)
    assert times[-1].get_xlabel() == "x (px)"
    # the colour bars span the rows: as tall as the three rows together
    assert bars[0].get_position().height > 2.5 * times[0].get_position().height
    # default scale: the exact times' range per sweep; with frames, the sweep's frames
    assert bars[0].get_ylim() == pytest.approx((5, 25)) and bars[1].get_ylim() == pytest.approx((7, 27))
    figure = light_set_figure(truths, truths, views, titles=["a", "b", "c"], frames=(20, 30))
    bars = [a for a in figure.axes if a.get_ylabel() == "shadow time (frame)"]
    assert bars[0].get_ylim() == pytest.approx((0, 19)) and bars[1].get_ylim() == pytest.approx((0, 29))
    # a light whose dip a sweep does not show says so
    figure = light_set_figure(truths, truths, views, titles=["a", "b", "c"], shown=[[1, 1, 1], [1, 1, 0]])
    titles = [a.get_title() for a in figure.axes]
    assert "c:\nv dip not shown" in titles and "c:\nu estimated" in titles and "c:\nv estimated" not in titles


def test_flagged_pixels_are_grey_and_times_take_their_colour_bar_colour():
    truths, views = _scene(s=1, n_lights=2, h=4, w=4)
    times = truths.copy()
    times[0, 1, :, :2] = np.nan  # light 1: the left half flagged
    views[0, :, :3] = np.nan  # a hole in light 0's dual view
    figure = light_set_figure(times, truths, views, titles=["point 0", "point 1"], sweeps=("u",))
    by_title = {a.get_title(): a for a in figure.axes}
    flagged = _at(figure, by_title["point 1:\nu estimated"], 0.2, 0.5)
    np.testing.assert_allclose(flagged, NAN_GREY, atol=1.5 / 255)
    times[0, 0, 0, 0] = 10.0  # mid-scale
    figure = light_set_figure(times, truths, views, titles=["point 0", "point 1"], sweeps=("u",))
    by_title = {a.get_title(): a for a in figure.axes}
    bar = next(a for a in figure.axes if a.get_ylabel() == "shadow time (frame)")
    column = _pixels(figure, bar)
    column = column[:, column.shape[1] // 2]  # top (15 frames) to bottom (5 frames)
    value = 15.0 - 10.0 * np.arange(column.shape[0]) / (column.shape[0] - 1)
    # each time's colour is the colour bar's at that time (within 2 % of the scale)
    for title, fx, fy, frames in (("point 1:\nu estimated", 0.8, 0.5, 15.0),
                                  ("point 0:\nu exact", 0.5, 0.5, 5.0),
                                  ("point 0:\nu estimated", 0.1, 0.1, 10.0)):
        colour = _at(figure, by_title[title], fx, fy)
        np.testing.assert_allclose(colour, colormaps["viridis"]((frames - 5.0) / 10.0)[:3], atol=2 / 255)
        nearest = value[np.argmin(np.abs(column - colour).sum(axis=1))]
        assert nearest == pytest.approx(frames, abs=0.2)
    scale = colormaps["viridis"](np.linspace(0, 1, 256))[:, :3]
    assert np.min(np.abs(scale - np.asarray(NAN_GREY)).max(axis=1)) > 0.1
    hole = _at(figure, by_title["point 0:\ndual view"], 0.2, 0.5)
    np.testing.assert_allclose(hole, HOLE_COLOUR, atol=1.5 / 255)


def test_shapes_and_names_must_match():
    truths, views = _scene()
    with pytest.raises(ValueError, match="same L"):
        light_set_figure(truths, truths, views[:2], titles=["a", "b", "c"])
    with pytest.raises(ValueError, match="titles"):
        light_set_figure(truths, truths, views, titles=["a", "b"])
    with pytest.raises(ValueError, match="truth_views"):
        light_set_figure(truths, truths, views, titles=["a", "b", "c"], truth_views=views[:, :2])
    with pytest.raises(ValueError, match="frames"):
        light_set_figure(truths, truths, views, titles=["a", "b", "c"], frames=(10,))
    with pytest.raises(ValueError, match="shown"):
        light_set_figure(truths, truths, views, titles=["a", "b", "c"], shown=[[1, 1, 1]])
    with pytest.raises(ValueError, match="axes"):
        light_titles(["point"], axes=["u", "v"])
