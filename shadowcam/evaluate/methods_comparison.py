"""Speed against error of every shadow-time, several-minima and dual-view resampling method.

Every method of :data:`shadowcam.lab.shadow_time_methods.SHADOW_TIME_METHODS` and
:data:`shadowcam.cameras.dual_view.DUAL_VIEW_METHODS` runs on the same scene and is
measured for wall time, throughput, peak memory and error against the exact
ground truth; the Pareto front (no other method both faster and more
accurate) says which defaults the data justify.

* Shadow time: the frames are tracked once (the streaming stage shared by
  every method), then each method classifies and times the dips. Its wall
  time is the tracking time plus its own; throughput is pixel-frames per
  second of that total; error is the absolute time error (frames) over the
  lit pixels with a true time, p50/p95, and coverage.
* Several minima (a capture lit by several lights, paper Fig. 11): each timing
  method finds, times and assigns every pixel's minima to the lights as the
  stage does (:func:`shadowcam.lab.light_views.light_set_views`: ``edge_fit`` over
  each light's own map, camera RAW from each pixel's own mosaic site by the
  capture's ``cfa_pattern``); throughput is
  pixel-frames per second of both sweeps; error is the absolute time error
  pooled over lights and sweeps on the scored pixels, p50/p95, and coverage.
* Dual view: each resampling method maps the camera colours to the dual grid;
  throughput is camera pixels per second; error is the gain-fitted relative
  RMSE against the reciprocal render inside the covered, visible mask.

Each measurement runs three times: a warm-up (compiled kernels load from their
cache), once under ``tracemalloc`` for the peak numpy/Python heap (compiled
kernels' own buffers are not counted), and once timed.

Offers
------
compare_shadow_time_methods : rows of figures, one per shadow-time method.
compare_minima_methods : rows of figures, one per timing method of several minima.
compare_dual_view_methods : rows of figures, one per resampling method.
pareto_front : which rows no other row beats in both speed and error.
methods_dataset : the rows as an xarray dataset over ``method``.
speed_error_figure : the speed-versus-error chart with its Pareto front.
compare_methods : every method on one dataset's frame stores and dual coordinates -> the methods dataset.
compare_light_set_methods : every several-minima method on one several-lights capture -> the methods dataset.
"""

import logging
import time
import tracemalloc

import numpy as np

from shadowcam.lab.accuracy import dual_image_errors, shadow_time_errors
from shadowcam.cameras.dual_view import DUAL_VIEW_METHODS, resample_dual_view
from shadowcam.lab.light_views import SWEEPS as LIGHT_SET_SWEEPS
from shadowcam.lab.light_views import light_set_errors, light_set_views
from shadowcam.lab.shadow_time import SHADOW_TIME_METHODS, summary_shadow_times, track_sweep

log = logging.getLogger(__name__)


def _measured(call):
    """Run `call` three times: to warm up (compiled kernels load), under ``tracemalloc``,
    then timed; return (result, seconds, peak MiB)."""
    call()
    tracemalloc.start()
    try:
        call()
        peak = tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()
    start = time.perf_counter()
    result = call()
    seconds = time.perf_counter() - start
    return result, seconds, peak


def _time_error_row(stage, method, seconds, throughput, peak, errors, coverage):
    """One comparison row of a timing method: median and p95 of the absolute `errors`
    (frames; NaN without any)."""
    return {"stage": stage, "method": method, "seconds": seconds, "throughput": throughput,
            "peak_mib": peak,
            "p50": float(np.median(errors)) if errors.size else np.nan,
            "p95": float(np.percentile(errors, 95)) if errors.size else np.nan,
            "coverage": coverage}


