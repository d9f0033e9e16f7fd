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

import numba as nb
import numpy as np

from shadowcam._shared.validation import check_array, check_positive


def shifted(array, dr, dc, fill):
    """`array` shifted so that ``out[r, c] = array[r + dr, c + dc]`` (fill outside)."""
    out = np.full_like(array, fill)
    h, w = array.shape
    rs, re = max(0, -dr), min(h, h - dr)
    cs, ce = max(0, -dc), min(w, w - dc)
    out[rs:re, cs:ce] = array[rs + dr:re + dr, cs + dc:ce + dc]
    return out


@nb.njit(cache=True, parallel=True)
def _robust_plane_fit(t64, inv_var, radius, range_sigma, iterations):
    """Per pixel: IRLS local plane fit of the neighbours' times (see :func:`refine_times`).

    Each pass fits ``t = a + b*dr + c*dc`` to the ``(2 * radius + 1)**2``
    neighbours weighted by their inverse variance and a Gaussian range kernel
    on their residual from the pixel's previous plane (first pass: the flat
    plane through its own time). Returns the plane values ``a`` (NaN where the
    pixel has no time) and the last pass's weight sums, ``(H, W)`` float64.
    """
    h, w = t64.shape
    centre_out = np.full((h, w), np.nan)
    weight_out = np.zeros((h, w))
    for row in nb.prange(h):
        for col in range(w):
            centre = t64[row, col]
            if not np.isfinite(centre):
                continue
            slope_r = 0.0
            slope_c = 0.0
            s = 0.0
            for _ in range(iterations):
                s = m_r = m_c = m_rr = m_rc = m_cc = m_t = m_tr = m_tc = 0.0
                for dr in range(-radius, radius + 1):
                    rr = row + dr
                    for dc in range(-radius, radius + 1):
                        cc = col + dc
                        if rr < 0 or rr >= h or cc < 0 or cc >= w:
                            continue
                        t_n = t64[rr, cc]
                        if not np.isfinite(t_n):
                            continue
                        predicted = centre + slope_r * dr + slope_c * dc
                        residual = (t_n - predicted) / range_sigma
                        wgt = inv_var[rr, cc] * np.exp(-0.5 * residual**2)
                        if not np.isfinite(wgt):
                            continue
                        if not wgt > 0:
                            t_n = 0.0
                        s += wgt
                        m_r += wgt * dr
                        m_c += wgt * dc
                        m_rr += wgt * dr * dr
                        m_rc += wgt * dr * dc
                        m_cc += wgt * dc * dc
                        m_t += wgt * t_n
                        m_tr += wgt * t_n * dr
                        m_tc += wgt * t_n * dc
                # solve [[s, r, c], [r, rr, rc], [c, rc, cc]] x = [t, tr, tc] by Cramer's rule
                det = (s * (m_rr * m_cc - m_rc**2) - m_r * (m_r * m_cc - m_rc * m_c)
                       + m_c * (m_r * m_rc - m_rr * m_c))
                scale = max(s, 1e-300) ** 3 * max(radius, 1) ** 4
                a = np.nan
                if det != 0.0:
                    a = (m_t * (m_rr * m_cc - m_rc**2) - m_r * (m_tr * m_cc - m_rc * m_tc)
                         + m_c * (m_tr * m_rc - m_rr * m_tc)) / det
                if abs(det) > 1e-6 * scale and np.isfinite(a):
                    slope_r = (s * (m_tr * m_cc - m_tc * m_rc) - m_t * (m_r * m_cc - m_rc * m_c)
                               + m_c * (m_r * m_tc - m_tr * m_c)) / det
                    slope_c = (s * (m_rr * m_tc - m_rc * m_tr) - m_r * (m_r * m_tc - m_tr * m_c)
                               + m_t * (m_r * m_rc - m_rr * m_c)) / det
                    centre = a
                else:  # too few or collinear neighbours: the weighted mean
                    centre = m_t / s if s != 0.0 else np.nan
                    slope_r = 0.0
                    slope_c = 0.0
            centre_out[row, col] = centre
            weight_out[row, col] = s
    return centre_out, weight_out


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
    check_array(time, "time", ndim=2)
    time_std = np.broadcast_to(np.asarray(time_std, dtype=np.float64), time.shape)
    if int(radius) < 1:
        raise ValueError(f"radius must be >= 1; got {radius!r}")
    check_positive(range_sigma, "range_sigma")
    valid = np.isfinite(time)
    t64 = np.where(valid, time, np.nan).astype(np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        inv_var = np.where(valid & (time_std > 0), 1.0 / time_std**2, 0.0)
    inv_var = np.nan_to_num(inv_var, nan=0.0, posinf=0.0)

    centre, weight_sum = _robust_plane_fit(t64, inv_var, int(radius), float(range_sigma),
                                           max(int(iterations), 1))
    with np.errstate(invalid="ignore", divide="ignore"):
        refined_std = np.sqrt(1.0 / weight_sum)
    refined = np.where(valid & np.isfinite(centre), centre, time)
    return refined.astype(time.dtype), np.where(valid, refined_std, np.nan)
