"""Accuracy of shadow times, dual coordinates and dual views against ground truth.

Metrics (synthetic data with exact ground truth, docs/contracts.md form):

* shadow time, per sweep, over lit pixels with a GT time: absolute error
  median, 95th percentile, RMSE, fraction > 1 frame; coverage = fraction of
  those pixels with an estimate; false-time rate = fraction of GT-unlit pixels
  that were given a time.
* dual coordinates: Euclidean error (dual pixels) of ``(u, v)`` against the
  GT times expressed on the same dual grid (uniform model: the mask plane
  scaled; calibration model: the calibration plane's window, reached from
  the mask plane by the exact GT homography of the central projection).
* dual image against the GT reciprocal render, after ONE least-squares gain
  fitted inside the valid mask (coverage & dual_cam_visible & finite
  reciprocal; the render resampled onto the dual grid when the grids
  differ): relative RMSE inside that mask, and over the whole image with
  holes counted as zero -- the two curves of the paper's Fig. 5.

* shadow pushbroom (one sweep) against the same assembly applied to the GT shadow
  times and the same colour source, after ONE least-squares gain: relative RMSE over
  the cells both have, and coverage = fraction of the GT cells the estimate has.
* dip interval (a wide wire under an area light), per sweep: absolute error of the
  entry, centre and exit against the exact half-depth crossings, and coverage; each
  viewpoint's dual view against its own reciprocal render, as the main dual view.
Targets (foundation issue) are checked and reported pass/fail.

Offers
------
ACCURACY_TARGETS : the targets and their thresholds.
CONFIDENT_STD : time std (frames) above which a time is reported as uncertain.
shadow_time_errors : error statistics of one sweep's shadow times.
dual_coord_errors : error statistics of dual coordinates.
dual_image_errors : gain-fitted relative RMSE of a dual view, masked and whole image.
pushbroom_errors : gain-fitted relative RMSE and coverage of a lab shadow pushbroom.
check_targets : pass/fail of every target for a report.
reciprocal_on_dual_grid : the GT reciprocal render resampled onto a dual grid.
accuracy_report : the nested report for one dataset's products.
noise_condition : the noise condition whose targets apply, and where it came from.
flatten_report : the report as ``(key, value)`` rows.
TABLE_ROWS, TARGET_KEYS, GROUND_TRUTH_DEFINITION : what the accuracy table shows.
accuracy_table : the report as one row per quantity (value, unit, target, pass).
report_to_json, report_to_csv : serialise a report to text (JSON whole, CSV as the table).
interval_errors : errors and coverage of the dip interval's entry, centre and exit.
viewpoint_image_errors : a viewpoint's dual view against its reciprocal render.
"""

import json

import numpy as np

from shadowcam._shared.quantity_table import quantity_row, table_to_csv
from shadowcam._shared.validation import check_array, check_in

#: targets of the foundation issue; the shadow-time p95 depends on the noise condition
ACCURACY_TARGETS = {
    "shadow_time_p95_frames": {"noise_free": 0.1, "raw12": 0.3, "comparison": "<="},
    "shadow_time_coverage": {"threshold": 0.98, "comparison": ">="},
    "false_time_rate": {"threshold": 0.01, "comparison": "<"},
}


def _stats(err):
    """median, p95, RMSE, max of a 1-D error array (NaN if empty)."""
    if err.size == 0:
        return {"median": float("nan"), "p95": float("nan"), "rmse": float("nan"),
                "max": float("nan")}
    return {
        "median": float(np.median(err)),
        "p95": float(np.percentile(err, 95)),
        "rmse": float(np.sqrt(np.mean(err**2))),
        "max": float(err.max()),
    }


#: a time whose standard deviation is above this (frames) is not confident (the scale of
#: the shadow time's ``confidence``, exp(-std^2 / (2 * 0.25^2)))
CONFIDENT_STD = 0.25


def shadow_time_errors(estimate, truth, *, lit, time_std=None):
    """Error statistics of one sweep's shadow times.

    Parameters
    ----------
    estimate : (rows, cols) ndarray
        Estimated shadow time (frames), NaN = no estimate.
    truth : (rows, cols) ndarray
        GT shadow time (frames), NaN where not lit or not swept.
    lit : (rows, cols) bool ndarray, keyword-only
        GT: the pixel's point sees the light.
    time_std : (rows, cols) ndarray, optional
        The estimate's standard deviation (frames).

    Returns
    -------
    dict
        ``n_truth`` (lit pixels with a GT time), ``n_evaluated``, ``coverage``,
        ``median``, ``p95``, ``rmse``, ``max`` (absolute error, frames),
        ``frac_gt_1_frame``, ``n_unlit``, ``false_time_rate``, ``mean_signed``,
        ``n_unswept`` (lit pixels the shadow does not cross within the sweep: no GT time)
        and ``unswept_time_rate`` (the fraction of them given a time); with
        `time_std` also ``n_uncertain`` (evaluated pixels whose std exceeds
        :data:`CONFIDENT_STD`; they stay in every statistic above) and ``p95_confident``
        (p95 over the other evaluated pixels).
    """
    estimate = np.asarray(estimate, dtype=np.float64)
    truth = np.asarray(truth, dtype=np.float64)
    lit = np.asarray(lit, dtype=bool)
    if estimate.shape != truth.shape or lit.shape != truth.shape:
        raise ValueError(
            f"estimate/truth/lit: shapes differ: {estimate.shape}, {truth.shape}, {lit.shape}"
        )
    has_truth = lit & np.isfinite(truth)
    has_est = np.isfinite(estimate)
    evaluated = has_truth & has_est
    signed = (estimate - truth)[evaluated]
    err = np.abs(signed)
    n_truth, n_unlit = int(has_truth.sum()), int((~lit).sum())
    out = {
        "n_truth": n_truth,
        "n_evaluated": int(evaluated.sum()),
        "coverage": float(evaluated.sum() / n_truth) if n_truth else float("nan"),
        **_stats(err),
        "frac_gt_1_frame": float(np.mean(err > 1.0)) if err.size else float("nan"),
        "mean_signed": float(signed.mean()) if err.size else float("nan"),
        "n_unlit": n_unlit,
        "false_time_rate": float((has_est & ~lit).sum() / n_unlit) if n_unlit else 0.0,
    }
    unswept = lit & ~np.isfinite(truth)
    out["n_unswept"] = int(unswept.sum())
    out["unswept_time_rate"] = float((has_est & unswept).sum() / out["n_unswept"]) if out["n_unswept"] else 0.0
    if time_std is not None:
        std = np.asarray(time_std, dtype=np.float64)
        if std.shape != truth.shape:
            raise ValueError(f"time_std: shape {std.shape} differs from truth's {truth.shape}")
        confident = ~(std[evaluated] > CONFIDENT_STD)
        out["n_uncertain"] = int((~confident).sum())
        out["p95_confident"] = _stats(np.abs(signed[confident]))["p95"]
    return out