def compare_shadow_time_methods(sweeps, *, methods=None, half_window=4, cfa_pattern=None):
    """Speed and error of shadow-time methods on the same sweeps.

    Parameters
    ----------
    sweeps : dict of str to (callable, (H, W) ndarray, (H, W) bool ndarray)
        Sweep name -> (a function returning a fresh iterable of ``(T, H, W, C)``
        float32 frame blocks, the true shadow time in frames (NaN where none),
        the pixels that see the light).
    methods : sequence of str, optional
        Default: every key of :data:`SHADOW_TIME_METHODS`.
    half_window : int, optional
    cfa_pattern : str, optional
        Bayer pattern of demosaiced RAW frames.

    Returns
    -------
    list of dict
        Per method: ``stage``, ``method``, ``seconds``, ``throughput``
        (pixel-frames/s), ``peak_mib``, ``p50``, ``p95`` (frames, pooled over
        sweeps), ``coverage``.
    """
    methods = list(methods or SHADOW_TIME_METHODS)
    unknown = set(methods) - set(SHADOW_TIME_METHODS)
    if unknown:
        raise ValueError(f"methods: unknown {sorted(unknown)}; choose from {sorted(SHADOW_TIME_METHODS)}")
    if not sweeps:
        raise ValueError("sweeps is empty: give at least one sweep with its truth")
    tracked = {}
    for name, (blocks, truth, lit) in sweeps.items():
        shape = np.shape(truth)
        (summary, _, _), seconds, peak = _measured(lambda: track_sweep(blocks(), shape, half_window=half_window))
        tracked[name] = (summary, truth, lit, seconds, peak)
    rows = []
    for method in methods:
        seconds = peak = pixel_frames = 0.0
        errors, n_truth, n_found = [], 0, 0
        for summary, truth, lit, track_seconds, track_peak in tracked.values():
            result, spent, used = _measured(lambda: summary_shadow_times(
                summary, method=method, cfa_pattern=cfa_pattern))
            seconds += track_seconds + spent
            peak = max(peak, track_peak, used)
            pixel_frames += summary.n_frames * truth.size
            stats = shadow_time_errors(result["shadow_time"], truth, lit=lit)
            has = lit & np.isfinite(truth) & np.isfinite(result["shadow_time"])
            errors.append(np.abs(result["shadow_time"] - truth)[has])
            n_truth += stats["n_truth"]
            n_found += stats["n_evaluated"]
        rows.append(_time_error_row("shadow_time", method, seconds, pixel_frames / seconds, peak,
                                    np.concatenate(errors), n_found / n_truth if n_truth else np.nan))
    return rows


#: timing methods of the several lights' minima: each method times every minimum, ``edge_fit``
#: (the stage's) dip centroids refined over each light's own time map, demosaiced RAW from each
#: pixel's own mosaic site (:func:`shadowcam.lab.light_views.light_set_views`)
MINIMA_METHODS = tuple(SHADOW_TIME_METHODS)


def compare_minima_methods(capture, *, methods=None, half_window=4):
    """Speed and per-light error of the timing methods of several minima on one capture.

    Parameters
    ----------
    capture : xarray.Dataset
        A several-lights capture with its per-light truth (see
        :func:`shadowcam.lab.light_views.light_set_views`, whose attr ``cfa_pattern`` it
        follows, and :func:`~shadowcam.lab.light_views.light_set_errors`).
    methods : sequence of str, optional
        Default: every method of :data:`MINIMA_METHODS`.
    half_window : int, optional

    Returns
    -------
    list of dict
        Per method: ``stage`` ("several_minima"), ``method``, ``seconds``,
        ``throughput`` (pixel-frames/s over both sweeps), ``peak_mib``, ``p50``,
        ``p95`` (frames, pooled over lights and sweeps), ``coverage`` (timed
        fraction of the scored pixel-lights).
    """
    methods = list(methods or MINIMA_METHODS)
    unknown = set(methods) - set(MINIMA_METHODS)
    if unknown:
        raise ValueError(f"methods: {sorted(unknown)} cannot time several minima; choose from {sorted(MINIMA_METHODS)}")
    capture = capture.load()
    pixel_frames = sum(capture[f"frames_{s}"].shape[0] for s in LIGHT_SET_SWEEPS) * capture["reference"][..., 0].size
    rows = []
    for method in methods:
        views, seconds, peak = _measured(lambda: light_set_views(capture, half_window=half_window, method=method))
        errors = light_set_errors(views, capture)
        err = np.concatenate([error[scored] for error, scored in errors.values()])
        timed = err[np.isfinite(err)]
        rows.append(_time_error_row("several_minima", method, seconds, pixel_frames / seconds, peak, timed,
                                    timed.size / err.size if err.size else np.nan))
    return rows


