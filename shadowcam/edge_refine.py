"""Edge-aware spatial refinement of per-pixel shadow times.

On a smooth surface the shadow time is a smooth function of the pixel
position: the shadow edge is a curve that sweeps the image. A pixel's own
temporal estimate is quantised (a shadow crossing it within one frame leaves
a nearly on/off profile) and noisy; fitting a local plane ``t = a + b*drow +
c*dcol`` to its neighbours' estimates averages both away, because the
quantisation error is periodic along the edge's motion and the noise is
independent. Neighbours across a depth discontinuity have times that do not
fit the plane; they are down-weighted by a range kernel on the residual, and
the fit is repeated (iteratively reweighted least squares), so discontinuities
stay sharp.

Offers
------
refine_times : local robust plane fit of a time map.
shifted : an image shifted by a neighbour offset, filled outside.
"""

import numpy as np


def shifted(array, dr, dc, fill):
    """`array` shifted so that ``out[r, c] = array[r + dr, c + dc]`` (fill outside)."""
    out = np.full_like(array, fill)
    h, w = array.shape
    rs, re = max(0, -dr), min(h, h - dr)
    cs, ce = max(0, -dc), min(w, w - dc)
    out[rs:re, cs:ce] = array[rs + dr:re + dr, cs + dc:ce + dc]
    return out


def _plane_fit(time, weight_of, radius):
    """Weighted local plane fit at every pixel.

    `weight_of(dr, dc, neighbour_time)` returns the ``(H, W)`` weights of the
    neighbour at offset ``(dr, dc)``. Returns the plane's value, its row and
    column slopes, and the weight sum.
    """
    h, w = time.shape
    moments = {key: np.zeros((h, w)) for key in
               ("s", "r", "c", "rr", "rc", "cc", "t", "tr", "tc")}
    for dr in range(-radius, radius + 1):
        for dc in range(-radius, radius + 1):
            t_n = shifted(time, dr, dc, np.nan)
            wgt = weight_of(dr, dc, t_n)
            wgt = np.where(np.isfinite(t_n), wgt, 0.0)
            t_n = np.where(wgt > 0, t_n, 0.0)
            moments["s"] += wgt
            moments["r"] += wgt * dr
            moments["c"] += wgt * dc
            moments["rr"] += wgt * dr * dr
            moments["rc"] += wgt * dr * dc
            moments["cc"] += wgt * dc * dc
            moments["t"] += wgt * t_n
            moments["tr"] += wgt * t_n * dr
            moments["tc"] += wgt * t_n * dc
    m = moments
    # solve [[s, r, c], [r, rr, rc], [c, rc, cc]] x = [t, tr, tc] by Cramer's rule
    det = (m["s"] * (m["rr"] * m["cc"] - m["rc"] ** 2)
           - m["r"] * (m["r"] * m["cc"] - m["rc"] * m["c"])
           + m["c"] * (m["r"] * m["rc"] - m["rr"] * m["c"]))
    with np.errstate(invalid="ignore", divide="ignore"):
        a = (m["t"] * (m["rr"] * m["cc"] - m["rc"] ** 2)
             - m["r"] * (m["tr"] * m["cc"] - m["rc"] * m["tc"])
             + m["c"] * (m["tr"] * m["rc"] - m["rr"] * m["tc"])) / det
        b = (m["s"] * (m["tr"] * m["cc"] - m["tc"] * m["rc"])
             - m["t"] * (m["r"] * m["cc"] - m["rc"] * m["c"])
             + m["c"] * (m["r"] * m["tc"] - m["tr"] * m["c"])) / det
        c = (m["s"] * (m["rr"] * m["tc"] - m["rc"] * m["tr"])
             - m["r"] * (m["r"] * m["tc"] - m["tr"] * m["c"])
             + m["t"] * (m["r"] * m["rc"] - m["rr"] * m["c"])) / det
        mean = m["t"] / m["s"]
    # too few or collinear neighbours: fall back to the weighted mean
    scale = np.maximum(m["s"], 1e-300) ** 3 * max(radius, 1) ** 4
    degenerate = ~(np.abs(det) > 1e-6 * scale) | ~np.isfinite(a)
    a = np.where(degenerate, mean, a)
    b = np.where(degenerate, 0.0, b)
    c = np.where(degenerate, 0.0, c)
    return a, b, c, m["s"]


def refine_times(time, time_std, *, radius=3, range_sigma=0.5, iterations=3):
    """Edge-aware local plane fit of a shadow-time map.

    Parameters
    ----------
    time : (H, W) float ndarray
        Per-pixel shadow times in frames; NaN where there is none (those
        pixels stay NaN and do not contribute).
    time_std : (H, W) float ndarray
        Per-pixel standard deviation of `time`, frames (sets the weights).
    radius : int, optional
        Half size of the square neighbourhood, pixels.
    range_sigma : float, optional
        Scale, in frames, of the range kernel on a neighbour's residual from
        the current local plane: neighbours further off (across a depth
        discontinuity) are ignored.
    iterations : int, optional
        Reweighting passes (1 = plain range kernel around the pixel's own time).

    Returns
    -------
    refined : (H, W) ndarray
        Refined times, same dtype as `time`.
    refined_std : (H, W) ndarray
        Standard deviation of the refined times under the weights' noise model.
    """
    time = np.asarray(time)
    if time.ndim != 2:
        raise ValueError(f"time must be 2-D (H, W), got shape {time.shape}")
    time_std = np.broadcast_to(np.asarray(time_std, dtype=np.float64), time.shape)
    if int(radius) < 1:
        raise ValueError(f"radius must be >= 1, got {radius!r}")
    if not range_sigma > 0:
        raise ValueError(f"range_sigma must be > 0, got {range_sigma!r}")
    valid = np.isfinite(time)
    t64 = np.where(valid, time, np.nan).astype(np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        inv_var = np.where(valid & (time_std > 0), 1.0 / time_std**2, 0.0)
    inv_var = np.nan_to_num(inv_var, nan=0.0, posinf=0.0)

    centre, slope_r, slope_c = t64, np.zeros_like(t64), np.zeros_like(t64)
    for _ in range(max(int(iterations), 1)):
        def weight_of(dr, dc, t_n, centre=centre, slope_r=slope_r, slope_c=slope_c):
            predicted = centre + slope_r * dr + slope_c * dc
            residual = (t_n - predicted) / range_sigma
            return shifted(inv_var, dr, dc, 0.0) * np.exp(-0.5 * residual**2)

        centre, slope_r, slope_c, weight_sum = _plane_fit(t64, weight_of, radius)
        centre = np.where(valid, centre, np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        refined_std = np.sqrt(1.0 / weight_sum)
    refined = np.where(valid & np.isfinite(centre), centre, time)
    return refined.astype(time.dtype), np.where(valid, refined_std, np.nan)