def dual_coord_errors(u, v, true_u, true_v, *, valid=None):
    """Euclidean error (dual pixels) of dual coordinates.

    Parameters
    ----------
    u, v : (rows, cols) ndarray
        Estimated dual coordinates, NaN = none.
    true_u, true_v : (rows, cols) ndarray
        GT dual coordinates, NaN = none.
    valid : (rows, cols) bool ndarray, optional
        Estimates to use (default: finite ``u`` and ``v``).

    Returns
    -------
    dict
        ``n_truth``, ``n_evaluated``, ``coverage``, ``median``, ``p95``,
        ``rmse``, ``max`` of ``hypot(u - true_u, v - true_v)``, and per-axis
        ``rmse_u``, ``rmse_v``.
    """
    u, v, tu, tv = (np.asarray(a, dtype=np.float64) for a in (u, v, true_u, true_v))
    if not (u.shape == v.shape == tu.shape == tv.shape):
        raise ValueError(f"u/v/true_u/true_v: shapes differ: {u.shape}, {v.shape}, {tu.shape}")
    est = np.isfinite(u) & np.isfinite(v)
    if valid is not None:
        est &= np.asarray(valid, dtype=bool)
    has_truth = np.isfinite(tu) & np.isfinite(tv)
    ev = est & has_truth
    du, dv = (u - tu)[ev], (v - tv)[ev]
    n_truth = int(has_truth.sum())
    return {
        "n_truth": n_truth,
        "n_evaluated": int(ev.sum()),
        "coverage": float(ev.sum() / n_truth) if n_truth else float("nan"),
        **_stats(np.hypot(du, dv)),
        "rmse_u": float(np.sqrt(np.mean(du**2))) if du.size else float("nan"),
        "rmse_v": float(np.sqrt(np.mean(dv**2))) if dv.size else float("nan"),
    }


def dual_image_errors(dual_view, coverage, reciprocal, *, dual_cam_visible):
    """Relative RMSE of a dual view against the reciprocal render, one gain fitted.

    The gain ``g`` minimises ``sum (g * est - ref)^2`` over the valid mask
    ``coverage & dual_cam_visible & finite(reciprocal)`` (all channels). Then

    * ``rel_rmse_masked = sqrt(mean((g est - ref)^2) / mean(ref^2))`` in the mask;
    * ``rel_rmse_whole``: the same over every dual pixel with a finite
      reciprocal, holes (no estimate) counted as zero.

    Parameters
    ----------
    dual_view : (v, u, channel) ndarray
        Estimated dual view (linear), NaN = hole.
    coverage : (v, u) bool ndarray
    reciprocal : (v, u, channel) ndarray
        GT reciprocal render on the same grid.
    dual_cam_visible : (v, u) bool ndarray, keyword-only
        GT: the dual pixel's point is seen by the camera.

    Returns
    -------
    dict
        ``gain``, ``rel_rmse_masked``, ``rel_rmse_whole``, ``n_mask``,
        ``coverage_of_visible`` (fraction of camera-visible dual pixels covered),
        ``covered_not_visible`` (fraction of covered pixels the camera cannot see).
    """
    est = np.asarray(dual_view, dtype=np.float64)
    ref = np.asarray(reciprocal, dtype=np.float64)
    cov = np.asarray(coverage, dtype=bool)
    vis = np.asarray(dual_cam_visible, dtype=bool)
    if est.shape != ref.shape:
        raise ValueError(f"dual_view: shape {est.shape} differs from reciprocal {ref.shape}")
    if cov.shape != est.shape[:2] or vis.shape != est.shape[:2]:
        raise ValueError(f"coverage/dual_cam_visible: shapes {cov.shape}, {vis.shape} "
                         f"differ from dual_view {est.shape[:2]}")
    ref_ok = np.all(np.isfinite(ref), axis=2)
    est_ok = cov & np.all(np.isfinite(est), axis=2)
    mask = est_ok & vis & ref_ok
    e, r = est[mask], ref[mask]
    denom = float(np.sum(e * e))
    gain = float(np.sum(e * r) / denom) if denom > 0 else float("nan")
    out = {
        "gain": gain,
        "n_mask": int(mask.sum()),
        "coverage_of_visible": float((cov & vis).sum() / vis.sum()) if vis.any() else float("nan"),
        "covered_not_visible": float((cov & ~vis).sum() / cov.sum()) if cov.any() else 0.0,
    }
    if mask.any() and np.isfinite(gain):
        out["rel_rmse_masked"] = float(np.sqrt(np.mean((gain * e - r) ** 2) / np.mean(r**2)))
        filled = np.where(est_ok[..., None], est, 0.0)[ref_ok]
        whole_ref = ref[ref_ok]
        out["rel_rmse_whole"] = float(
            np.sqrt(np.mean((gain * filled - whole_ref) ** 2) / np.mean(whole_ref**2))
        )
    else:
        out["rel_rmse_masked"] = out["rel_rmse_whole"] = float("nan")
    return out


