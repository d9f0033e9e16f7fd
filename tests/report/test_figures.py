"""Tests of shadowcam.report.figures and the accuracy table of ``shadowcam report-figures``."""

import matplotlib.image
import numpy as np
import pytest

from shadowcam.report import figures
from shadowcam.report.dataset_report import csv_to_html

GREY_TOL = 1.5 / 255  # one 8-bit quantisation step (plus rounding)


def canvas_rgb(figure):
    """Rendered figure as a (rows, cols, 3) float array in [0, 1]."""
    figure.canvas.draw()
    return np.asarray(figure.canvas.buffer_rgba())[..., :3] / 255.0


def pixel_of(figure, axes, row, col):
    """Canvas (row, col) of the centre of data pixel (row, col) shown by `axes`."""
    x, y = axes.transData.transform((col, row))
    height = figure.canvas.get_width_height()[1]
    return int(round(height - y)), int(round(x))


@pytest.fixture
def time_map():
    rng = np.random.default_rng(0)
    times = rng.uniform(0, 23, size=(20, 30)).astype(np.float32)
    times[5:10, 10:20] = np.nan
    return times


def test_saved_png_has_figure_size_in_pixels(tmp_path, time_map):
    path = figures.save_png(figures.time_map_figure(time_map, size=(6.0, 5.0)),
                            tmp_path / "t.png")
    image = matplotlib.image.imread(path)
    assert image.shape[:2] == (5 * figures.FIGURE_DPI, 6 * figures.FIGURE_DPI)


def test_time_map_draws_nan_grey_and_values_in_colour(time_map):
    time_map[0, 0] = 0.0  # the colour-range minimum: first colour of viridis
    figure = figures.time_map_figure(time_map, vmin=0.0, vmax=23.0)
    axes = figure.axes[0]
    rgb = canvas_rgb(figure)
    hole = rgb[pixel_of(figure, axes, 7, 15)]
    np.testing.assert_allclose(hole, figures.NAN_GREY, atol=GREY_TOL)
    lowest = rgb[pixel_of(figure, axes, 0, 0)]
    np.testing.assert_allclose(lowest, matplotlib.colormaps["viridis"](0.0)[:3], atol=GREY_TOL)
    assert len(figure.axes) == 2  # image + colour bar


def test_figures_use_the_preview_tone_map():
    from shadowcam.io.images import srgb_encode, tone_map

    image = np.zeros((4, 4, 3), np.float32)
    image[0, 0] = 2.0  # the brightest value maps to white
    image[1, 1] = 0.5
    image[2, 2, 1] = np.nan
    rgb = tone_map(image, percentile=100)
    assert rgb.shape == (4, 4, 3)
    np.testing.assert_allclose(rgb[0, 0], 1.0)
    np.testing.assert_allclose(rgb[1, 1], srgb_encode(0.25), rtol=1e-6)
    np.testing.assert_allclose(rgb[2, 2], figures.NAN_GREY)
    np.testing.assert_allclose(rgb[3, 3], 0.0)


def test_primal_figure_keeps_row_zero_at_top():
    image = np.zeros((40, 40, 3), np.float32)
    image[:4, :4] = 1.0  # bright top-left corner
    figure = figures.primal_figure(image, size=(4.0, 4.0))
    axes = figure.axes[0]
    rgb = canvas_rgb(figure)
    np.testing.assert_allclose(rgb[pixel_of(figure, axes, 1, 1)], 1.0, atol=GREY_TOL)
    np.testing.assert_allclose(rgb[pixel_of(figure, axes, 38, 38)], 0.0, atol=GREY_TOL)
    assert figure.canvas.get_width_height() == (400, 400)


def test_dual_view_next_to_reciprocal():
    dual = np.ones((24, 24, 3), np.float32)
    dual[10:14, 10:14] = np.nan  # a hole
    reciprocal = np.ones((24, 24, 3), np.float32)
    figure = figures.dual_view_figure(dual, reciprocal=reciprocal)
    assert figure.canvas.get_width_height() == (1000, 500)
    left, right = figure.axes
    rgb = canvas_rgb(figure)
    np.testing.assert_allclose(rgb[pixel_of(figure, left, 12, 12)], figures.NAN_GREY,
                               atol=GREY_TOL)
    np.testing.assert_allclose(rgb[pixel_of(figure, right, 12, 12)], 1.0, atol=GREY_TOL)
    alone = figures.dual_view_figure(dual)
    assert alone.canvas.get_width_height() == (500, 500) and len(alone.axes) == 1


