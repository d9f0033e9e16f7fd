"""Accuracy of a light-field capture against ground truth, and the naive baseline.

Offers
------
naive_baseline : the nearest captured screen image rescaled by inverse square and magnification.
relative_rmse_gain : relative RMSE after the one least-squares gain.
bandpass_correlation : correlation of difference-of-Gaussians band-passed images.
bandpass_error : relative RMSE (one gain) of difference-of-Gaussians band-passed images.
far_field_error : median relative intensity error over the directions of the beam.
TARGETS : the accuracy targets.
lightfield_accuracy : renders, far field and coverage of a capture scored against ground truth.
accuracy_rows : the scores as quantity-table rows.
"""

import numpy as np
from scipy.ndimage import gaussian_filter, map_coordinates

from shadowcam._shared.validation import check_array, check_positive, check_same_shape


def naive_baseline(image, xy, *, position_mm, target_position_mm, target_shape, pixel_size):
    """Nearest captured screen rescaled: ``E(x) = E_k(x z_k / z) (z_k / z)**2``.

    Parameters
    ----------
    image : (H, W) ndarray
        Irradiance of the captured screen (lux) on its camera pixels.
    xy : (H, W, 2) ndarray
        Screen ``x, y`` mm of those pixels.
    position_mm, target_position_mm : float, keyword-only
        Distances of the captured and the target screen from the source.
    target_shape : (rows, cols), keyword-only
    pixel_size : float, keyword-only
        Target grid pitch, mm (the grid of :func:`shadowcam.lightfield.render.irradiance_on_plane`).

    Returns
    -------
    (rows, cols) float64 ndarray
    """
    image = check_array(image, "image", ndim=2)
    check_same_shape({"image": image, "xy[..., 0]": xy[..., 0]})
    check_positive(position_mm, "position_mm", finite=True)
    check_positive(target_position_mm, "target_position_mm", finite=True)
    check_positive(pixel_size, "pixel_size", finite=True)
    ratio = position_mm / target_position_mm
    rows = (np.arange(target_shape[0]) - (target_shape[0] - 1) / 2) * pixel_size
    cols = (np.arange(target_shape[1]) - (target_shape[1] - 1) / 2) * pixel_size
    ty, tx = np.meshgrid(rows * ratio, cols * ratio, indexing="ij")
    # invert the captured pixel grid's affine approximation (least squares on its xy)
    h, w = image.shape
    r, c = np.meshgrid(np.arange(h), np.arange(w), indexing="ij")
    design = np.c_[xy[..., 0].ravel(), xy[..., 1].ravel(), np.ones(h * w)]
    coef, *_ = np.linalg.lstsq(design, np.c_[r.ravel(), c.ravel()], rcond=None)
    pr = coef[0, 0] * tx + coef[1, 0] * ty + coef[2, 0]
    pc = coef[0, 1] * tx + coef[1, 1] * ty + coef[2, 1]
    values = map_coordinates(np.nan_to_num(image), [pr, pc], order=1, cval=0.0)
    return values * ratio**2


def _gain(estimate, truth):
    """Least-squares gain ``argmin_g ||g estimate - truth||`` over finite pixels."""
    estimate = np.asarray(estimate, np.float64)
    truth = np.asarray(truth, np.float64)
    check_same_shape({"estimate": estimate, "truth": truth})
    keep = np.isfinite(estimate) & np.isfinite(truth)
    e, t = estimate[keep], truth[keep]
    return (e @ t) / (e @ e) if e @ e > 0 else 0.0


def relative_rmse_gain(estimate, truth):
    """``min_g ||g estimate - truth|| / ||truth||`` over finite pixels."""
    estimate = np.asarray(estimate, np.float64)
    truth = np.asarray(truth, np.float64)
    keep = np.isfinite(estimate) & np.isfinite(truth)
    gain = _gain(estimate, truth)
    return float(np.linalg.norm(gain * estimate[keep] - truth[keep]) / np.linalg.norm(truth[keep]))


def _bandpassed(estimate, truth, sigmas):
    estimate = np.nan_to_num(np.asarray(estimate, np.float64))
    truth = np.nan_to_num(np.asarray(truth, np.float64))
    check_same_shape({"estimate": estimate, "truth": truth})
    return [gaussian_filter(a, sigmas[0]) - gaussian_filter(a, sigmas[1]) for a in (estimate, truth)]


def bandpass_correlation(estimate, truth, *, sigmas=(1.0, 4.0)):
    """Pearson correlation of the images band-passed by a difference of Gaussians (pixels)."""
    a, b = _bandpassed(estimate, truth, sigmas)
    return float(np.corrcoef(a.ravel(), b.ravel())[0, 1])


def bandpass_error(estimate, truth, *, sigmas=(1.0, 4.0)):
    """``||g B(estimate) - B(truth)|| / ||B(truth)||``: the band-passed images' relative error.

    ``B`` is the difference of Gaussians (`sigmas`, pixels) and ``g`` the one gain fitted
    on the whole images (:func:`relative_rmse_gain`'s). It scores the ring pattern's fine
    structure (periods between about ``2 pi sigmas[0]`` and ``2 pi sigmas[1]`` pixels) in
    amplitude and position: 0 when it is reproduced, 1 when it is missing (smoothed
    away), up to 2 when it is inverted.
    """
    a, b = _bandpassed(estimate, truth, sigmas)
    return float(np.linalg.norm(_gain(estimate, truth) * a - b) / np.linalg.norm(b))


def far_field_error(estimate, truth, *, floor=0.05):
    """Median relative error ``|I - I_true| / I_true`` over directions with ``I_true > floor * max``."""
    estimate = np.asarray(estimate, np.float64)
    truth = np.asarray(truth, np.float64)
    check_same_shape({"estimate": estimate, "truth": truth})
    keep = truth > floor * truth.max()
    return float(np.median(np.abs(estimate[keep] - truth[keep]) / truth[keep]))