def compare_dual_view_methods(colours, u, v, *, shape, valid, reciprocal, dual_cam_visible,
                              methods=None):
    """Speed and error of dual-view resampling methods on the same dual coordinates.

    Parameters
    ----------
    colours : (rows, cols, channel) ndarray
    u, v : (rows, cols) ndarray
        Dual coordinates.
    shape : (int, int)
        Dual grid ``(height, width)``.
    valid : (rows, cols) bool ndarray
    reciprocal : (v, u, channel) ndarray
        True reciprocal render on the dual grid.
    dual_cam_visible : (v, u) bool ndarray
    methods : sequence of str, optional
        Default: every key of :data:`DUAL_VIEW_METHODS`.

    Returns
    -------
    list of dict
        Per method: ``stage``, ``method``, ``seconds``, ``throughput`` (camera
        pixels/s), ``peak_mib``, ``p50`` (NaN), ``p95`` (relative RMSE in the
        mask, in the error column), ``coverage`` (of the visible dual pixels).
    """
    methods = list(methods or DUAL_VIEW_METHODS)
    unknown = set(methods) - set(DUAL_VIEW_METHODS)
    if unknown:
        raise ValueError(f"methods: unknown {sorted(unknown)}; choose from {sorted(DUAL_VIEW_METHODS)}")
    rows = []
    for method in methods:
        (image, coverage), seconds, peak = _measured(lambda: resample_dual_view(
            colours, u, v, shape=shape, valid=valid, method=method))
        errors = dual_image_errors(image, coverage, reciprocal, dual_cam_visible=dual_cam_visible)
        rows.append({
            "stage": "dual_view", "method": method, "seconds": seconds,
            "throughput": np.size(u) / seconds, "peak_mib": peak, "p50": np.nan,
            "p95": errors["rel_rmse_masked"], "coverage": errors["coverage_of_visible"],
        })
    return rows


def pareto_front(throughput, error):
    """Rows that no other row beats in both throughput (higher) and error (lower).

    Parameters
    ----------
    throughput, error : (N,) array_like

    Returns
    -------
    (N,) bool ndarray
        NaN errors are never on the front.
    """
    speed = np.asarray(throughput, np.float64)
    err = np.asarray(error, np.float64)
    if speed.shape != err.shape or speed.ndim != 1:
        raise ValueError(f"throughput and error must be 1-D of equal length, got {speed.shape}, {err.shape}")
    ok = np.isfinite(speed) & np.isfinite(err)
    front = np.zeros(speed.shape, bool)
    for i in np.flatnonzero(ok):
        others = ok & (np.arange(speed.size) != i)
        dominated = others & (speed >= speed[i]) & (err <= err[i]) & ((speed > speed[i]) | (err < err[i]))
        front[i] = not dominated.any()
    return front


_UNITS = {
    "seconds": ("s", "wall time of the method (shadow time: including the shared tracking)"),
    "throughput": ("1/s", "pixel-frames per second (shadow time, several minima) or camera pixels per second (dual view)"),
    "peak_mib": ("MiB", "peak numpy/Python heap during the method (tracemalloc)"),
    "p50": ("frame", "median absolute shadow-time error"),
    "p95": ("frame or 1", "95th percentile absolute shadow-time error; dual view: relative RMSE"),
    "coverage": ("1", "fraction of the true pixels given a value"),
}


def methods_dataset(rows):
    """The comparison rows as an xarray dataset over ``method``, with ``pareto`` per stage.

    Parameters
    ----------
    rows : list of dict
        From :func:`compare_shadow_time_methods` and :func:`compare_dual_view_methods`.

    Returns
    -------
    xarray.Dataset
        Coordinates ``method``, ``stage``; variables of :data:`_UNITS` and
        ``pareto`` (bool: on its stage's Pareto front).
    """
    import xarray as xr

    if not rows:
        raise ValueError("rows is empty: nothing was measured")
    stage = np.array([r["stage"] for r in rows])
    data = {key: ("method", np.array([r[key] for r in rows], np.float64),
                  {"units": units, "long_name": long_name})
            for key, (units, long_name) in _UNITS.items()}
    pareto = np.zeros(len(rows), bool)
    for name in np.unique(stage):
        mine = stage == name
        pareto[mine] = pareto_front(data["throughput"][1][mine], data["p95"][1][mine])
    data["pareto"] = ("method", pareto, {"long_name": "on the Pareto front of its stage"})
    return xr.Dataset(data, coords={"method": [r["method"] for r in rows], "stage": ("method", stage)})


