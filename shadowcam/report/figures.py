"""Report figures: matplotlib (Agg, no pyplot state) renderings of shadowcam products.

Every function takes arrays and returns a :class:`matplotlib.figure.Figure` of a fixed
pixel size (``size`` inches x :data:`FIGURE_DPI`); :func:`save_png` writes one. Linear
radiance is shown through the tone map of the PNG previews
(:func:`shadowcam.io.images.tone_map`, white point at :data:`WHITE_PERCENTILE`); pixels
without a value (NaN) are drawn in :data:`NAN_GREY`.

Offers
------
FIGURE_DPI : dots per inch of every figure (image size = size x FIGURE_DPI pixels).
NAN_GREY : RGB colour of pixels without a value.
WHITE_PERCENTILE : percentile of the brightest channel shown as white.
DUAL_AXES : axis labels of the dual-view panels of many-panel figures.
FRINGE_MEDIAN : median window of the primal figure's colour-fringe suppression.
suppress_colour_fringes : median of the colour differences (demosaic false colour), for display.
primal_figure : the camera (primal) image.
time_map_figure : a shadow-time map with colour bar.
dual_view_figure : the dual view, next to the ground-truth reciprocal view if given.
viewpoints_figure : per viewpoint, the dual view beside its reciprocal render (paper Fig. 13).
error_histogram_figure : histogram of shadow-time errors per sweep.
study_factor_figure : the simulation study's error curves against one factor (paper Fig. 5).
save_png : write a figure as PNG (exact pixel size).
"""

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib import colormaps
from matplotlib.figure import Figure

from shadowcam._shared.validation import check_positive
from shadowcam.io.images import HOLE_COLOUR, tone_map

FIGURE_DPI = 100
NAN_GREY = HOLE_COLOUR
WHITE_PERCENTILE = 99.5
#: axis labels of a small dual-view panel (u, v)
DUAL_AXES = ("u (dual px)", "v (dual px)")
#: median window of the colour differences in the primal figure (demosaic fringes)
FRINGE_MEDIAN = 5


def _new_figure(size):
    width, height = size
    if not (width > 0 and height > 0):
        raise ValueError(f"size must be two positive numbers (inches); got {size!r}")
    figure = Figure(figsize=(width, height), dpi=FIGURE_DPI)
    FigureCanvasAgg(figure)
    return figure


def _show_image(axes, rgb, title, *, xlabel="col", ylabel="row"):
    axes.imshow(rgb, interpolation="nearest", origin="upper")
    axes.set_title(title)
    axes.set_xlabel(xlabel)
    axes.set_ylabel(ylabel)


def _show_times(axes, times, *, vmin, vmax, cmap="viridis"):
    """Draw a (rows, cols) time map on `axes`, NaN in :data:`NAN_GREY`; return the image
    (the mappable of its colour bar)."""
    colours = colormaps[cmap].with_extremes(bad=NAN_GREY)
    return axes.imshow(np.ma.masked_invalid(times), cmap=colours, vmin=vmin, vmax=vmax,
                       interpolation="nearest", origin="upper")


def _small_panel(axes, rgb, title, *, xlabel=None, ylabel=None):
    """A small panel of a many-panel figure: `rgb` (rows, cols, 3) in [0, 1] (or a drawn
    image when None), small title, tick labels and axis labels (None = no label)."""
    if rgb is not None:
        axes.imshow(rgb, interpolation="nearest", origin="upper")
    axes.set_title(title, fontsize="small")
    axes.tick_params(labelsize="x-small")
    if xlabel:
        axes.set_xlabel(xlabel, fontsize="small")
    if ylabel:
        axes.set_ylabel(ylabel, fontsize="small")


def suppress_colour_fringes(image, *, size=FRINGE_MEDIAN):
    """Median-filter the colour differences R - G and B - G of an RGB image (Freeman's method).

    Bilinear demosaicing colours sharp grey edges (false colour along the edge, one to
    two pixels wide); a median of the colour differences removes such narrow colour
    while green, which carries the detail, is kept. For display only.

    Parameters
    ----------
    image : (rows, cols, 3) ndarray
        Linear RGB image (other shapes are returned as they are).
    size : int, optional
        Side of the median window (pixels); 0 or 1 returns `image` unchanged.

    Returns
    -------
    ndarray, same shape, float32
    """
    from scipy.ndimage import median_filter

    image = np.asarray(image, dtype=np.float32)
    if image.ndim != 3 or image.shape[2] != 3 or int(size) <= 1:
        return image
    out = image.copy()
    green = image[..., 1]
    for channel in (0, 2):
        difference = np.nan_to_num(image[..., channel] - green)
        out[..., channel] = green + median_filter(difference, size=int(size), mode="nearest")
    return np.where(np.isnan(image), np.nan, out)


