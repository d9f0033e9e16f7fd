"""Ray correspondence: the far point of each near pixel's mask coordinates on a curved ray family."""

import numpy as np
from scipy.interpolate import LinearNDInterpolator

from shadowcam.lightfield import rays

C = 2e-3  # the family's slope grows as 1 + C r^2 (mm^-2 at the mask plane, z = 50 mm)


def _direction(mask):
    return mask / 50.0 * (1 + C * np.sum(mask**2, -1))[..., None]


def _mask_of(xy, z):
    # invert the radial hit map r_screen = r (1 + alpha (1 + C r^2)), alpha = (z - 50) / 50 (Newton)
    alpha = (z - 50.0) / 50.0
    rs = np.hypot(xy[..., 0], xy[..., 1])
    r = rs / (1 + alpha)
    for _ in range(30):
        r -= (alpha * C * r**3 + (1 + alpha) * r - rs) / (3 * alpha * C * r**2 + 1 + alpha)
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.where(rs > 0, r / rs, 1 / (1 + alpha))
    return xy * scale[..., None]


def _curved_screen(z, n=32, pitch=1.0):
    r, c = np.mgrid[:n, :n].astype(float)
    xy = np.stack([(c - (n - 1) / 2) * pitch, (r - (n - 1) / 2) * pitch], -1) * z / 100.0
    return {"mask": _mask_of(xy, z), "mask_std": np.full((n, n), 0.01), "xy": xy,
            "area": np.full((n, n), (pitch * z / 100) ** 2), "irradiance": np.ones((n, n)),
            "ok": np.ones((n, n), bool), "position_mm": float(z)}


def test_far_point_follows_the_curvature_of_the_far_map():
    near, far = _curved_screen(100.0), _curved_screen(200.0)
    truth = _direction(near["mask"])                       # exact mask points: only the far map's interpolation errs
    got = rays.rays_dataset(near, far, anchor="near")["direction"].values[..., :2]
    inner = (slice(2, -2), slice(2, -2))                   # away from the far grid's hull
    error = np.hypot(*(got - truth)[inner].reshape(-1, 2).T)
    linear = LinearNDInterpolator(far["mask"].reshape(-1, 2), far["xy"].reshape(-1, 2))(near["mask"])
    linear_error = np.hypot(*((linear - near["xy"]) / 100.0 - truth)[inner].reshape(-1, 2).T)
    # measured: max 1.1e-5, median 6e-8 (piecewise-linear: 1.1e-4, 3.2e-5); directions up to 0.17
    assert error.max() < 3e-5 and error.max() < 0.2 * linear_error.max()
    assert np.median(error) < 1e-6 < np.median(linear_error)


def test_a_dark_pixels_negative_hdr_estimate_carries_no_flux():
    near, far = _curved_screen(100.0), _curved_screen(200.0)
    near["irradiance"] = np.where(np.arange(32)[None, :] < 4, -0.01, 1.0) * np.ones((32, 1))  # read noise below 0
    ray_set = rays.rays_dataset(near, far, anchor="near")
    assert np.all(ray_set["flux"].values[:, :4] == 0) and np.all(ray_set["flux"].values[:, 4:] > 0)
    assert np.all(ray_set["irradiance"].values[:, :4] < 0)  # the measurement itself is kept