def test_error_histogram_counts_every_finite_value():
    rng = np.random.default_rng(1)
    errors = {"u": rng.normal(0, 0.3, 1000), "v": np.array([np.nan, 0.1, 5.0])}
    figure = figures.error_histogram_figure(errors, limit=3.0, bins=30)
    axes = figure.axes[0]
    assert figure.canvas.get_width_height() == (600, 400)
    labels = [text.get_text() for text in axes.get_legend().get_texts()]
    assert labels[0].startswith("u: n=1000")
    assert labels[1].startswith("v: n=2") and labels[1].endswith("|e|>3: 1")


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: figures.time_map_figure(np.zeros((2, 2, 2))), "times"),
        (lambda: figures.primal_figure(np.zeros((2, 2, 2))), "image"),
        (lambda: figures.error_histogram_figure({}), "errors"),
        (lambda: figures.primal_figure(np.zeros((2, 2)), size=(0, 1)), "size"),
    ],
)
def test_invalid_input_names_the_parameter(call, name):
    with pytest.raises(ValueError, match=name):
        call()


def test_accuracy_csv_becomes_html_table(tmp_path):
    path = tmp_path / "accuracy.csv"
    path.write_text("metric,sweep,value\nmedian_abs_error,u,0.12\nwithin_1,v,<99%>\n")
    page = csv_to_html(path, title="accuracy")
    assert page.count("<tr>") == 3
    assert "<th>metric</th>" in page and "<td>0.12</td>" in page
    assert "&lt;99%&gt;" in page  # cells are escaped


def test_reciprocal_panel_is_the_truth_resampled_onto_the_dual_grid():
    import xarray as xr

    from shadowcam.report.dataset_report import dual_view_report_figure

    reciprocal = np.full((40, 40, 3), 0.1, np.float32)
    reciprocal[18:23, 8:13] = 1.0  # a bright square centred at mask-plane (t_u, t_v) = (10, 20)
    truth = xr.Dataset({"reciprocal": (("v", "u", "channel"), reciprocal),
                        "dual_cam_visible": (("v", "u"), np.ones((40, 40), bool))})
    # uniform model, two dual pixels per frame: the point lands at (u, v) = (20.5, 40.5)
    coords = xr.Dataset(attrs={"method": "uniform", "model": "uniform", "scale": [2.0, 2.0],
                               "offset": [0.5, 0.5], "model_choice": "uniform: assumed",
                               "projection": "cross-slit"})
    dual = xr.Dataset({"dual_view": (("v", "u", "channel"), np.full((80, 80, 3), 0.5, np.float32)),
                       "coverage": (("v", "u"), np.ones((80, 80), bool))})
    figure = dual_view_report_figure(dual, dual_coords=coords, truth=truth)
    left, right = figure.axes[:2]
    shown = np.asarray(right.images[0].get_array())
    assert shown.shape[:2] == np.asarray(left.images[0].get_array()).shape[:2] == (80, 80)
    rows, cols = np.nonzero(shown[..., 0] > 0.9 * shown[..., 0].max())
    assert abs(rows.mean() - 40.5) <= 1 and abs(cols.mean() - 20.5) <= 1
    assert "uniform" in left.get_title() and "coverage" in left.get_title()
    assert "cross-slit shadow camera" in left.get_title()
    planned = dual_view_report_figure(dual, dual_coords=coords, truth=truth,
                                      camera_kind="orthographic")
    assert "orthographic shadow camera" in planned.axes[0].get_title()


def test_primal_figure_shows_no_demosaic_colour_fringes_on_a_grey_edge():
    from shadowcam.io.cfa import demosaic_bilinear

    rows, cols = np.mgrid[0:40, 0:40]
    grey = np.where(cols + 0.4 * rows > 24, 3000, 300).astype(np.uint16)  # slanted grey edge
    rgb = demosaic_bilinear(grey, pattern="RGGB", max_value=4095)

    def fringe(image):  # largest departure from grey, relative to white
        image = np.asarray(image, dtype=np.float64)
        return np.abs(image - image.mean(-1, keepdims=True)).max() / image.max()

    assert fringe(rgb) > 0.3  # bilinear demosaic colours the edge
    shown = figures.primal_figure(rgb).axes[0].images[0].get_array()
    assert fringe(shown) < 0.02
