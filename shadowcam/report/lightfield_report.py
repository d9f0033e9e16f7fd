"""Figures of a light-field capture (paper Fig. 17): inputs, time maps, renders, far field.

Every function takes arrays and returns a :class:`matplotlib.figure.Figure`; the report
shows them in reading order (inputs, time maps, renders, far field).

Offers
------
FIGURES : figure name -> what it shows, in reading order.
inputs_figure : one HDR frame per screen (log scale).
time_maps_figure : the shadow time of every screen and sweep.
renders_figure : rendered vs ground-truth screen at each new position with the error map.
far_field_figure : polar intensity plot, estimate vs ground truth.
"""

import numpy as np

from shadowcam._shared.validation import check_array
from shadowcam.report.figures import _new_figure

#: figure name -> what it shows, in reading order
FIGURES = {
    "inputs": "one HDR frame per screen",
    "time_maps": "shadow time of each screen and sweep",
    "renders": "rendered vs ground-truth screen at the new positions, error map",
    "far_field": "polar intensity plot, estimate vs ground truth",
}


def _log(image):
    image = np.asarray(image, np.float64)
    floor = np.nanmax(image) * 1e-3 if np.any(np.isfinite(image)) else 1.0
    return np.log10(np.maximum(image, floor))


def inputs_figure(frames, names, *, size=None):
    """One unshadowed HDR frame ``(H, W)`` (lux) per screen, log10 colour scale."""
    figure = _new_figure(size or (4.0 * len(frames), 3.8))
    for k, (frame, name) in enumerate(zip(frames, names)):
        axes = figure.add_subplot(1, len(frames), k + 1)
        shown = axes.imshow(_log(check_array(frame, f"frames[{k}]", ndim=2)), cmap="gray")
        axes.set_title(f"screen {name}: HDR frame")
        axes.set_xlabel("col")
        axes.set_ylabel("row")
        figure.colorbar(shown, ax=axes, label="log10 lux")
    return figure


def time_maps_figure(times, labels, *, size=None):
    """Shadow times ``(H, W)`` (frames; NaN where none) of each screen and sweep."""
    figure = _new_figure(size or (3.6 * len(times), 3.6))
    for k, (time, label) in enumerate(zip(times, labels)):
        axes = figure.add_subplot(1, len(times), k + 1)
        shown = axes.imshow(check_array(time, f"times[{k}]", ndim=2), cmap="viridis")
        axes.set_title(f"{label}: shadow time")
        axes.set_xlabel("col")
        figure.colorbar(shown, ax=axes, label="frame")
    return figure


def renders_figure(renders, truths, positions_mm, *, size=None):
    """Rendered and ground-truth irradiance on one grid per position, and ``render * g - truth``.

    ``g`` is the one least-squares gain; the error is shown relative to the truth's maximum.
    """
    figure = _new_figure(size or (11.0, 3.4 * len(renders)))
    for k, (render, truth, z) in enumerate(zip(renders, truths, positions_mm)):
        render, truth = np.nan_to_num(render), np.asarray(truth, np.float64)
        gain = (render.ravel() @ truth.ravel()) / max(render.ravel() @ render.ravel(), 1e-300)
        top = truth.max()
        for j, (image, title, cmap, limits) in enumerate([
                (gain * render, f"rendered at {z:g} mm", "inferno", (0, top)),
                (truth, "ground truth", "inferno", (0, top)),
                ((gain * render - truth) / top, "error / max truth", "coolwarm", (-0.2, 0.2))]):
            axes = figure.add_subplot(len(renders), 3, 3 * k + j + 1)
            shown = axes.imshow(image, cmap=cmap, vmin=limits[0], vmax=limits[1])
            axes.set_title(title)
            figure.colorbar(shown, ax=axes)
    return figure


def far_field_figure(gamma, c, estimate, truth, *, planes=(0.0, 90.0), size=(6.0, 6.0)):
    """Polar intensity plot (cd vs gamma) in the C planes `planes` and their opposites.

    Parameters
    ----------
    gamma : (V,) ndarray
        Degrees from the axis.
    c : (Hz,) ndarray
        C angles, degrees.
    estimate, truth : (Hz, V) ndarray
        Candela tables.
    """
    figure = _new_figure(size)
    axes = figure.add_subplot(1, 1, 1, projection="polar")
    axes.set_theta_zero_location("S")
    for plane, style in zip(planes, ("-", "--")):
        for table, colour, label in ((estimate, "tab:red", "estimate"), (truth, "black", "ground truth")):
            i, j = int(np.argmin(np.abs(c - plane))), int(np.argmin(np.abs(c - (plane + 180) % 360)))
            angles = np.radians(np.r_[-gamma[::-1], gamma])
            values = np.r_[table[j][::-1], table[i]]
            axes.plot(angles, values, style, color=colour, label=f"{label}, C {c[i]:g}/{c[j]:g}")
    widest = float(np.max(gamma)) + 2.0
    axes.set_thetamin(-widest)
    axes.set_thetamax(widest)
    axes.set_title("luminous intensity, cd, vs gamma (nadir = source axis)")
    axes.legend(loc="lower left", fontsize=7)
    return figure