def pushbroom_errors(pushbroom, true_time, reference, *, along):
    """Accuracy of a lab shadow pushbroom against the one the exact shadow times give.

    The ground-truth pushbroom is the same assembly
    (:func:`shadowcam.cameras.pushbroom.edge_from_time_map`, then
    :func:`~shadowcam.cameras.pushbroom.assemble_pushbroom`) applied to `true_time` and
    `reference`; one least-squares gain maps the estimate onto it.

    Parameters
    ----------
    pushbroom : (T, P, C) ndarray
        Estimated pushbroom (time, position along the shadow line, channel); NaN = no edge.
    true_time : (H, W) ndarray
        GT shadow times of the sweep (frames; NaN = none).
    reference : (H, W, C) ndarray
        Colour source of the estimate.
    along : {"row", "col"}, keyword-only
        Camera axis the shadow line runs along (the estimate's ``along``).

    Returns
    -------
    dict
        ``rel_rmse`` (RMSE of gain * estimate - GT over the cells both have, relative to the
        RMS of GT there), ``gain``, ``coverage`` (fraction of GT cells the estimate has),
        ``n_evaluated`` (cells in both).
    """
    from shadowcam.cameras.pushbroom import assemble_pushbroom, edge_from_time_map

    estimate = check_array(np.asarray(pushbroom, dtype=np.float64), "pushbroom", ndim=3)
    truth_edge = edge_from_time_map(true_time, np.arange(estimate.shape[0]), along=along)
    truth = assemble_pushbroom(np.asarray(reference, dtype=np.float64), truth_edge, along=along)
    if truth.shape != estimate.shape:
        raise ValueError(f"pushbroom must have the shape of the GT pushbroom {truth.shape}; "
                         f"got {estimate.shape}")
    has_truth = np.all(np.isfinite(truth), axis=-1)
    both = has_truth & np.all(np.isfinite(estimate), axis=-1)
    n = int(both.sum())
    coverage = float(both.sum() / has_truth.sum()) if has_truth.any() else float("nan")
    if n == 0:
        return {"rel_rmse": float("nan"), "gain": float("nan"), "coverage": coverage, "n_evaluated": 0}
    est, gt = estimate[both], truth[both]
    denom = float(np.sum(est * est))
    gain = float(np.sum(est * gt) / denom) if denom > 0 else 1.0
    rms = float(np.sqrt(np.mean(gt * gt)))
    rel = float(np.sqrt(np.mean((gain * est - gt) ** 2)) / rms) if rms > 0 else float("nan")
    return {"rel_rmse": rel, "gain": gain, "coverage": coverage, "n_evaluated": n}


def _compare(value, threshold, comparison):
    if not np.isfinite(value):
        return False
    return {"<=": value <= threshold, "<": value < threshold, ">=": value >= threshold}[comparison]


def check_targets(report, *, noise="noise_free"):
    """Pass/fail of every target of `ACCURACY_TARGETS` for a report's shadow times.

    Parameters
    ----------
    report : dict
        With ``report["shadow_time"][sweep]`` from `shadow_time_errors`.
    noise : {"noise_free", "raw12"}, keyword-only
        Noise condition; selects the shadow-time p95 threshold.

    Returns
    -------
    list of dict
        ``target``, ``sweep``, ``value``, ``threshold``, ``comparison``, ``pass``.
    """
    p95 = ACCURACY_TARGETS["shadow_time_p95_frames"]
    check_in(noise, "noise", ("noise_free", "raw12"))
    rows = []
    for sweep, stats in report.get("shadow_time", {}).items():
        for target, key, threshold, comparison in (
            ("shadow_time_p95_frames", "p95", p95[noise], p95["comparison"]),
            ("shadow_time_coverage", "coverage", ACCURACY_TARGETS["shadow_time_coverage"]["threshold"],
             ACCURACY_TARGETS["shadow_time_coverage"]["comparison"]),
            ("false_time_rate", "false_time_rate", ACCURACY_TARGETS["false_time_rate"]["threshold"],
             ACCURACY_TARGETS["false_time_rate"]["comparison"]),
        ):
            value = stats[key]
            rows.append({"target": target, "sweep": sweep, "value": value, "threshold": threshold,
                         "comparison": comparison, "pass": bool(_compare(value, threshold, comparison))})
    return rows


