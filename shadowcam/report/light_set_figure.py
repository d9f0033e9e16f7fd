"""Several lights beside their ground truth (paper Fig. 11 / Fig. 13 layout).

Offers
------
light_titles : a title per light from the dataset's light kinds ("point 0", "tube along e_v").
light_set_figure : a row per light: estimated and exact shadow times of each sweep on one
    colour scale per sweep, then the light's dual view beside its ground truth.
light_set_figure_of : the figure of a views dataset and its capture's ground truth.
"""

import ast

import numpy as np

from shadowcam.cameras.dual_view import resample_dual_view
from shadowcam.io.images import tone_map
from shadowcam.report.figures import DUAL_AXES, WHITE_PERCENTILE, _new_figure, _show_times, _small_panel

#: inches per panel side
_PANEL_INCHES = 1.7
#: widths of a colour bar column and of the gap after it (its labels), in panels
_BAR_WIDTH, _BAR_GAP = 0.08, 0.3
#: camera-image axis labels (x, y)
_CAMERA_AXES = ("x (px)", "y (px)")


def light_titles(kinds, *, axes=None):
    """A title per light: ``"point k"``, ``"tube along e_<axis>"`` (``"tube k"`` without an axis).

    Parameters
    ----------
    kinds : sequence of str
        Each light's kind (a several-lights manifest's ``lights.kinds``).
    axes : sequence of str or None, optional
        Each light's tube axis (``"u"``, ``"v"``; None or ``""`` for none), when known.

    Returns
    -------
    list of str
    """
    kinds = [str(k) for k in kinds]
    axes = [None] * len(kinds) if axes is None else list(axes)
    if len(axes) != len(kinds):
        raise ValueError(f"axes must give one entry per light ({len(kinds)}); got {len(axes)}")
    return [f"{kind} along e_{axis}" if kind == "tube" and axis else f"{kind} {k}"
            for k, (kind, axis) in enumerate(zip(kinds, axes))]


def light_set_figure(times, truths, dual_views, *, titles, truth_views=None,
                     truth_title="from exact times", sweeps=("u", "v"), frames=None, shown=None, size=None):
    """Figure of per-light time maps beside their exact times, and each light's dual view.

    Parameters
    ----------
    times : (S, L, H, W) array_like
        Estimated shadow times (frame) per sweep and light; NaN = flagged (drawn grey).
    truths : (S, L, H, W) array_like
        Exact times, same layout (NaN = none, drawn grey).
    dual_views : (L, V, U, C) array_like
        Each light's dual view (NaN = hole, drawn in the hole colour).
    titles : sequence of str
        One per light (:func:`light_titles`).
    truth_views : (L, V, U, C) array_like, optional
        Each light's ground-truth view on the same dual grid (a reciprocal render, or the
        dual view from the exact times); None = the dual view alone.
    truth_title : str
        Title of the ground-truth view panels.
    sweeps : sequence of str
        The ``S`` sweeps' names.
    frames : sequence of int, optional
        Each sweep's number of frames: its colour scale runs over the sweep, 0 to
        ``frames - 1`` (exact times outside it saturate); default the range of its exact
        times over all lights.
    shown : (S, L) array_like of bool, optional
        Whether each sweep shows each light's dip; an estimated panel of a dip not shown
        is titled "dip not shown" (its pixels are all flagged).
    size : (float, float), optional
        Figure width, height in inches; default :data:`_PANEL_INCHES` per panel.

    Returns
    -------
    matplotlib.figure.Figure
        ``L`` rows; per sweep the estimated and the exact map (one colour scale per sweep,
        `frames`) and a colour bar spanning the rows,
        then the dual view and its ground truth (each with its own white point).
    """
    times, truths = np.asarray(times, np.float64), np.asarray(truths, np.float64)
    dual_views = np.asarray(dual_views, np.float64)
    if times.shape != truths.shape or times.ndim != 4 or dual_views.ndim != 4 \
            or dual_views.shape[0] != times.shape[1]:
        raise ValueError(f"times and truths must be (S, L, H, W) and dual_views (L, V, U, C) with the "
                         f"same L; got {times.shape}, {truths.shape}, {dual_views.shape}")
    n_sweeps, n_lights = times.shape[:2]
    shown = np.ones((n_sweeps, n_lights), bool) if shown is None else np.asarray(shown, bool)
    if shown.shape != (n_sweeps, n_lights):
        raise ValueError(f"shown must be (S, L) = {(n_sweeps, n_lights)}; got {shown.shape}")
    if frames is not None and len(frames) != n_sweeps:
        raise ValueError(f"frames must give one count per sweep ({n_sweeps}); got {list(frames)}")
    if len(sweeps) != n_sweeps or len(titles) != n_lights:
        raise ValueError(f"sweeps and titles must name the {n_sweeps} sweeps and {n_lights} lights; got "
                         f"{list(sweeps)} and {list(titles)}")
    views = [("dual view", dual_views)]
    if truth_views is not None:
        truth_views = np.asarray(truth_views, np.float64)
        if truth_views.shape[:3] != dual_views.shape[:3]:
            raise ValueError(f"truth_views must be on the dual grid of dual_views {dual_views.shape[:3]}; "
                             f"got {truth_views.shape}")
        views.append((truth_title, truth_views))
    ratios = [1, 1, _BAR_WIDTH, _BAR_GAP] * n_sweeps + [1] * len(views)
    width, height = size or (1.3 * sum(ratios) * _PANEL_INCHES + 0.5, n_lights * 1.55 * _PANEL_INCHES + 0.7)
    figure = _new_figure((width, height))
    # fixed margins (inches) for the titles, tick and axis labels; panels keep their aspect
    grid = figure.add_gridspec(n_lights, len(ratios), width_ratios=ratios, left=0.6 / width,
                               right=1 - 0.2 / width, top=1 - 0.8 / height, bottom=0.5 / height,
                               wspace=0.45, hspace=0.55)
    for s, sweep in enumerate(sweeps):
        finite = truths[s][np.isfinite(truths[s])]
        vmin, vmax = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
        if frames is not None:
            vmin, vmax = 0.0, float(max(int(frames[s]) - 1, 1))
        for k in range(n_lights):
            estimated = "estimated" if shown[s, k] else "dip not shown"
            for c, (label, image) in enumerate(((estimated, times[s, k]), ("exact", truths[s, k]))):
                axes = figure.add_subplot(grid[k, 4 * s + c])
                drawn = _show_times(axes, image, vmin=vmin, vmax=vmax)
                _small_panel(axes, None, f"{titles[k]}:\n{sweep} {label}",
                             xlabel=_CAMERA_AXES[0] if k == n_lights - 1 else None,
                             ylabel=_CAMERA_AXES[1] if c == 0 else None)
        bar = figure.colorbar(drawn, cax=figure.add_subplot(grid[:, 4 * s + 2]))
        bar.set_label("shadow time (frame)", fontsize="small")
        bar.ax.set_title(f"{sweep} sweep", fontsize="x-small")
        bar.ax.tick_params(labelsize="x-small")
    for k in range(n_lights):
        for c, (label, images) in enumerate(views):
            _small_panel(figure.add_subplot(grid[k, 4 * n_sweeps + c]),
                         tone_map(images[k], percentile=WHITE_PERCENTILE), f"{titles[k]}:\n{label}",
                         xlabel=DUAL_AXES[0] if k == n_lights - 1 else None, ylabel=DUAL_AXES[1] if c == 0 else None)
    figure.suptitle("several lights: shadow times (grey = flagged or none) and dual views", fontsize="medium")
    return figure


