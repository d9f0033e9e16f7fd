"""Accuracy of a light-field capture against ground truth, and the naive baseline.

Offers
------
naive_baseline : the nearest captured screen image rescaled by inverse square and magnification.
relative_rmse_gain : relative RMSE after the one least-squares gain.
bandpass_correlation : correlation of difference-of-Gaussians band-passed images.
far_field_error : median relative intensity error over the directions of the beam.
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


def relative_rmse_gain(estimate, truth):
    """``min_g ||g estimate - truth|| / ||truth||`` over finite pixels."""
    estimate = np.asarray(estimate, np.float64)
    truth = np.asarray(truth, np.float64)
    check_same_shape({"estimate": estimate, "truth": truth})
    keep = np.isfinite(estimate) & np.isfinite(truth)
    e, t = estimate[keep], truth[keep]
    gain = (e @ t) / (e @ e) if e @ e > 0 else 0.0
    return float(np.linalg.norm(gain * e - t) / np.linalg.norm(t))


def bandpass_correlation(estimate, truth, *, sigmas=(1.0, 4.0)):
    """Pearson correlation of the images band-passed by a difference of Gaussians (pixels)."""
    estimate = np.nan_to_num(np.asarray(estimate, np.float64))
    truth = np.nan_to_num(np.asarray(truth, np.float64))
    check_same_shape({"estimate": estimate, "truth": truth})
    a = gaussian_filter(estimate, sigmas[0]) - gaussian_filter(estimate, sigmas[1])
    b = gaussian_filter(truth, sigmas[0]) - gaussian_filter(truth, sigmas[1])
    return float(np.corrcoef(a.ravel(), b.ravel())[0, 1])


def far_field_error(estimate, truth, *, floor=0.05):
    """Median relative error ``|I - I_true| / I_true`` over directions with ``I_true > floor * max``."""
    estimate = np.asarray(estimate, np.float64)
    truth = np.asarray(truth, np.float64)
    check_same_shape({"estimate": estimate, "truth": truth})
    keep = truth > floor * truth.max()
    return float(np.median(np.abs(estimate[keep] - truth[keep]) / truth[keep]))
