"""Report figures of the outdoor pipeline: the equivalent of the paper's Fig. 18.

Every function takes arrays and returns a :class:`matplotlib.figure.Figure`
(see :mod:`shadowcam.report.figures` for the conventions: linear images shown with a
percentile white point and display gamma, NaN drawn grey). The sky is masked
(drawn grey) in every camera-space figure.

Offers
------
display_step : decimation step of large images for display.
keyframes_figure : frames with their tracked edge overlaid.
edge_over_time_figure : edge rows of every column over time (time x col image) and sample curves.
arrival_map_figure : the arrival-time map in minutes, sky masked.
pushbroom_figure : the ridge pushbroom beside the real view.
transient_events_figure : where transient (passing) shadows were seen, how often and when.
"""

import numpy as np
from matplotlib import colormaps

from shadowcam._shared.validation import check_array, check_positive
from shadowcam.io.images import tone_map
from shadowcam.report.figures import NAN_GREY, WHITE_PERCENTILE, _new_figure


#: images are shown at most this many pixels wide / high (a 24 MP frame is decimated)
DISPLAY_SIZE = 1600


def display_step(shape, *, max_size=DISPLAY_SIZE):
    """Decimation step that brings an ``(H, W)`` image to at most `max_size` pixels a side."""
    return max(1, -(-max(int(n) for n in shape[:2]) // int(max_size)))


def _extent(shape, step):
    """imshow extent of an image decimated by `step`, in full-resolution pixel coordinates."""
    return (-0.5, shape[1] * step - 0.5, shape[0] * step - 0.5, -0.5)


def _masked_rgb(image, sky, step=1):
    """Display RGB of `image` (already decimated by `step`), sky grey."""
    rgb = tone_map(image, percentile=WHITE_PERCENTILE)
    sky = np.asarray(sky, dtype=bool)[::step, ::step]
    rgb[sky[: rgb.shape[0], : rgb.shape[1]]] = NAN_GREY
    return rgb


def keyframes_figure(frames, edge_rows, times_s, *, sky, is_keyframe=None, size=None, step=1):
    """Frames with the tracked edge of each drawn on it.

    Parameters
    ----------
    frames : sequence of (H, W, 3) ndarray
        Linear frames (e.g. divided by their gain so they look alike).
    edge_rows : sequence of (W,) ndarray
        Edge row per column of each frame (pixel-edge coordinates).
    times_s : sequence of float
    sky : (H, W) bool ndarray
    is_keyframe : sequence of bool, optional
        Marks non-keyframes (edge interpolated) in the titles.
    size : (float, float), optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    n = len(frames)
    if n == 0 or len(edge_rows) != n or len(times_s) != n:
        raise ValueError(f"frames, edge_rows and times_s must have the same non-zero length; got "
                         f"{n}, {len(edge_rows)}, {len(times_s)}")
    cols = min(3, n)
    rows = int(np.ceil(n / cols))
    figure = _new_figure(size or (4.0 * cols, 3.0 * rows))
    for i, (frame, edge, t) in enumerate(zip(frames, edge_rows, times_s)):
        axes = figure.add_subplot(rows, cols, i + 1)
        axes.imshow(_masked_rgb(frame, sky, step), interpolation="nearest", origin="upper",
                    extent=_extent(np.shape(frame), step))
        x = np.arange(len(edge)) + 0.5
        axes.plot(x, np.asarray(edge) - 0.5, color="red", linewidth=1.0)  # imshow: centre of row r at r
        mark = "" if is_keyframe is None or is_keyframe[i] else " (interpolated)"
        axes.set_title(f"t = {t / 60:.1f} min{mark}", fontsize="small")
        axes.set_xticks([])
        axes.set_yticks([])
    figure.tight_layout()
    return figure


def edge_over_time_figure(edge_row, time_s, *, reference=None, sky=None, n_curves=12, size=(11.0, 4.0)):
    """The tracked edge over time: edge row as a (time x col) image, and curves on the view.

    Parameters
    ----------
    edge_row : (T, W) ndarray
    time_s : (T,) ndarray
    reference : (H, W, 3) ndarray, optional
        View on which `n_curves` edges are drawn, coloured by time.
    sky : (H, W) bool ndarray, optional
    n_curves : int, optional
    size : (float, float), optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    edge = np.asarray(edge_row, dtype=np.float64)
    times = np.asarray(time_s, dtype=np.float64)
    if edge.ndim != 2 or times.shape != (edge.shape[0],):
        raise ValueError(f"edge_row must be (T, W) and time_s (T,); got {edge.shape}, {times.shape}")
    figure = _new_figure(size)
    panels = 2 if reference is not None else 1
    axes = figure.add_subplot(1, panels, 1)
    shown = axes.imshow(np.ma.masked_invalid(edge), aspect="auto", origin="lower", interpolation="nearest",
                        cmap=colormaps["viridis"].with_extremes(bad=NAN_GREY),
                        extent=(0, edge.shape[1], times[0] / 60, times[-1] / 60))
    axes.set_xlabel("col")
    axes.set_ylabel("time (min)")
    axes.set_title("edge row over time")
    figure.colorbar(shown, ax=axes, label="edge row (pixel)")
    if reference is not None:
        axes = figure.add_subplot(1, panels, 2)
        step = display_step(reference.shape)
        axes.imshow(_masked_rgb(reference[::step, ::step], np.zeros(reference.shape[:2], bool) if sky is None
                                else sky, step), interpolation="nearest", origin="upper",
                    extent=_extent(reference[::step, ::step].shape, step))
        cmap = colormaps["plasma"]
        for k in np.linspace(0, edge.shape[0] - 1, n_curves).astype(int):
            axes.plot(np.arange(edge.shape[1]) + 0.5, edge[k] - 0.5, color=cmap(k / max(edge.shape[0] - 1, 1)),
                      linewidth=0.8)
        axes.set_title(f"{n_curves} edges, early (dark) to late (yellow)")
        axes.set_xticks([])
        axes.set_yticks([])
    figure.tight_layout()
    return figure


def arrival_map_figure(arrival_s, *, sky, truth_s=None, interval_s=None, error_limit=2.0, size=None):
    """The arrival-time map in minutes, beside its ground truth and error if given; sky grey.

    Parameters
    ----------
    arrival_s : (H, W) ndarray
        Estimated arrival times (s); NaN = none.
    sky : (H, W) bool ndarray
    truth_s : (H, W) ndarray, optional
        Ground-truth arrival times (s) on the same pixel grid; adds the ground-truth map
        (same colour scale) and the error map.
    interval_s : float, optional
        Median capture interval (s): the unit of the error map (needed with `truth_s`).
    error_limit : float, optional
        The error colour scale spans +-`error_limit` intervals.
    size : (float, float), optional
        Figure size in inches; default (6.5, 4.5), (18, 4.5) with ground truth.

    Returns
    -------
    matplotlib.figure.Figure
    """
    arrival = np.asarray(arrival_s, dtype=np.float64) / 60.0
    check_array(arrival, "arrival_s", ndim=2)
    sky = np.asarray(sky, dtype=bool)
    arrival = np.where(sky, np.nan, arrival)
    panels = [("shadow arrival, estimate\n(sky, never / always shadowed: grey)", arrival, "arrival time (min)",
               "viridis", None)]
    if truth_s is not None:
        truth = np.where(sky, np.nan, np.asarray(truth_s, dtype=np.float64) / 60.0)
        check_array(truth, "truth_s", shape=arrival.shape)
        check_positive(interval_s, "interval_s")
        error = (arrival - truth) * 60.0 / float(interval_s)
        panels.append(("shadow arrival, ground truth\n(pixel centre goes dark)", truth, "arrival time (min)",
                       "viridis", None))
        panels.append(("error, estimate - ground truth", error,
                       f"error (capture intervals of {float(interval_s):.3g} s)", "RdBu_r",
                       (-error_limit, error_limit)))
    finite = np.concatenate([p[1][np.isfinite(p[1])] for p in panels[:2]])
    times_range = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    figure = _new_figure(size or ((6.5, 4.5) if len(panels) == 1 else (18.0, 4.5)))
    step = display_step(arrival.shape)
    for index, (title, values, label, cmap, limits) in enumerate(panels, start=1):
        axes = figure.add_subplot(1, len(panels), index)
        vmin, vmax = limits or times_range
        shown = axes.imshow(np.ma.masked_invalid(values[::step, ::step]),
                            cmap=colormaps[cmap].with_extremes(bad=NAN_GREY), vmin=vmin, vmax=vmax,
                            interpolation="nearest", origin="upper",
                            extent=_extent(values[::step, ::step].shape, step))
        axes.set_title(title)
        axes.set_xlabel("col")
        axes.set_ylabel("row")
        figure.colorbar(shown, ax=axes, label=label)
    figure.tight_layout()
    return figure


def pushbroom_figure(view, pushbroom, time_s, *, sky, size=(11.0, 4.5)):
    """The ridge pushbroom (time upward) beside the real view.

    Parameters
    ----------
    view : (H, W, 3) ndarray
        The real view (first frame).
    pushbroom : (T, W, 3) ndarray
        Rows at `time_s` (e.g. resampled to evenly spaced times).
    time_s : (T,) ndarray
    sky : (H, W) bool ndarray

    Returns
    -------
    matplotlib.figure.Figure
    """
    pushbroom = np.asarray(pushbroom)
    times = np.asarray(time_s, dtype=np.float64)
    if pushbroom.ndim != 3 or times.shape != (pushbroom.shape[0],):
        raise ValueError(f"pushbroom must be (T, W, 3) and time_s (T,); got {pushbroom.shape}, {times.shape}")
    figure = _new_figure(size)
    axes = figure.add_subplot(1, 2, 1)
    step = display_step(view.shape)
    axes.imshow(_masked_rgb(view[::step, ::step], sky, step), interpolation="nearest", origin="upper",
                extent=_extent(view[::step, ::step].shape, step))
    axes.set_title("real view (first frame)")
    axes.set_xlabel("col")
    axes.set_ylabel("row")
    axes = figure.add_subplot(1, 2, 2)
    axes.imshow(tone_map(pushbroom[:, ::step], percentile=WHITE_PERCENTILE), interpolation="nearest", origin="lower", aspect="auto",
                extent=(0, pushbroom.shape[1], times[0] / 60, times[-1] / 60))
    axes.set_title("ridge pushbroom (colour along the edge)")
    axes.set_xlabel("col")
    axes.set_ylabel("time (min)")
    figure.tight_layout()
    return figure


def transient_events_figure(event_row, event_col, event_start_s, transient, *, sky, size=(11.0, 4.5)):
    """Transient shadows (a passing cloud): episodes per pixel and when the first one began.

    Parameters
    ----------
    event_row, event_col, event_start_s : (N,) ndarray
        The event table of the arrival dataset (``event_row``, ``event_col``, ``event_start_s``).
    transient : (N,) bool ndarray
        Events to show (``event_kind`` is ``transient``).
    sky : (H, W) bool ndarray

    Returns
    -------
    matplotlib.figure.Figure
    """
    sky = np.asarray(sky, dtype=bool)
    check_array(sky, "sky", ndim=2)
    rows, cols = np.asarray(event_row, dtype=np.int64), np.asarray(event_col, dtype=np.int64)
    start = np.asarray(event_start_s, dtype=np.float64)
    keep = np.asarray(transient, dtype=bool)
    if not rows.shape == cols.shape == start.shape == keep.shape:
        raise ValueError(f"event_row {rows.shape}, event_col {cols.shape}, event_start_s {start.shape} and "
                         f"transient {keep.shape} must be the same (N,) shape")
    count = np.zeros(sky.shape)
    np.add.at(count, (rows[keep], cols[keep]), 1)
    first = np.full(sky.shape, np.inf)
    np.minimum.at(first, (rows[keep], cols[keep]), start[keep] / 60.0)
    count[sky] = np.nan
    first[~np.isfinite(first) | sky] = np.nan
    figure = _new_figure(size)
    step = display_step(sky.shape)
    for index, (image, title, label, cmap) in enumerate((
            (count, "transient shadows per pixel", "episodes", "magma"),
            (first, "start of the first transient shadow", "time (min)", "viridis"))):
        axes = figure.add_subplot(1, 2, index + 1)
        shown = axes.imshow(np.ma.masked_invalid(image[::step, ::step]),
                            cmap=colormaps[cmap].with_extremes(bad=NAN_GREY), interpolation="nearest",
                            origin="upper", extent=_extent(image[::step, ::step].shape, step))
        axes.set_title(title)
        axes.set_xlabel("col")
        axes.set_ylabel("row")
        figure.colorbar(shown, ax=axes, label=label)
    figure.tight_layout()
    return figure