def _dual_grid_map(dual_coords, ground_truth):
    """Homography from GT mask-plane coordinates (``t_u``, ``t_v``) to the dual grid.

    The uniform model's grid is an axis scaling of the mask plane. A
    calibration plane's grid is the plane window of the dual coordinates
    (attrs ``plane_window``, ``axes_flipped``, ``dual_width``,
    ``dual_height``); for a point light the mask plane and the calibration
    plane are related by the central projection from the light, a
    homography, fitted exactly to the GT calibration times and plane points.
    Returns None when the GT cannot express that grid.
    """
    attrs = dual_coords.attrs
    method = attrs.get("method", attrs.get("model"))
    if method == "uniform":
        scale = np.asarray(attrs.get("scale", (1.0, 1.0)), dtype=np.float64)
        offset = np.asarray(attrs.get("offset", (0.0, 0.0)), dtype=np.float64)
        return np.array([[scale[0], 0, offset[0]], [0, scale[1], offset[1]], [0, 0, 1.0]])
    if method not in ("uniform", "calibration"):  # a camera model's own grid
        from shadowcam.cameras.accuracy import camera_grid_map

        return camera_grid_map(attrs)
    needed = ("t_cal_u", "t_cal_v", "plane_xy")
    if method != "calibration" or not all(k in ground_truth for k in needed):
        return None
    import cv2

    times = np.stack([ground_truth["t_cal_u"].values, ground_truth["t_cal_v"].values], -1)
    plane = ground_truth["plane_xy"].values
    ok = np.all(np.isfinite(times), -1) & np.all(np.isfinite(plane), -1)
    if ok.sum() < 4:
        return None
    to_plane, _ = cv2.findHomography(times[ok].astype(np.float64), plane[ok].astype(np.float64), 0)
    x0, y0, x1, y1 = (float(w) for w in attrs["plane_window"])
    flip_x, flip_y = (bool(f) for f in attrs.get("axes_flipped", (False, False)))
    sx = float(attrs["dual_width"]) / (x1 - x0)
    sy = float(attrs["dual_height"]) / (y1 - y0)
    to_grid = np.array([
        [-sx if flip_x else sx, 0, (sx * x1 if flip_x else -sx * x0) - 0.5],
        [0, -sy if flip_y else sy, (sy * y1 if flip_y else -sy * y0) - 0.5],
        [0, 0, 1.0],
    ])
    return to_grid @ to_plane


def _map_points(homography, x, y):
    """:func:`~shadowcam.cameras.dual_coords.apply_homography` on coordinate arrays `x`, `y` of any shape."""
    from shadowcam.cameras.dual_coords import apply_homography

    mapped = apply_homography(homography, np.column_stack([np.ravel(x), np.ravel(y)]))
    return mapped[:, 0].reshape(np.shape(x)), mapped[:, 1].reshape(np.shape(x))


def _reciprocal_on_grid(ground_truth, grid_map, shape):
    """GT reciprocal render and camera visibility resampled onto a dual grid.

    Each grid pixel centre is mapped back to mask-plane coordinates (the
    reciprocal render's pixel grid: centre of column i is ``t_u = i``) and
    the render is interpolated bilinearly there (NaN outside it); visibility
    is taken from the nearest reciprocal pixel.
    """
    from scipy.ndimage import map_coordinates

    reciprocal = ground_truth["reciprocal"].transpose("v", "u", "channel").values.astype(np.float64)
    visible = ground_truth["dual_cam_visible"].transpose("v", "u").values
    rows, cols = np.indices(shape, dtype=np.float64)
    t_u, t_v = _map_points(np.linalg.inv(grid_map), cols, rows)
    h, w = visible.shape
    inside = (t_u >= -0.5) & (t_u <= w - 0.5) & (t_v >= -0.5) & (t_v <= h - 0.5)
    coords = np.stack([np.where(inside, t_v, 0), np.where(inside, t_u, 0)])
    resampled = np.stack([map_coordinates(reciprocal[..., c], coords, order=1, mode="nearest")
                          for c in range(reciprocal.shape[2])], axis=-1)
    resampled[~inside] = np.nan
    nearest = np.rint(coords).astype(np.intp)
    visible_on_grid = inside & visible[np.clip(nearest[0], 0, h - 1), np.clip(nearest[1], 0, w - 1)]
    return resampled, visible_on_grid


def reciprocal_on_dual_grid(ground_truth, shape, *, dual_coords=None):
    """The GT reciprocal render and camera visibility on the dual grid of `dual_coords`.

    The same resampling as the accuracy of the dual image, so that a figure
    compares the dual view with its ground truth pixel for pixel.

    Parameters
    ----------
    ground_truth : xarray.Dataset
        ``reciprocal (v, u, channel)``, ``dual_cam_visible (v, u)`` on the mask-plane
        (frame-index) grid; calibration grids also need ``t_cal_u``, ``t_cal_v``, ``plane_xy``.
    shape : (int, int)
        ``(height, width)`` of the dual grid.
    dual_coords : xarray.Dataset, optional
        Its attrs define the grid (``method``, ``scale``, ``offset`` or ``plane_window``);
        default: the dual grid is the reciprocal render's.

    Returns
    -------
    reciprocal : (height, width, channel) ndarray or None
        NaN outside the render; None when the ground truth cannot express the grid.
    visible : (height, width) bool ndarray or None
    """
    grid_map = np.eye(3) if dual_coords is None else _dual_grid_map(dual_coords, ground_truth)
    if grid_map is None:
        return None, None
    return _reciprocal_on_grid(ground_truth, grid_map, tuple(int(n) for n in shape))