def primal_figure(image, *, title="primal (camera) image", fringe_median=FRINGE_MEDIAN, size=(5.0, 5.0)):
    """Figure of the camera image, demosaic colour fringes suppressed for display.

    Parameters
    ----------
    image : (rows, cols) or (rows, cols, 1|3) ndarray
        Linear camera image (e.g. the unshadowed reference frame).
    title : str, optional
    fringe_median : int, optional
        Window of :func:`suppress_colour_fringes` (0 = show the image as it is).
    size : (float, float), optional
        Figure width, height in inches (pixels = inches x :data:`FIGURE_DPI`).

    Returns
    -------
    matplotlib.figure.Figure
    """
    rgb = tone_map(suppress_colour_fringes(image, size=fringe_median), percentile=WHITE_PERCENTILE)
    figure = _new_figure(size)
    _show_image(figure.add_subplot(), rgb, title)
    figure.tight_layout()
    return figure


def time_map_figure(times, *, title="shadow time", label="shadow time (frame)",
                    vmin=None, vmax=None, cmap="viridis", size=(6.0, 5.0)):
    """Figure of a per-pixel time map with a colour bar; NaN drawn grey.

    Parameters
    ----------
    times : (rows, cols) ndarray
        Times (e.g. frames); NaN where there is no reliable time.
    title, label : str, optional
        Axes title and colour-bar label.
    vmin, vmax : float, optional
        Colour range; default the range of the finite values.
    cmap : str, optional
        Matplotlib colour map name.
    size : (float, float), optional
        Figure width, height in inches.

    Returns
    -------
    matplotlib.figure.Figure
    """
    times = np.asarray(times)
    if times.ndim != 2 or min(times.shape) < 1:
        raise ValueError(f"times must be a (rows, cols) array; got shape {times.shape}")
    if not np.issubdtype(times.dtype, np.number):
        raise ValueError(f"times must be numeric, got dtype {times.dtype}")
    finite = times[np.isfinite(times)]
    if vmin is None:
        vmin = float(finite.min()) if finite.size else 0.0
    if vmax is None:
        vmax = float(finite.max()) if finite.size else 1.0
    figure = _new_figure(size)
    axes = figure.add_subplot()
    shown = _show_times(axes, times, vmin=vmin, vmax=vmax, cmap=cmap)
    axes.set_title(title)
    axes.set_xlabel("col")
    axes.set_ylabel("row")
    figure.colorbar(shown, ax=axes, label=label)
    figure.tight_layout()
    return figure


def dual_view_figure(dual_view, *, reciprocal=None, title="dual view (shadow camera)",
                     reciprocal_title="ground-truth reciprocal view", note=None, size=None):
    """Figure of the dual view, next to the ground-truth reciprocal view if given.

    Both panels must be on the same dual grid (pixel (v, u) of one is pixel (v, u)
    of the other). Each panel is scaled to its own white point: the two views
    differ photometrically (the camera and light fall-off terms swap), so only
    geometry is compared.

    Parameters
    ----------
    dual_view : (v, u) or (v, u, 1|3) ndarray
        Linear dual view; NaN = hole (drawn grey).
    reciprocal : (v, u) or (v, u, 1|3) ndarray, optional
        Ground-truth reciprocal view (rendered from the light) on the same grid.
    title, reciprocal_title : str, optional
        Panel titles.
    note : str, optional
        Text under the panels (e.g. which dual model and why), wrapped.
    size : (float, float), optional
        Figure width, height in inches; default 5 inches per panel by 5 (5.6 with a `note`).

    Returns
    -------
    matplotlib.figure.Figure
    """
    panels = [(title, tone_map(dual_view, percentile=WHITE_PERCENTILE))]
    if reciprocal is not None:
        if np.shape(reciprocal)[:2] != np.shape(dual_view)[:2]:
            raise ValueError(f"reciprocal must be on the dual grid {np.shape(dual_view)[:2]}; "
                             f"got shape {np.shape(reciprocal)}")
        panels.append((reciprocal_title, tone_map(reciprocal, percentile=WHITE_PERCENTILE)))
    figure = _new_figure(size or (5.0 * len(panels), 5.6 if note else 5.0))
    for index, (panel_title, rgb) in enumerate(panels, start=1):
        _show_image(figure.add_subplot(1, len(panels), index), rgb, panel_title,
                    xlabel="u (dual column, dual px)", ylabel="v (dual row, dual px)")
    bottom = 0.0
    if note:
        import textwrap

        lines = textwrap.wrap(note, width=int(16 * figure.get_figwidth()))
        figure.text(0.01, 0.01, "\n".join(lines), fontsize="small", va="bottom", ha="left")
        bottom = min(0.4, 0.03 + 0.032 * len(lines) * 5.6 / figure.get_figheight())
    figure.tight_layout(rect=(0, bottom, 1, 0.97))
    return figure


