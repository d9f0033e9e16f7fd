"""Where a pixel's flux is centred: the first-order shift of its footprint's flux centroid.

A pixel integrates the irradiance ``E`` over its footprint (centred on the pixel, second
moment ``var`` px^2 per axis). An event that passes the footprint (a wire's shadow line)
is seen when it crosses the flux-weighted centroid of the footprint, not the pixel centre.
To first order in the footprint's size, for any footprint symmetric about the centre, the
centroid lies at ``centre + var * grad(E) / E`` (pixel units). The shift is clipped to the
half-width of the box of that variance, ``sqrt(3 var)`` px per axis: a centroid lies inside
its footprint; the clipped part is where the first order does not hold.

Offers
------
flux_centroid_shift : per-pixel shift of the flux centroid from the pixel centre, and its clipped part.
"""

import numpy as np

from shadowcam._shared.validation import check_array


def flux_centroid_shift(irradiance, *, footprint_variance):
    """Shift of each pixel's flux centroid from its centre, px, to first order.

    Parameters
    ----------
    irradiance : (H, W) array_like
        The pixels' lit level (any positive scale; measured, so ``grad`` is taken by central
        differences of the pixel grid, one-sided at the border). Not finite or <= 0: no shift,
        and 0 in its neighbours' differences.
    footprint_variance : float or (H, W) array_like, keyword-only
        Per-axis second moment of a pixel's footprint, px^2 (>= 0): 1/12 for a box pixel,
        ``(s**2 - 1) / (12 s**2)`` for ``s x s`` point samples, 1/6 for a tent; per pixel
        where the footprints differ (a RAW pixel timed from its own site or from the
        demosaic's blend of its neighbours).

    Returns
    -------
    shift : (H, W, 2) float64 ndarray
        Row and column shift, px, each within ``+-sqrt(3 footprint_variance)``; 0 where the
        irradiance (or a difference it needs) is not usable.
    clipped : (H, W, 2) float64 ndarray
        The first-order shift less `shift` (nonzero where it left the footprint).
    """
    irradiance = check_array(irradiance, "irradiance", ndim=2, dtype_kind="iuf").astype(np.float64)
    if min(irradiance.shape) < 2:
        raise ValueError(f"irradiance must be at least 2 x 2 pixels; got shape {irradiance.shape}")
    variance = np.asarray(footprint_variance, dtype=np.float64)
    if variance.ndim not in (0, 2) or (variance.ndim == 2 and variance.shape != irradiance.shape):
        raise ValueError(f"footprint_variance must be a number or an array of the irradiance's shape "
                         f"{irradiance.shape} (px^2); got shape {variance.shape}")
    if not (np.all(np.isfinite(variance)) and np.all(variance >= 0)):
        raise ValueError(f"footprint_variance must be finite and >= 0 (px^2); got {footprint_variance!r}")
    footprint_variance = variance[()] if variance.ndim == 0 else variance
    usable = np.isfinite(irradiance) & (irradiance > 0)
    e = np.where(usable, irradiance, 0.0)
    half_width = np.sqrt(3.0 * footprint_variance)
    shift = np.zeros(irradiance.shape + (2,))
    first = np.zeros(irradiance.shape + (2,))
    with np.errstate(divide="ignore", invalid="ignore"):
        for axis in (0, 1):
            raw = footprint_variance * np.gradient(e, axis=axis) / e
            raw = np.where(usable & np.isfinite(raw), raw, 0.0)
            first[..., axis] = raw
            shift[..., axis] = np.clip(raw, -half_width, half_width)
    return shift, first - shift