def accuracy_report(shadow_time, ground_truth, *, dual_coords=None, dual_view=None,
                    pushbroom=None, reference=None, noise="noise_free", sweeps=("u", "v")):
    """Accuracy report of one dataset's products against its ground truth.

    Parameters
    ----------
    shadow_time : xarray.Dataset
        ``shadow_time (sweep, row, col)``.
    ground_truth : xarray.Dataset
        Standard GT form: ``t_u``, ``t_v``, ``lit`` over ``(row, col)``;
        ``reciprocal (v, u, channel)``, ``dual_cam_visible (v, u)``.
    dual_coords : xarray.Dataset, optional
        ``u``, ``v``, ``valid`` over ``(row, col)``.
    dual_view : xarray.Dataset, optional
        ``dual_view (v, u, channel)``, ``coverage (v, u)``.
    pushbroom : xarray.Dataset, optional
        Lab shadow pushbroom (:func:`shadowcam.cameras.pushbroom.pushbroom_from_shadow_time`).
    reference : (H, W, C) ndarray, optional
        The pushbroom's colour source (default the sweep's ``lit_image``).
    noise : {"noise_free", "raw12"}, keyword-only
        Noise condition of the capture (selects the shadow-time target).
    sweeps : sequence of str
        Scene sweeps to evaluate (GT ``t_<sweep>``).

    Returns
    -------
    dict
        ``shadow_time`` (per sweep), ``dual_model`` (``model`` and ``why``, from the dual
        coordinates' attrs), ``dual_coords``, ``dual_image``, ``pushbroom`` (with a pushbroom
        whose sweep has GT times, :func:`pushbroom_errors`), ``targets`` (list),
        ``all_targets_pass``, ``noise``.
    """
    lit = np.asarray(ground_truth["lit"].values, dtype=bool)
    report = {"noise": noise, "shadow_time": {}}
    names = [str(s) for s in shadow_time["sweep"].values]
    for sweep in sweeps:
        if sweep not in names or f"t_{sweep}" not in ground_truth:
            continue
        est = shadow_time["shadow_time"].sel(sweep=sweep).transpose("row", "col").values
        std = (shadow_time["time_std"].sel(sweep=sweep).transpose("row", "col").values
               if "time_std" in shadow_time else None)
        report["shadow_time"][sweep] = shadow_time_errors(
            est, ground_truth[f"t_{sweep}"].transpose("row", "col").values, lit=lit, time_std=std)
    # without dual coordinates the dual view is taken to be on the reciprocal grid
    grid_map = np.eye(3) if dual_coords is None else _dual_grid_map(dual_coords, ground_truth)
    if dual_coords is not None:
        report["dual_model"] = {"model": str(dual_coords.attrs.get("model", "")),
                                "why": str(dual_coords.attrs.get("model_choice", ""))}
        if grid_map is None:
            report["dual_coords"] = {"skipped": "the ground truth cannot express this dual grid"}
        else:
            true_u, true_v = _map_points(grid_map, ground_truth["t_u"].values.astype(np.float64),
                                         ground_truth["t_v"].values.astype(np.float64))
            report["dual_coords"] = dual_coord_errors(
                dual_coords["u"].values, dual_coords["v"].values, true_u, true_v,
                valid=dual_coords["valid"].values)
    if dual_view is not None:
        image = dual_view["dual_view"].transpose("v", "u", "channel").values
        if grid_map is None:
            report["dual_image"] = {"skipped": "the ground truth cannot express this dual grid"}
        else:
            if "intrinsics_affine" in dual_view.attrs:  # the view of chosen virtual intrinsics
                affine = np.asarray(dual_view.attrs["intrinsics_affine"], dtype=np.float64).reshape(2, 3)
                grid_map = np.vstack([affine, [0.0, 0.0, 1.0]]) @ grid_map
            reciprocal, visible = _reciprocal_on_grid(ground_truth, grid_map, image.shape[:2])
            report["dual_image"] = dual_image_errors(
                image, dual_view["coverage"].values, reciprocal, dual_cam_visible=visible)
    if pushbroom is not None and f"t_{pushbroom.attrs['sweep']}" in ground_truth:
        sweep, along = pushbroom.attrs["sweep"], pushbroom.attrs["along"]
        if reference is None:
            reference = shadow_time["lit_image"].sel(sweep=sweep).transpose("row", "col", "channel").values
        report["pushbroom"] = pushbroom_errors(
            pushbroom["pushbroom"].transpose("time", along, "channel").values,
            ground_truth[f"t_{sweep}"].transpose("row", "col").values, reference, along=along)
    report["targets"] = check_targets(report, noise=noise)
    report["all_targets_pass"] = bool(report["targets"]) and all(t["pass"] for t in report["targets"])
    return report


def flatten_report(report):
    """Flatten a nested report into ``(key, value)`` rows (keys joined by ``.``).

    Target rows become ``targets.<target>.<sweep>.value|threshold|pass``.
    """
    rows = []

    def walk(prefix, node):
        if isinstance(node, dict):
            for key, value in node.items():
                walk(f"{prefix}.{key}" if prefix else str(key), value)
        else:
            rows.append((prefix, node))

    for key, value in report.items():
        if key == "targets":
            for t in value:
                base = f"targets.{t['target']}.{t['sweep']}"
                rows += [(f"{base}.value", t["value"]), (f"{base}.threshold", t["threshold"]),
                         (f"{base}.pass", t["pass"])]
        else:
            walk(key, value)
    return rows


def _json_safe(node):
    if isinstance(node, dict):
        return {k: _json_safe(v) for k, v in node.items()}
    if isinstance(node, (list, tuple)):
        return [_json_safe(v) for v in node]
    if isinstance(node, (float, np.floating)):
        return float(node) if np.isfinite(node) else None
    if isinstance(node, np.integer):
        return int(node)
    if isinstance(node, np.bool_):
        return bool(node)
    return node