def viewpoints_figure(rows, *, size=None):
    """Paper Fig. 13's layout: one row per viewpoint, its dual view beside its ground truth.

    Parameters
    ----------
    rows : sequence of (str, ndarray, ndarray or None)
        In reading order: ``(title, dual_view, reciprocal)`` with the (v, u[, channel])
        linear dual view (NaN = hole) and the reciprocal render on the same grid (None =
        no ground truth). Each panel is scaled to its own white point.
    size : (float, float), optional
        Default 3.2 inches per panel.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not rows:
        raise ValueError("rows: expected at least one viewpoint")
    columns = 2 if any(r[2] is not None for r in rows) else 1
    figure = _new_figure(size or (3.4 * columns, 3.3 * len(rows)))
    for index, (title, dual, reciprocal) in enumerate(rows):
        panels = [(f"{title}: dual view", dual)]
        if reciprocal is not None:
            if np.shape(reciprocal)[:2] != np.shape(dual)[:2]:
                raise ValueError(f"rows[{index}]: reciprocal must be on the dual grid {np.shape(dual)[:2]}; "
                                 f"got shape {np.shape(reciprocal)}")
            panels.append((f"{title}: reciprocal render", reciprocal))
        for column, (panel_title, image) in enumerate(panels, start=1):
            _show_image(figure.add_subplot(len(rows), columns, index * columns + column),
                        tone_map(image, percentile=WHITE_PERCENTILE), panel_title,
                        xlabel="u (dual column, dual px)", ylabel="v (dual row, dual px)")
    figure.tight_layout()
    return figure


def error_histogram_figure(errors, *, limit=3.0, bins=60, unit="frame", size=(6.0, 4.0)):
    """Histogram of errors (estimate - ground truth), one outline per series, log counts.

    Parameters
    ----------
    errors : mapping of str to (N,) ndarray
        Series name (e.g. sweep) -> errors; non-finite values are ignored.
    limit : float, optional
        Histogram range is [-limit, limit]; values outside are counted in the legend.
    bins : int, optional
    unit : str, optional
        Unit of the errors, for the axis label.
    size : (float, float), optional
        Figure width, height in inches.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not hasattr(errors, "items") or not errors:
        raise ValueError("errors must be a non-empty mapping of name -> 1-D array")
    check_positive(limit, "limit")
    if int(bins) < 1:
        raise ValueError(f"bins must be a positive integer; got {bins!r}")
    figure = _new_figure(size)
    axes = figure.add_subplot()
    edges = np.linspace(-limit, limit, int(bins) + 1)
    for name, values in errors.items():
        values = np.asarray(values, dtype=np.float64).ravel()
        values = values[np.isfinite(values)]
        if values.size == 0:
            axes.plot([], [], label=f"{name}: no pixels")
            continue
        outside = np.count_nonzero(np.abs(values) > limit)
        label = (f"{name}: n={values.size}, median |e|={np.median(np.abs(values)):.3f}, "
                 f"|e|>{limit:g}: {outside}")
        axes.hist(values, bins=edges, histtype="step", linewidth=1.5, label=label)
    axes.set_xlabel(f"error ({unit})")
    axes.set_yscale("log")  # the tails (edge pixels, outliers) matter as much as the peak
    axes.set_ylabel("pixels")
    axes.legend(fontsize="small")
    figure.tight_layout()
    return figure


def save_png(figure, path):
    """Write `figure` to `path` as PNG (size = figure inches x FIGURE_DPI); return the Path."""
    path = Path(path)
    figure.savefig(path, format="png", dpi=FIGURE_DPI)
    return path


def study_factor_figure(values, *, whole, masked, coord_error, factor, unit="",
                        size=(6.0, 4.0)):
    """Error curves of the simulation study against one factor (the paper's Fig. 5).

    Parameters
    ----------
    values : (L,) ndarray
        The factor's levels (NaN entries are skipped).
    whole, masked : (L,) ndarray
        Relative RMSE of the dual view over the whole image and inside the GT valid mask.
    coord_error : (L,) ndarray
        RMS dual-coordinate error (dual pixels), drawn on a second axis.
    factor : str
        Name of the factor (x-axis label).
    unit : str
        Unit of the factor.
    size : (float, float)
        Figure size in inches.

    Returns
    -------
    matplotlib.figure.Figure
    """
    values = np.asarray(values, dtype=np.float64)
    curves = [np.asarray(c, dtype=np.float64) for c in (whole, masked, coord_error)]
    if values.ndim != 1 or any(c.shape != values.shape for c in curves):
        raise ValueError(f"values, whole, masked, coord_error must be 1-D of one length, got "
                         f"{values.shape}, {[c.shape for c in curves]}")
    keep = np.isfinite(values)
    figure = _new_figure(size)
    axes = figure.add_subplot(1, 1, 1)
    axes.plot(values[keep], curves[0][keep], "o-", color="tab:blue", label="dual view, whole image")
    axes.plot(values[keep], curves[1][keep], "s-", color="tab:orange",
              label="dual view, GT valid mask")
    axes.set_xlabel(f"{factor} ({unit})" if unit else factor)
    axes.set_ylabel("relative RMSE vs reciprocal render")
    axes.set_ylim(bottom=0)
    twin = axes.twinx()
    twin.plot(values[keep], curves[2][keep], "^--", color="tab:green",
              label="dual coordinates (right axis)")
    twin.set_ylabel("RMS (u, v) error (dual pixel)")
    twin.set_ylim(bottom=0)
    lines = axes.get_lines() + twin.get_lines()
    axes.legend(lines, [line.get_label() for line in lines], fontsize="small", loc="best")
    axes.set_title(f"simulation study: {factor}")
    figure.tight_layout()
    return figure
