"""Ray directions estimated by a weighted local-linear fit over neighbouring rays.

A ray's direction is the difference of its far and near screen points over the screens'
separation. The near point is the pixel centre (exact); the far point is where the
far screen sees the ray's mask coordinates, so it carries the noise of both screens'
mask positions (``time_std * |mask_step|`` per sweep), magnified by the far screen's
mm per mask mm ``g``::

    std(direction, per axis) = g * hypot(mask_std_near, mask_std_far) / sqrt(2) / (z_far - z_near)

(``mask_std`` holds both sweeps' std in quadrature, hence the ``sqrt(2)`` per axis).

The direction field of a compact source is a smooth function of the near-screen
point (caustics are folds of the *hit* map, not of the direction field), so each
ray's direction is estimated by a local-linear fit over its neighbours in the
near-screen (pixel) coordinates, Gaussian kernel of ``h`` pixels, weights ``1 / var``.
The fit's variance follows from the weights; its bias is ``h**2 / 2`` times the
field's Laplacian (the kernel's second moment), estimated from a pilot fit. Each ray
takes the ``h`` of least estimated mean-square error (variance + bias**2), including
``h = 0`` (its own measured direction), so the neighbourhood grows where the field is
flat against the noise and shrinks where it curves. Flux is not touched.

Offers
------
BANDWIDTHS : candidate kernel widths (pixels) of the fit.
direction_noise : per-axis direction std of each ray from the screens' mask-position std.
local_linear_fit : weighted local-linear estimate of a field and its std at one kernel width.
fit_directions : directions of least estimated mean-square error over the kernel widths.
"""

import numpy as np
from scipy.ndimage import correlate1d, median_filter

from shadowcam._shared.validation import check_array, check_positive, check_same_shape

#: candidate kernel widths (Gaussian sigma, pixels); 0 = the ray's own measurement
BANDWIDTHS = (0.0, 0.7, 1.0, 1.4, 2.0, 2.8, 4.0)
#: kernel width of the pilot fit whose Laplacian estimates the fit's bias
PILOT_BANDWIDTH = 2.0


def direction_noise(near_mask_std, far_mask_std, magnification, *, separation_mm):
    """Per-axis standard deviation of each ray's direction (dz = 1).

    Parameters
    ----------
    near_mask_std, far_mask_std : (H, W) ndarray
        Mask-position std (mm, both sweeps in quadrature) of the near pixel and of the far
        screen at the matched point.
    magnification : (H, W) ndarray
        Far-screen mm per mask mm at the matched point.
    separation_mm : float, keyword-only
        Far minus near screen position.

    Returns
    -------
    (H, W) ndarray
    """
    check_same_shape({"near_mask_std": near_mask_std, "far_mask_std": far_mask_std, "magnification": magnification})
    check_positive(separation_mm, "separation_mm", finite=True)
    return np.abs(magnification) * np.hypot(near_mask_std, far_mask_std) / np.sqrt(2.0) / separation_mm


def far_magnification(mask, xy, ok):
    """Screen mm per mask mm of each pixel of a screen, ``sqrt(|det d xy / d mask|)``, median over 5 x 5 pixels.

    Parameters
    ----------
    mask, xy : (H, W, 2) ndarray
        Mask and screen coordinates of the screen's pixels.
    ok : (H, W) bool ndarray
        Pixels with a mask position.

    Returns
    -------
    (H, W) ndarray
        NaN where no neighbour has a mask position.
    """
    def det(a):
        dr = np.gradient(a, axis=0)
        dc = np.gradient(a, axis=1)
        return dr[..., 0] * dc[..., 1] - dr[..., 1] * dc[..., 0]

    with np.errstate(invalid="ignore", divide="ignore"):
        g = np.sqrt(np.abs(det(xy)) / np.abs(det(np.where(ok[..., None], mask, np.nan))))
    g = np.where(np.isfinite(g), g, np.nan)
    # NaN-aware median: a median of the finite values in the window
    filled = np.where(np.isfinite(g), g, np.inf)
    high = median_filter(filled, size=5, mode="nearest")
    low = median_filter(np.where(np.isfinite(g), g, -np.inf), size=5, mode="nearest")
    with np.errstate(invalid="ignore"):
        out = 0.5 * (high + low)
    return np.where(np.isfinite(out), out, np.nan)


def _kernel(h):
    radius = max(1, int(np.ceil(3 * h)))
    u = np.arange(-radius, radius + 1, dtype=np.float64)
    return u, np.exp(-0.5 * (u / h) ** 2)


def _smooth(a, k):
    return correlate1d(correlate1d(a, k, axis=0, mode="constant"), k, axis=1, mode="constant")