def report_to_json(report):
    """The report as indented JSON text (NaN/inf written as null)."""
    return json.dumps(_json_safe(report), indent=2, sort_keys=False) + "\n"


#: rows of the accuracy table per report section: key -> (quantity, unit, scale)
TABLE_ROWS = {
    "shadow_time": {
        "coverage": ("shadow time coverage", "%", 100.0),
        "median": ("shadow time |error| median", "frame", 1.0),
        "p95": ("shadow time |error| p95", "frame", 1.0),
        "rmse": ("shadow time RMSE", "frame", 1.0),
        "max": ("shadow time |error| max", "frame", 1.0),
        "frac_gt_1_frame": ("shadow time |error| > 1 frame", "%", 100.0),
        "mean_signed": ("shadow time mean signed error", "frame", 1.0),
        "false_time_rate": ("false times (unlit pixels given a time)", "%", 100.0),
        "unswept_time_rate": ("false times (lit pixels the sweep's shadow does not cross given a time)", "%", 100.0),
        "n_evaluated": ("pixels evaluated (lit, timed)", "pixel", 1.0),
        "n_uncertain": (f"pixels evaluated with time std > {CONFIDENT_STD:g} frame", "pixel", 1.0),
        "p95_confident": (f"shadow time |error| p95, time std <= {CONFIDENT_STD:g} frame", "frame", 1.0),
    },
    "dual_coords": {
        "coverage": ("dual coordinates coverage", "%", 100.0),
        "median": ("dual coordinates |error| median", "dual px", 1.0),
        "p95": ("dual coordinates |error| p95", "dual px", 1.0),
        "rmse": ("dual coordinates RMSE", "dual px", 1.0),
        "rmse_u": ("dual coordinates RMSE of u", "dual px", 1.0),
        "rmse_v": ("dual coordinates RMSE of v", "dual px", 1.0),
        "max": ("dual coordinates |error| max", "dual px", 1.0),
        "n_evaluated": ("camera pixels with dual coordinates", "pixel", 1.0),
    },
    "pushbroom": {
        "coverage": ("pushbroom coverage of the GT pushbroom", "%", 100.0),
        "rel_rmse": ("pushbroom relative RMSE", "%", 100.0),
        "gain": ("pushbroom gain fitted to the GT pushbroom", "1", 1.0),
        "n_evaluated": ("pushbroom cells evaluated", "cell", 1.0),
    },
    "dual_image": {
        "coverage_of_visible": ("dual view coverage of what the camera sees", "%", 100.0),
        "covered_not_visible": ("dual view covered where the camera sees nothing", "%", 100.0),
        "rel_rmse_masked": ("dual view relative RMSE, GT valid mask", "%", 100.0),
        "rel_rmse_whole": ("dual view relative RMSE, whole image", "%", 100.0),
        "gain": ("dual view gain fitted to the reciprocal render", "1", 1.0),
        "n_mask": ("dual pixels in the GT valid mask", "dual px", 1.0),
    },
    "straightness": {
        "primal_rms": ("straight edges: RMS distance from their line, primal view", "px", 1.0),
        "dual_rms": ("straight edges: RMS distance from their line, dual view", "dual px", 1.0),
        "n_edges": ("straight edges measured", "edge", 1.0),
    },
    "redundancy": {
        "rmse_two": ("dual coordinates RMSE from sweeps u, v alone", "dual px", 1.0),
        "rmse_all": ("dual coordinates RMSE from all sweeps", "dual px", 1.0),
        "reduction": ("dual coordinates RMSE lowered by the extra sweeps", "%", 100.0),
    },
}
#: rows of the dip-interval section, per sweep: the pixels with a measurable interval and
#: the absolute error of its entry, centre and exit (frames)
INTERVAL_ROWS = {
    "n_truth": ("dip interval: pixels whose whole dip lies in the sweep", "pixel", 1.0),
    "coverage": ("dip interval coverage", "%", 100.0),
    **{f"{part}.{stat}": (f"dip interval {part} |error| {label}", "frame", 1.0)
       for part in ("entry", "centre", "exit")
       for stat, label in (("median", "median"), ("p95", "p95"), ("rmse", "RMSE"), ("max", "max"))},
    "n_outer_truth": ("penumbra outer edges: pixels whose whole penumbra lies in the sweep", "pixel", 1.0),
    "outer_coverage": ("penumbra outer edges coverage", "%", 100.0),
    **{f"{part}.{stat}": (f"penumbra {part} |error| {label}", "frame", 1.0)
       for part in ("first", "last")
       for stat, label in (("median", "median"), ("p95", "p95"), ("rmse", "RMSE"), ("max", "max"))},
}
#: target name -> the report key it checks (per sweep of ``shadow_time``; sweep None: a section)
TARGET_KEYS = {"shadow_time_p95_frames": "p95", "shadow_time_coverage": "coverage",
               "false_time_rate": "false_time_rate", "dual_straightness_rms_px": "dual_rms"}
#: what the ground truth is (shown with the table)
GROUND_TRUTH_DEFINITION = (
    "Ground truth: exact per-pixel shadow times t_u, t_v (frame at which the wire's shadow line "
    "crosses the pixel centre, from ray casting the rendered geometry; NaN where unlit) and the "
    "reciprocal render from the light (docs/architecture.md, 'Datasets between stages', lab ground "
    "truth; shared data README section 1)."
)