def _tube_axes(truth, n_lights):
    """Each light's tube axis from the ground truth's ``lights`` attr (the rendered lights
    block), None per light where it does not say."""
    try:
        described = ast.literal_eval(str(truth.attrs.get("lights", "[]")))
    except (ValueError, SyntaxError):
        described = []
    if not isinstance(described, list) or len(described) != n_lights:
        return None
    return [entry.get("axis") if isinstance(entry, dict) else None for entry in described]


def light_set_figure_of(views, truth, *, sweeps=("u", "v")):
    """:func:`light_set_figure` of a views dataset beside its capture's per-light truth.

    Parameters
    ----------
    views : xarray.Dataset
        From :func:`shadowcam.lab.light_views.light_set_views` (``time`` (sweep, light, y,
        x), ``dual_view`` (light, v, u, channel), attr ``kinds`` when read from files).
    truth : xarray.Dataset
        The capture's ``ground_truth.nc``: ``t_center_<sweep>`` (light, y, x) and
        ``reference`` (y, x, channel); the ground-truth views are the reference resampled
        at the exact times (the dual view the shadows would give without error).

    Returns
    -------
    matplotlib.figure.Figure
    """
    n_lights = views.sizes["light"]
    kinds = views.attrs.get("kinds", ["light"] * n_lights)
    kinds = [kinds] if isinstance(kinds, str) else list(kinds)
    titles = light_titles(kinds, axes=_tube_axes(truth, n_lights))
    truths = np.stack([truth[f"t_center_{s}"].values for s in sweeps])
    shape = views["dual_view"].shape[1:3]
    reference = truth["reference"].values
    truth_views = np.stack([resample_dual_view(reference, truths[0, k], truths[1, k], shape=shape)[0]
                            for k in range(n_lights)])
    return light_set_figure(views["time"].values, truths, views["dual_view"].values, titles=titles,
                            truth_views=truth_views, sweeps=sweeps, frames=[views.sizes[s] for s in sweeps],
                            shown=views["shown"].values.astype(bool) if "shown" in views else None)