def speed_error_figure(dataset, *, title=""):
    """Speed-versus-error chart with the Pareto front, one panel per stage.

    Parameters
    ----------
    dataset : xarray.Dataset
        From :func:`methods_dataset`.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    stages = list(dict.fromkeys(dataset["stage"].values.tolist()))
    fig, axes = plt.subplots(1, len(stages), figsize=(6 * len(stages), 4.5), squeeze=False)
    for ax, name in zip(axes[0], stages):
        sub = dataset.where(dataset["stage"] == name, drop=True)
        speed, err = sub["throughput"].values / 1e6, sub["p95"].values
        front = sub["pareto"].values.astype(bool)
        ax.scatter(speed[~front], err[~front], color="0.5", label="dominated")
        ax.scatter(speed[front], err[front], color="C3", label="Pareto front")
        order = np.argsort(speed[front])
        ax.plot(speed[front][order], err[front][order], color="C3", drawstyle="steps-post")
        for x, y, label in zip(speed, err, sub["method"].values):
            ax.annotate(str(label), (x, y), fontsize=7, xytext=(3, 3), textcoords="offset points")
        if np.nanmax(speed) > 10 * np.nanmin(speed):
            ax.set_xscale("log")
        unit = "M camera pixels/s" if name == "dual_view" else "M pixel-frames/s"
        ax.set_xlabel(f"throughput ({unit}, higher is better)")
        ax.set_ylabel("relative RMSE" if name == "dual_view" else "p95 |time error| (frames)")
        ax.set_title(name.replace("_", " "))
        ax.legend(fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def compare_methods(truth, sweeps, shadow_time, coords, *, reference=None, half_window=4):
    """Time every shadow-time and dual-view method on one dataset and score it against `truth`.

    Parameters
    ----------
    truth : xarray.Dataset
        Lab ground truth (``lit``, ``t_<sweep>``, ``reciprocal``, ``dual_cam_visible``).
    sweeps : mapping of str to xarray.Dataset
        Scene sweep name -> its frame store (loaded into memory before timing, so
        that the trackers are timed and not the store's codec).
    shadow_time : xarray.Dataset
        Its ``lit_image`` gives the colours when `reference` is None.
    coords : xarray.Dataset
        Dual coordinates.
    reference : xarray.Dataset, optional
        Reference frame store.
    half_window : int
        Dip half window of the trackers.

    Returns
    -------
    xarray.Dataset
        :func:`methods_dataset` of every method.
    """
    from shadowcam.cameras.dual_view import camera_colours
    from shadowcam.io.frame_store import iter_frame_chunks

    lit = truth["lit"].transpose("row", "col").values.astype(bool)
    inputs, cfa = {}, None
    for sweep, frames in sweeps.items():
        if f"t_{sweep}" not in truth:
            raise ValueError(f"sweeps: the ground truth has no t_{sweep}; compare scene sweeps only")
        cfa = frames.attrs.get("cfa_pattern") or None
        loaded = [block for _, block in iter_frame_chunks(frames)]

        def blocks(loaded=loaded):
            return iter(loaded)

        inputs[sweep] = (blocks, truth[f"t_{sweep}"].transpose("row", "col").values, lit)
    rows = compare_shadow_time_methods(inputs, half_window=half_window, cfa_pattern=cfa)
    if reference is not None:
        image = reference["image"]
        image = image.mean("time") if "time" in image.dims else image
        reference = image.transpose("row", "col", "channel").values
    colours = camera_colours(shadow_time, reference=reference)
    rows += compare_dual_view_methods(
        colours, coords["u"].transpose("row", "col").values, coords["v"].transpose("row", "col").values,
        shape=(int(coords.attrs["dual_height"]), int(coords.attrs["dual_width"])),
        valid=coords["valid"].values, reciprocal=truth["reciprocal"].transpose("v", "u", "channel").values,
        dual_cam_visible=truth["dual_cam_visible"].transpose("v", "u").values,
    )
    return _logged(rows, methods_dataset(rows))


def _logged(rows, dataset):
    for row, on_front in zip(rows, dataset["pareto"].values):
        log.info("%-14s %-38s %9.3g /s  p95 %.4f  coverage %.3f  %s", row["stage"], row["method"],
                 row["throughput"], row["p95"], row["coverage"], "Pareto" if on_front else "")
    return dataset


def compare_light_set_methods(capture, *, half_window=4):
    """Time every several-minima method on one several-lights capture and score it.

    Parameters
    ----------
    capture : xarray.Dataset
        From the render-lights step (frames, reference, per-light truth).
    half_window : int

    Returns
    -------
    xarray.Dataset
        :func:`methods_dataset` of every method of :data:`MINIMA_METHODS`.
    """
    rows = compare_minima_methods(capture, half_window=half_window)
    return _logged(rows, methods_dataset(rows))