def accuracy_table(report):
    """The report as a table a reader scans: one row per quantity, targets on their quantity's row.

    Parameters
    ----------
    report : dict
        From :func:`accuracy_report` (the ``noise_source`` and ``dataset`` keys are optional).

    Returns
    -------
    list of dict
        Rows of :func:`shadowcam._shared.quantity_table.quantity_row` (``quantity``, ``value``,
        ``unit``, ``target``, ``pass``), values to three significant digits: the sections of
        :data:`TABLE_ROWS`, then the dip interval per sweep (:data:`INTERVAL_ROWS`) and each
        viewpoint's dual image (the ``dual_image`` rows, suffixed ``, viewpoint <name>``).
    """
    targets = {(TARGET_KEYS.get(t["target"]), t["sweep"]): t for t in report.get("targets", [])}
    rows = []
    for section, spec in TABLE_ROWS.items():
        node = report.get(section)
        if node is None:
            continue
        parts = node.items() if section == "shadow_time" else [(None, node)]
        for sweep, stats in parts:
            suffix = f", sweep {sweep}" if sweep is not None else ""
            if "skipped" in stats:
                rows.append(quantity_row(f"{section.replace('_', ' ')}{suffix}", f"skipped: {stats['skipped']}"))
                continue
            for key, (quantity, unit, scale) in spec.items():
                if key in stats:
                    rows.append(quantity_row(quantity + suffix, stats[key], unit, scale=scale,
                                             target=targets.get((key, sweep))))
    for sweep, stats in report.get("interval", {}).items():
        flat = {f"{part}.{k}": v for part, node in stats.items() if isinstance(node, dict) for k, v in node.items()}
        for key, (quantity, unit, scale) in INTERVAL_ROWS.items():
            value = stats.get(key, flat.get(key))
            if value is not None:
                rows.append(quantity_row(f"{quantity}, sweep {sweep}", value, unit, scale=scale))
    for name, stats in report.get("viewpoints", {}).items():
        suffix = f", viewpoint {name}"
        if "skipped" in stats:
            rows.append(quantity_row(f"dual view{suffix}", f"skipped: {stats['skipped']}"))
            continue
        rows += [quantity_row(quantity + suffix, stats[key], unit, scale=scale)
                 for key, (quantity, unit, scale) in TABLE_ROWS["dual_image"].items() if key in stats]
    if "dual_model" in report:
        model = report["dual_model"]
        rows.append(quantity_row("dual model", model["why"] or model["model"]))  # why starts with the model
    noise = report.get("noise")
    if report.get("noise_source"):
        noise = f"{noise} (from {report['noise_source']})"
    rows.append(quantity_row("noise condition", noise))
    rows.append(quantity_row("all targets pass", report.get("all_targets_pass")))
    if "dataset" in report:
        rows.append(quantity_row("dataset", report["dataset"]))
    return rows


def report_to_csv(report):
    """The report's :func:`accuracy_table` as CSV text (``quantity,value,unit,target,pass``)."""
    return table_to_csv(accuracy_table(report))


def noise_condition(manifest, noise=None):
    """The noise condition that selects the shadow-time target, and its source.

    Parameters
    ----------
    manifest : mapping
        Loaded manifest: ``ground_truth.noise``, else ``synthetic.noise`` (True: ``raw12``).
    noise : str, optional
        Explicit condition (wins).

    Returns
    -------
    noise : str
        ``noise_free`` or ``raw12`` (or the declared name).
    source : str
        ``--params``, ``manifest ground_truth.noise``, ``manifest synthetic.noise`` or ``default``.
    """
    synthetic = manifest.get("synthetic") or {}
    declared = (manifest.get("ground_truth") or {}).get("noise")
    if noise is not None:
        return noise, "--params"
    if declared:
        return declared, "manifest ground_truth.noise"
    if "noise" in synthetic:
        return ("raw12" if synthetic["noise"] else "noise_free"), "manifest synthetic.noise"
    return "noise_free", "default"