#: targets of the light-field accuracy (issue figures): render/baseline error ratio, band-passed
#: correlation, band-passed error of the render below the baseline's, far-field median error
TARGETS = {"render_ratio": 0.5, "bandpass_correlation": 0.9, "bandpass_error_ratio": 1.0, "far_field_error": 0.05}


def _target(value, threshold, comparison):
    ok = value <= threshold if comparison == "<=" else value >= threshold
    return {"threshold": threshold, "comparison": comparison, "pass": bool(ok)}


def lightfield_accuracy(renders, far_field, screens, truth, *, far_truth, flags):
    """Scores of a light-field capture against ground truth.

    Parameters
    ----------
    renders : xarray.Dataset
        :func:`shadowcam.lightfield.stages.render_positions` (``irradiance (position, row, col)``).
    far_field : (S, S) ndarray
        Estimated intensity per cell of the equal-area direction chart
        (:func:`shadowcam.lightfield.photometry_export.far_field_grid`, cd).
    screens : list of dict
        Captured screens nearest first: ``position_mm``, ``irradiance`` (H, W) lux, ``xy`` (H, W, 2) mm.
    truth : (P, rows, cols) ndarray
        True irradiance (lux) on each render's grid, in the renders' position order.
    far_truth : (S, S) ndarray, keyword-only
        True intensity integrated over the same cells (cd).
    flags : (H, W) ndarray, keyword-only
        Ray flags (:data:`shadowcam.lightfield.rays.REASONS`), for the coverage.

    Returns
    -------
    dict
        ``renders``: per position ``rmse_render``, ``rmse_baseline`` (relative, one gain fit),
        ``ratio``, ``bandpass_render``, ``bandpass_baseline`` (correlations),
        ``bandpass_error_render``, ``bandpass_error_baseline`` (:func:`bandpass_error`) and
        their ``targets``; ``far_field``: ``median_error`` with target and the cell size
        ``resolution_deg``; ``coverage``:
        fraction of pixels with a ray.
    """
    truth = check_array(truth, "truth", ndim=3, shape=renders["irradiance"].shape)
    positions = [s["position_mm"] for s in screens]
    out = {"renders": {}, "coverage": float(np.mean(np.asarray(flags) == 0))}
    for k, z in enumerate(renders["position"].values):
        image = renders["irradiance"].values[k]
        pitch = float(renders["pixel_size"].values[k])
        expected = truth[k]
        nearest = screens[int(np.argmin(np.abs(np.asarray(positions) - z)))]
        baseline = naive_baseline(nearest["irradiance"], nearest["xy"], position_mm=nearest["position_mm"],
                                  target_position_mm=float(z), target_shape=image.shape, pixel_size=pitch)
        rmse, base = relative_rmse_gain(image, expected), relative_rmse_gain(baseline, expected)
        corr = bandpass_correlation(image, expected)
        band, band_base = bandpass_error(image, expected), bandpass_error(baseline, expected)
        out["renders"][f"{z:g}"] = {
            "position_mm": float(z), "pixel_size_mm": pitch, "rmse_render": rmse, "rmse_baseline": base,
            "ratio": rmse / base, "bandpass_render": corr, "bandpass_baseline": bandpass_correlation(baseline, expected),
            "bandpass_error_render": band, "bandpass_error_baseline": band_base,
            "targets": {"ratio": _target(rmse / base, TARGETS["render_ratio"], "<="),
                        "bandpass_render": _target(corr, TARGETS["bandpass_correlation"], ">="),
                        "bandpass_error": _target(band / band_base, TARGETS["bandpass_error_ratio"], "<=")},
        }
    error = far_field_error(np.asarray(far_field), far_truth)
    out["far_field"] = {"median_error": error, "resolution_deg": getattr(far_field, "attrs", {}).get("resolution_deg"),
                        "targets": {"median_error": _target(error, TARGETS["far_field_error"], "<=")}}
    return out


def accuracy_rows(scores):
    """Quantity-table rows (:func:`shadowcam._shared.quantity_table.quantity_row`) of :func:`lightfield_accuracy`."""
    from shadowcam._shared.quantity_table import quantity_row

    rows = []
    for key, r in scores["renders"].items():
        rows += [quantity_row(f"render at {key} mm: rel. RMSE (one gain)", r["rmse_render"]),
                 quantity_row(f"naive baseline at {key} mm: rel. RMSE (one gain)", r["rmse_baseline"]),
                 quantity_row(f"render / baseline error at {key} mm", r["ratio"], target=r["targets"]["ratio"]),
                 quantity_row(f"band-passed correlation DoG(1, 4 px) at {key} mm", r["bandpass_render"],
                              target=r["targets"]["bandpass_render"]),
                 quantity_row(f"band-passed rel. RMSE DoG(1, 4 px) at {key} mm", r["bandpass_error_render"]),
                 quantity_row(f"naive baseline band-passed rel. RMSE at {key} mm", r["bandpass_error_baseline"]),
                 quantity_row(f"band-passed error render / baseline at {key} mm",
                              r["bandpass_error_render"] / r["bandpass_error_baseline"],
                              target=r["targets"]["bandpass_error"])]
    far = scores["far_field"]
    if far.get("resolution_deg") is not None:
        rows.append(quantity_row("far-field cell (capture's angular resolution)", far["resolution_deg"], "deg"))
    rows.append(quantity_row("far-field intensity median |error|", far["median_error"], "%", scale=100.0,
                             target=far["targets"]["median_error"]))
    rows.append(quantity_row("pixels with a ray", scores["coverage"], "%", scale=100.0))
    return rows