def local_linear_fit(values, std, *, bandwidth):
    """Weighted local-linear fit of a field on a pixel grid, evaluated at every pixel.

    Parameters
    ----------
    values : (H, W, C) ndarray
        Measured field (NaN where not measured).
    std : (H, W) ndarray
        Per-component std of each measurement (NaN or inf where not measured).
    bandwidth : float, keyword-only
        Gaussian kernel sigma in pixels (> 0).

    Returns
    -------
    estimate : (H, W, C) ndarray
        The fit's value at each pixel (also where not measured, from its neighbours);
        NaN where the neighbours do not determine a plane.
    estimate_std : (H, W) ndarray
        Its std from the weights (``(A^-1 M A^-1)[0, 0]``, ``A`` the weighted normal
        matrix and ``M`` the same with squared kernel weights).
    """
    values = check_array(values, "values", ndim=3, dtype_kind="f")
    check_same_shape({"values[..., 0]": values[..., 0], "std": std})
    check_positive(bandwidth, "bandwidth", finite=True)
    measured = np.all(np.isfinite(values), axis=-1) & np.isfinite(std) & (std > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        w = np.where(measured, 1.0 / np.where(measured, std, 1.0) ** 2, 0.0)
    y = np.where(measured[..., None], values, 0.0)
    _, k = _kernel(bandwidth)
    rows, cols = np.meshgrid(np.arange(values.shape[0], dtype=np.float64),
                             np.arange(values.shape[1], dtype=np.float64), indexing="ij")
    # moments about each pixel: sum K(u) w u^a, u = neighbour - centre
    basis = [np.ones_like(rows), rows, cols]
    raw = {}
    for kernel_name, kern in (("k", k), ("k2", k ** 2)):
        for i in range(3):
            for j in range(i, 3):
                raw[kernel_name, i, j] = _smooth(w * basis[i] * basis[j], kern)
    centre = [None, rows, cols]

    def moment(kernel_name, i, j):
        # sum K w (x_i - c_i)(x_j - c_j) with x_0 = 1 (c_0 = 0)
        if i == 0 and j == 0:
            return raw[kernel_name, 0, 0]
        if i == 0:
            return raw[kernel_name, 0, j] - centre[j] * raw[kernel_name, 0, 0]
        return (raw[kernel_name, i, j] - centre[i] * raw[kernel_name, 0, j] - centre[j] * raw[kernel_name, 0, i]
                + centre[i] * centre[j] * raw[kernel_name, 0, 0])

    a = np.empty(values.shape[:2] + (3, 3))
    m = np.empty_like(a)
    for i in range(3):
        for j in range(i, 3):
            a[..., i, j] = a[..., j, i] = moment("k", i, j)
            m[..., i, j] = m[..., j, i] = moment("k2", i, j)
    rhs = np.empty(values.shape[:2] + (3, values.shape[2]))
    for c in range(values.shape[2]):
        t0 = _smooth(w * y[..., c], k)
        tr = _smooth(w * y[..., c] * rows, k) - rows * t0
        tc = _smooth(w * y[..., c] * cols, k) - cols * t0
        rhs[..., c] = np.stack([t0, tr, tc], -1)
    scale = np.linalg.norm(a.reshape(a.shape[:2] + (9,)), axis=-1)
    solvable = np.abs(np.linalg.det(a)) > 1e-9 * np.where(scale > 0, scale, 1.0) ** 3
    eye = np.eye(3)
    inv = np.linalg.inv(np.where(solvable[..., None, None], a, eye))
    coef = inv @ rhs
    estimate = np.where(solvable[..., None], coef[..., 0, :], np.nan)
    variance = (inv @ m @ inv)[..., 0, 0]
    estimate_std = np.where(solvable, np.sqrt(np.maximum(variance, 0.0)), np.nan)
    return estimate, estimate_std


def _laplacian(a):
    p = np.pad(a, ((1, 1), (1, 1), (0, 0)), mode="edge")
    return p[:-2, 1:-1] + p[2:, 1:-1] + p[1:-1, :-2] + p[1:-1, 2:] - 4 * p[1:-1, 1:-1]


def fit_directions(direction, std, *, bandwidths=BANDWIDTHS):
    """Ray directions of least estimated mean-square error over the kernel widths.

    Parameters
    ----------
    direction : (H, W, 2) ndarray
        Measured ``dx, dy`` (dz = 1) per near pixel; NaN where the ray has no correspondence.
    std : (H, W) ndarray
        Per-axis std of each measured direction (:func:`direction_noise`).
    bandwidths : sequence of float, keyword-only
        Candidate widths (pixels); 0 is the ray's own measurement.

    Returns
    -------
    dict
        ``direction`` (H, W, 2), ``direction_std`` (H, W) per axis (the chosen fit's
        variance), ``bandwidth`` (H, W) pixels (NaN where no width gives an estimate)
        and ``bias`` (H, W) the estimated bias per axis at that width.
    """
    direction = check_array(direction, "direction", ndim=3, dtype_kind="f")
    if direction.shape[-1] != 2:
        raise ValueError(f"direction must have shape (H, W, 2); got {direction.shape}")
    if not all(np.isfinite(b) and b >= 0 for b in bandwidths) or not len(bandwidths):
        raise ValueError(f"bandwidths must list widths >= 0; got {bandwidths!r}")
    pilot, _ = local_linear_fit(direction, std, bandwidth=PILOT_BANDWIDTH)
    lap = _laplacian(np.where(np.isfinite(pilot), pilot, 0.0))
    lap_sq = np.where(np.all(np.isfinite(pilot), -1), 0.5 * np.sum(lap ** 2, -1), np.nan)  # per axis
    best_mse = np.full(direction.shape[:2], np.inf)
    out = np.full(direction.shape, np.nan)
    out_std = np.full(direction.shape[:2], np.nan)
    out_h = np.full(direction.shape[:2], np.nan)
    out_bias = np.full(direction.shape[:2], np.nan)
    measured = np.all(np.isfinite(direction), -1) & np.isfinite(std)
    for h in bandwidths:
        if h == 0:
            estimate, est_std, bias = direction, np.where(measured, std, np.nan), np.zeros(std.shape)
        else:
            estimate, est_std = local_linear_fit(direction, std, bandwidth=h)
            bias = 0.5 * h ** 2 * np.sqrt(lap_sq)
        mse = est_std ** 2 + bias ** 2
        better = np.isfinite(mse) & (mse < best_mse) & np.all(np.isfinite(estimate), -1)
        best_mse = np.where(better, mse, best_mse)
        out[better] = estimate[better]
        out_std[better] = est_std[better]
        out_h[better] = h
        out_bias[better] = bias[better]
    return {"direction": out, "direction_std": out_std, "bandwidth": out_h, "bias": out_bias}