def interval_errors(shadow_time, ground_truth, *, sweeps=("u", "v")):
    """Errors of the dip interval's entry, centre and exit (and outer edges) against their exact times.

    Parameters
    ----------
    shadow_time : xarray.Dataset
        ``interval_entry``, ``interval_exit`` over ``(sweep, row, col)``.
    ground_truth : xarray.Dataset
        ``lit`` and, per sweep, ``interval_entry_<sweep>``, ``interval_exit_<sweep>``
        (row, col): the half-depth crossings the tracker measures (the rendered capture
        of an area light, ``synthetic.lab.render``), and ``penumbra_first_<sweep>``,
        ``penumbra_last_<sweep>`` when it has them (the dip's outer edges).
    sweeps : sequence of str, keyword-only

    Returns
    -------
    dict
        Per sweep with truth: ``n_truth`` (lit pixels whose whole dip, from the penumbra's
        first to its last frame, or the half-depth interval without them, lies within the
        sweep's frames ``0 .. shadow_time.attrs["n_frames_<sweep>"] - 1``: only those have
        a measurable entry and exit),
        ``coverage`` (their share with an estimated interval), and ``entry``, ``centre``,
        ``exit``: median, p95, RMSE, max of the absolute error in frames. Where both
        `shadow_time` (the penumbra law of wide dips, ``penumbra_first``, ``penumbra_last``)
        and the truth have the outer edges, also ``n_outer_truth`` (lit pixels whose whole
        penumbra lies in the sweep, with or without a half-hidden truth), ``outer_coverage``
        (their share with both edges) and ``first``, ``last``: the same statistics of
        their errors.
    """
    missing = {"interval_entry", "interval_exit"} - set(shadow_time)
    if missing:
        raise ValueError(f"shadow_time: has no {sorted(missing)}; recompute it with the current shadow-time step")
    lit = np.asarray(ground_truth["lit"].values, dtype=bool)
    names = [str(s) for s in shadow_time["sweep"].values]
    out = {}
    for sweep in sweeps:
        keys = (f"interval_entry_{sweep}", f"interval_exit_{sweep}")
        if sweep not in names or any(k not in ground_truth for k in keys):
            continue
        true_entry, true_exit = (ground_truth[k].transpose("row", "col").values.astype(np.float64) for k in keys)
        entry, exit_ = (shadow_time[k].sel(sweep=sweep).transpose("row", "col").values.astype(np.float64)
                        for k in ("interval_entry", "interval_exit"))
        first, last = true_entry, true_exit
        if f"penumbra_first_{sweep}" in ground_truth and f"penumbra_last_{sweep}" in ground_truth:
            first, last = (ground_truth[f"penumbra_{k}_{sweep}"].transpose("row", "col").values.astype(np.float64)
                           for k in ("first", "last"))
        n_frames = shadow_time.attrs.get(f"n_frames_{sweep}", np.inf)
        with np.errstate(invalid="ignore"):
            inside = (first >= 0) & (last <= float(n_frames) - 1)
        truth = lit & np.isfinite(true_entry) & np.isfinite(true_exit) & inside
        found = truth & np.isfinite(entry) & np.isfinite(exit_)
        out[sweep] = {
            "n_truth": int(truth.sum()),
            "coverage": float(found.sum() / truth.sum()) if truth.any() else float("nan"),
            "entry": _stats(np.abs(entry - true_entry)[found]),
            "centre": _stats(np.abs(0.5 * (entry + exit_) - 0.5 * (true_entry + true_exit))[found]),
            "exit": _stats(np.abs(exit_ - true_exit)[found]),
        }
        if first is not true_entry and {"penumbra_first", "penumbra_last"} <= set(shadow_time):
            # every lit pixel whose whole penumbra lies in the sweep (also where the source is
            # never half hidden, a wire narrower than it: no half-depth truth)
            outer_truth = lit & np.isfinite(first) & np.isfinite(last) & inside
            outer_first, outer_last = (shadow_time[k].sel(sweep=sweep).transpose("row", "col").values.astype(np.float64)
                                       for k in ("penumbra_first", "penumbra_last"))
            outer = outer_truth & np.isfinite(outer_first) & np.isfinite(outer_last)
            out[sweep].update(
                n_outer_truth=int(outer_truth.sum()),
                outer_coverage=float(outer.sum() / outer_truth.sum()) if outer_truth.any() else float("nan"),
                first=_stats(np.abs(outer_first - first)[outer]), last=_stats(np.abs(outer_last - last)[outer]))
    return out


def viewpoint_image_errors(ground_truth, viewpoint, *, shadow_time, dual_coords, dual_view):
    """A viewpoint's dual view against its reciprocal render after one gain fit.

    The same comparison as the main dual view (:func:`dual_image_errors` on the grid of
    `dual_coords`), with the ground truth's ``reciprocal_<viewpoint>`` and
    ``dual_cam_visible_<viewpoint>`` as the reciprocal render.

    Parameters
    ----------
    ground_truth : xarray.Dataset
    viewpoint : str
        A viewpoint name the ground truth renders (e.g. ``entry``).
    shadow_time, dual_coords, dual_view : xarray.Dataset, keyword-only
        The viewpoint's products (``results/<ds>/viewpoints/<viewpoint>/``).

    Returns
    -------
    dict
        Keys of :func:`dual_image_errors`, or ``skipped`` (why) when the ground truth has
        no reciprocal render of the viewpoint or cannot express the dual grid.
    """
    keys = (f"reciprocal_{viewpoint}", f"dual_cam_visible_{viewpoint}")
    if any(k not in ground_truth for k in keys):
        return {"skipped": f"the ground truth has no reciprocal render of viewpoint {viewpoint!r}"}
    truth = ground_truth.assign(reciprocal=ground_truth[keys[0]], dual_cam_visible=ground_truth[keys[1]])
    report = accuracy_report(shadow_time, truth, dual_coords=dual_coords, dual_view=dual_view, sweeps=())
    return report["dual_image"]


def add_interval_checks(report, shadow_time, ground_truth, *, viewpoints=None):
    """Add the dip interval (``report["interval"]``) and viewpoint (``report["viewpoints"]``)
    sections to an accuracy report, when the ground truth has what they need.

    Parameters
    ----------
    report : dict
        From :func:`accuracy_report`; updated in place.
    shadow_time, ground_truth : xarray.Dataset
    viewpoints : dict of str to (xarray.Dataset, xarray.Dataset, xarray.Dataset), optional
        Viewpoint name -> its ``(shadow_time, dual_coords, dual_view)``.

    Returns
    -------
    dict
        `report`.
    """
    if "interval_entry" in shadow_time and any(str(k).startswith("interval_entry_") for k in ground_truth):
        report["interval"] = interval_errors(shadow_time, ground_truth)
    if viewpoints:
        report["viewpoints"] = {
            name: viewpoint_image_errors(ground_truth, name, shadow_time=st, dual_coords=coords, dual_view=view)
            for name, (st, coords, view) in viewpoints.items()}
    return report
