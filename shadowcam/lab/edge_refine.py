"""Edge-aware spatial refinement of per-pixel shadow times.

On a smooth surface the shadow time is a smooth function of the pixel
position: the shadow edge is a curve that sweeps the image. A pixel's own
temporal estimate is quantised (a shadow crossing it within one frame leaves
a nearly on/off profile) and noisy; a local plane ``t = a + b*drow + c*dcol``
fitted to its neighbours' estimates averages both away, because the
quantisation error is periodic along the edge's motion and the noise is
independent. Neighbours across a depth discontinuity have times that do not
fit the plane; they are down-weighted by a range kernel on the residual, and
the fit is repeated (iteratively reweighted least squares), so discontinuities
stay sharp.

A plane is itself a model, biased where the window spans a curved time
surface. The refined time is therefore the inverse-variance combination of
two independent estimates of the pixel's time: its own (variance: its stated
variance) and the plane through its neighbours, the pixel left out (variance:
the fit's variance at the centre plus the plane's squared bias there). Both
come from the same neighbours fitted by a local quadratic, which follows the
curvature. Its residuals are the per-pixel errors: the median over the map
of their chi-square per degree of freedom, ``phi``, rescales every stated
variance, the pixel's own included. The plane's bias at the pixel shows as
the gap between the plane and the quadratic there; its square, less the part
the per-pixel errors explain (``phi`` times the difference of the two fits'
variances, as for nested least squares), estimates the squared bias
``tau**2`` without bias; averaged over the window (the bias follows the
curvature on that scale), then clipped at 0. A clean centroid on a curved surface is kept; on
a plane, or where the pixel's own estimate is noisy, the plane takes over.

A pixel's dip is timed where the shadow line crosses its flux centroid, not its
centre. Given each pixel's centroid shift (a camera fact: its footprint over the
lit image), the times are first taken to the centres with the slopes of a first
plane fit (:func:`centre_times`), and the refinement runs on the centred map.

Offers
------
refine_times : local robust plane fit of a time map, combined with the pixel's own time.
centre_times : times at the pixel centres from times at the pixels' flux centroids.
dispersion : common scale of the stated variances from the local quadratic fits.
shifted : an image shifted by a neighbour offset, filled outside.
"""

import numba as nb
import numpy as np
from scipy import ndimage

from shadowcam._shared.validation import check_array, check_positive


def shifted(array, dr, dc, fill):
    """`array` shifted so that ``out[r, c] = array[r + dr, c + dc]`` (fill outside)."""
    out = np.full_like(array, fill)
    h, w = array.shape
    rs, re = max(0, -dr), min(h, h - dr)
    cs, ce = max(0, -dc), min(w, w - dc)
    out[rs:re, cs:ce] = array[rs + dr:re + dr, cs + dc:ce + dc]
    return out


@nb.njit(cache=True, nogil=True)
def _solve(work, n, m):
    """Solve, in place, the leading ``n x n`` block of `work` for its ``m`` right-hand columns.

    `work` is ``(N, N + m)`` with ``N >= n``: the matrix in its first ``n``
    columns, the right-hand sides in columns ``N .. N + m - 1`` (Gauss-Jordan, partial
    pivoting). Each right-hand column sees the same operations as if it were
    solved alone. On return ``work[i, N + k] / work[i, i]`` is solution ``k``'s
    ``i``-th unknown. Returns False when a pivot is negligible against the
    matrix's scale (too few or collinear neighbours).
    """
    first = work.shape[0]
    scale = 0.0
    for i in range(n):
        scale = max(scale, abs(work[i, i]))
    for col in range(n):
        pivot = col
        for i in range(col + 1, n):
            if abs(work[i, col]) > abs(work[pivot, col]):
                pivot = i
        if not abs(work[pivot, col]) > 1e-9 * scale:
            return False
        if pivot != col:
            for j in range(n):
                work[col, j], work[pivot, j] = work[pivot, j], work[col, j]
            for k in range(m):
                work[col, first + k], work[pivot, first + k] = work[pivot, first + k], work[col, first + k]
        for i in range(n):
            if i != col:
                f = work[i, col] / work[col, col]
                for j in range(col, n):
                    work[i, j] -= f * work[col, j]
                for k in range(m):
                    work[i, first + k] -= f * work[col, first + k]
    return True


@nb.njit(cache=True, nogil=True, inline="always")
def _load(normal, rhs, n, work):
    """`work` = ``[normal | rhs | e0]`` over the leading ``n x n`` block (see :func:`_solve`)."""
    first = work.shape[0]
    for i in range(n):
        for j in range(n):
            work[i, j] = normal[i, j]
        work[i, first] = rhs[i]
        work[i, first + 1] = 1.0 if i == 0 else 0.0


@nb.njit(cache=True, nogil=True, inline="always")
def _range_weight(dr, dc, t_n, iv, c0, c1, c2, range_sigma, inv_sigma):
    """A neighbour's range kernel on its residual from the plane ``c0 + c1*dr + c2*dc``, and its weight.

    The residual is in units of `range_sigma`: multiplied by `inv_sigma` where that is
    exact (a power-of-two `range_sigma`, see :func:`_exact_inverse`; 0 otherwise), else
    divided. The weight is `iv` times the kernel, or 0 where that is not positive and
    finite (the neighbour then takes no part).
    """
    offset = t_n - c0 - c1 * dr - c2 * dc
    residual = offset * inv_sigma if inv_sigma > 0 else offset / range_sigma
    kernel = np.exp(-0.5 * residual**2)
    wgt = iv * kernel
    if not wgt > 0 or not np.isfinite(wgt):
        return kernel, 0.0
    return kernel, wgt


def _exact_inverse(value):
    """``1 / value`` where multiplying by it equals dividing by `value` for every double, else 0.

    For a power of two the inverse is exact, so ``x * (1 / value)`` and ``x / value`` are the
    same real number, each correctly rounded; in general the inverse itself is rounded.
    """
    mantissa, _ = np.frexp(value)
    inverse = 1.0 / value
    return inverse if mantissa == 0.5 and np.isfinite(inverse) and inverse > 0 else 0.0


@nb.njit(cache=True, nogil=True, inline="always")
def _plane_pass(n_dr, n_dc, n_t, n_iv, count, c0, c1, c2, range_sigma, inv_sigma, normal, rhs):
    """One reweighting pass: the plane's 3 x 3 normal equations into `normal`, `rhs`; returns the weight sum.

    Entries ``(w * b_i) * b_j`` and ``(w * b_i) * t`` for the basis ``1, dr, dc``, each summed
    in a register in neighbour order (``b_0 = 1``: the first column equals the first row).
    """
    s_w = n01 = n02 = n11 = n12 = n21 = n22 = r0 = r1 = r2 = 0.0
    for k in range(count):
        dr = n_dr[k]
        dc = n_dc[k]
        t_n = n_t[k]
        _, wgt = _range_weight(dr, dc, t_n, n_iv[k], c0, c1, c2, range_sigma, inv_sigma)
        if wgt == 0.0:
            continue
        s_w += wgt
        w_r = wgt * dr
        w_c = wgt * dc
        n01 += wgt * dr
        n02 += wgt * dc
        n11 += w_r * dr
        n12 += w_r * dc
        n21 += w_c * dr
        n22 += w_c * dc
        r0 += wgt * t_n
        r1 += w_r * t_n
        r2 += w_c * t_n
    normal[0, 0] = s_w
    normal[0, 1] = normal[1, 0] = n01
    normal[0, 2] = normal[2, 0] = n02
    normal[1, 1] = n11
    normal[1, 2] = n12
    normal[2, 1] = n21
    normal[2, 2] = n22
    rhs[0] = r0
    rhs[1] = r1
    rhs[2] = r2
    return s_w


@nb.njit(cache=True, nogil=True, inline="always")
def _quadratic_pass(n_dr, n_dc, n_t, n_iv, count, c0, c1, c2, range_sigma, inv_sigma, normal, rhs):
    """The last pass: the quadratic's 6 x 6 normal equations into `normal`, `rhs`.

    Entries ``(w * b_i) * b_j`` and ``(w * b_i) * t`` for the basis ``1, dr, dc, dr^2, dr dc,
    dc^2``, each summed in a register in neighbour order (``b_0 = 1``: the first column
    equals the first row). Returns the sums of the weights, of the range kernels and of
    ``w * t**2``.
    """
    s_w = s_k = s_tt = 0.0
    q01 = q02 = q03 = q04 = q05 = 0.0
    q11 = q12 = q13 = q14 = q15 = 0.0
    q21 = q22 = q23 = q24 = q25 = 0.0
    q31 = q32 = q33 = q34 = q35 = 0.0
    q41 = q42 = q43 = q44 = q45 = 0.0
    q51 = q52 = q53 = q54 = q55 = 0.0
    r0 = r1 = r2 = r3 = r4 = r5 = 0.0
    for k in range(count):
        b1 = n_dr[k]
        b2 = n_dc[k]
        t_n = n_t[k]
        kernel, wgt = _range_weight(b1, b2, t_n, n_iv[k], c0, c1, c2, range_sigma, inv_sigma)
        if wgt == 0.0:
            continue
        b3 = b1 * b1
        b4 = b1 * b2
        b5 = b2 * b2
        s_w += wgt
        s_k += kernel
        s_tt += wgt * t_n * t_n
        q01 += wgt * b1
        q02 += wgt * b2
        q03 += wgt * b3
        q04 += wgt * b4
        q05 += wgt * b5
        r0 += wgt * t_n
        w = wgt * b1
        q11 += w * b1
        q12 += w * b2
        q13 += w * b3
        q14 += w * b4
        q15 += w * b5
        r1 += w * t_n
        w = wgt * b2
        q21 += w * b1
        q22 += w * b2
        q23 += w * b3
        q24 += w * b4
        q25 += w * b5
        r2 += w * t_n
        w = wgt * b3
        q31 += w * b1
        q32 += w * b2
        q33 += w * b3
        q34 += w * b4
        q35 += w * b5
        r3 += w * t_n
        w = wgt * b4
        q41 += w * b1
        q42 += w * b2
        q43 += w * b3
        q44 += w * b4
        q45 += w * b5
        r4 += w * t_n
        w = wgt * b5
        q51 += w * b1
        q52 += w * b2
        q53 += w * b3
        q54 += w * b4
        q55 += w * b5
        r5 += w * t_n
    normal[0, 0] = s_w
    normal[0, 1] = normal[1, 0] = q01
    normal[0, 2] = normal[2, 0] = q02
    normal[0, 3] = normal[3, 0] = q03
    normal[0, 4] = normal[4, 0] = q04
    normal[0, 5] = normal[5, 0] = q05
    normal[1, 1], normal[1, 2], normal[1, 3], normal[1, 4], normal[1, 5] = q11, q12, q13, q14, q15
    normal[2, 1], normal[2, 2], normal[2, 3], normal[2, 4], normal[2, 5] = q21, q22, q23, q24, q25
    normal[3, 1], normal[3, 2], normal[3, 3], normal[3, 4], normal[3, 5] = q31, q32, q33, q34, q35
    normal[4, 1], normal[4, 2], normal[4, 3], normal[4, 4], normal[4, 5] = q41, q42, q43, q44, q45
    normal[5, 1], normal[5, 2], normal[5, 3], normal[5, 4], normal[5, 5] = q51, q52, q53, q54, q55
    rhs[0], rhs[1], rhs[2], rhs[3], rhs[4], rhs[5] = r0, r1, r2, r3, r4, r5
    return s_w, s_k, s_tt


@nb.njit(cache=True, nogil=True, parallel=True)
def _robust_plane_fit(t64, inv_var, radius, range_sigma, iterations, inv_sigma):
    """Per pixel: the neighbours' IRLS plane and its variances (see :func:`refine_times`).

    The pixel itself is left out. Each pass fits ``t = a + b*dr + c*dc`` to the
    ``(2 * radius + 1)**2 - 1`` neighbours weighted by their inverse variance
    and a Gaussian range kernel on their residual from the previous plane
    (first pass: the flat plane through the pixel's own time). With the last
    pass's weights, a local quadratic is fitted too.

    A pixel's usable neighbours (finite time, positive inverse variance) are
    gathered once; each pass then only evaluates the range kernel and adds
    to the normal equations, summed in registers (:func:`_plane_pass`,
    :func:`_quadratic_pass`), and the solves work in preallocated buffers.
    `inv_sigma`: :func:`_exact_inverse` of `range_sigma` (0: divide by it).
    Rows run in parallel (``prange``).

    Returns, each ``(H, W)`` float64, NaN where the pixel has no time or no
    plane: the plane's value ``a`` at the pixel and its variance under the
    stated variances; its slopes ``b, c`` (frames per px along rows and
    columns; NaN where the plane is undetermined) and their variances; the local dispersion (chi-square per degree of freedom
    about the quadratic, corrected for the range kernel's down-weighting of
    large residuals; inf where they exceed the kernel's scale), the quadratic's
    value at the pixel and its variance (NaN where the quadratic is
    undetermined).
    """
    h, w = t64.shape
    plane_out = np.full((h, w), np.nan)
    var_out = np.full((h, w), np.nan)
    phi_out = np.full((h, w), np.nan)
    quad_out = np.full((h, w), np.nan)
    quad_var_out = np.full((h, w), np.nan)
    slope_out = np.full((h, w, 2), np.nan)
    slope_var_out = np.full((h, w, 2), np.nan)
    size = (2 * radius + 1) ** 2
    for row in nb.prange(h):
        normal = np.empty((6, 6))
        rhs = np.empty(6)
        work = np.empty((6, 10))
        n_dr = np.empty(size)
        n_dc = np.empty(size)
        n_t = np.empty(size)
        n_iv = np.empty(size)
        r_lo = max(row - radius, 0) - row
        r_hi = min(row + radius, h - 1) - row
        for col in range(w):
            own = t64[row, col]
            if not np.isfinite(own):
                continue
            count = 0
            for dr in range(r_lo, r_hi + 1):
                rr = row + dr
                for dc in range(max(col - radius, 0) - col, min(col + radius, w - 1) - col + 1):
                    if dr == 0 and dc == 0:
                        continue
                    cc = col + dc
                    t_n = t64[rr, cc] - own
                    iv = inv_var[rr, cc]
                    if not np.isfinite(t_n) or not iv > 0:
                        continue
                    n_dr[count] = dr
                    n_dc[count] = dc
                    n_t[count] = t_n
                    n_iv[count] = iv
                    count += 1
            c0 = c1 = c2 = 0.0  # plane relative to the pixel's own time
            a3_0 = 0.0
            ok = False
            s_w = s_k = s_tt = 0.0
            for it in range(iterations + 1):
                last = it == iterations  # the quadratic only with the last weights
                if last:
                    s_w, s_k, s_tt = _quadratic_pass(n_dr, n_dc, n_t, n_iv, count, c0, c1, c2, range_sigma,
                                                     inv_sigma, normal, rhs)
                else:
                    s_w = _plane_pass(n_dr, n_dc, n_t, n_iv, count, c0, c1, c2, range_sigma, inv_sigma, normal, rhs)
                if s_w == 0.0:
                    ok = False
                    break
                _load(normal, rhs, 3, work)
                if last:  # the slopes' variances: unit vectors e1, e2 as two more columns
                    for i in range(3):
                        work[i, 8] = 1.0 if i == 1 else 0.0
                        work[i, 9] = 1.0 if i == 2 else 0.0
                ok = _solve(work, 3, 4 if last else 1)
                if not ok:  # too few or collinear neighbours: the weighted mean
                    c0 = rhs[0] / s_w
                    c1 = 0.0
                    c2 = 0.0
                else:
                    a3_0 = work[0, 6] / work[0, 0]
                    if it < iterations:
                        c0 = a3_0
                        c1 = work[1, 6] / work[1, 1]
                        c2 = work[2, 6] / work[2, 2]
            if s_w == 0.0:
                continue
            if ok:
                variance = work[0, 7] / work[0, 0]
                a = a3_0
                slope_out[row, col, 0] = work[1, 6] / work[1, 1]
                slope_out[row, col, 1] = work[2, 6] / work[2, 2]
                slope_var_out[row, col, 0] = work[1, 8] / work[1, 1]
                slope_var_out[row, col, 1] = work[2, 9] / work[2, 2]
            else:
                variance = 1.0 / s_w
                a = c0
            phi = np.nan
            a_quad = np.nan
            var_quad = np.nan
            df_quad = s_k - 6.0
            if ok and df_quad > 1.0:
                _load(normal, rhs, 6, work)
                if _solve(work, 6, 2):
                    q_quad = s_tt
                    for i in range(6):
                        q_quad -= (work[i, 6] / work[i, i]) * rhs[i]
                    # the range kernel keeps Gaussian residuals of variance s2 as if their
                    # variance were s2 h2 / (s2 + h2) (h = range_sigma): undo that shrinkage
                    shrunk = max(q_quad, 0.0) / df_quad * (s_k / s_w)
                    h2 = range_sigma**2
                    phi = shrunk * h2 / (h2 - shrunk) / (s_k / s_w) if shrunk < h2 else np.inf
                    a_quad = own + work[0, 6] / work[0, 0]
                    var_quad = work[0, 7] / work[0, 0]
            plane_out[row, col] = own + a
            var_out[row, col] = variance
            phi_out[row, col] = phi
            quad_out[row, col] = a_quad
            quad_var_out[row, col] = var_quad
    return plane_out, var_out, slope_out, slope_var_out, phi_out, quad_out, quad_var_out


def _squared_bias(gap, gap_var, radius):
    """The plane's squared bias at each pixel, ``(H, W)``, from its gap to the quadratic.

    ``gap**2 - gap_var`` is unbiased for the squared bias (nested fits:
    ``var(plane - quadratic) = var(quadratic) - var(plane)``) but as noisy as
    the gap; its mean over the fit's window (the bias varies with the
    surface's curvature on that scale) is clipped at 0.
    """
    with np.errstate(invalid="ignore"):
        estimate = gap**2 - gap_var
    finite = np.isfinite(estimate)
    size = 2 * radius + 1
    total = ndimage.uniform_filter(np.where(finite, estimate, 0.0), size, mode="constant")
    count = ndimage.uniform_filter(finite.astype(np.float64), size, mode="constant")
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0, total / count, 0.0)
    return np.maximum(np.where(finite, mean, 0.0), 0.0)


def dispersion(local_phi):
    """Common scale of the stated variances: the median of the local dispersions.

    The per-pixel error (noise, and the staircase of a dip sampled at whole
    frames) is a property of the capture; the local dispersion about the
    quadratic also holds geometry (outlines, higher-order curvature) on a
    minority of pixels, which the median ignores.

    Parameters
    ----------
    local_phi : (H, W) float ndarray
        Chi-square per degree of freedom about the local quadratic; NaN where
        undetermined.

    Returns
    -------
    phi : float
        The median over the pixels with a finite dispersion (an infinite one,
        residuals beyond the range kernel's scale, is outside the kernel's
        noise model and takes no part); 1 (the stated variances as given)
        where there is none.
    """
    local_phi = np.asarray(local_phi, dtype=np.float64)
    finite = local_phi[np.isfinite(local_phi)]
    return float(np.median(finite)) if finite.size else 1.0


def _plane(t64, inv_var, radius, range_sigma, iterations):
    """The neighbours' plane at each pixel, with its variance and slopes, the common scale applied.

    Returns ``plane, plane_var, slope, slope_var, phi`` (see :func:`_robust_plane_fit`):
    ``plane_var`` is ``phi * var(a) + tau**2`` and ``slope_var`` is ``phi * var(b, c)``.
    """
    plane, plane_var, slope, slope_var, local_phi, quad, quad_var = _robust_plane_fit(
        t64, inv_var, int(radius), float(range_sigma), max(int(iterations), 1), _exact_inverse(float(range_sigma)))
    phi = dispersion(local_phi)
    tau2 = _squared_bias(plane - quad, phi * (quad_var - plane_var), int(radius))
    return plane, phi * plane_var + tau2, slope, phi * slope_var, phi


def centre_times(time, time_std, slope, slope_var, centroid_shift, *, shift_std=None):
    """Times at the pixel centres from times at the pixels' flux centroids.

    A pixel's dip is centred on the time the shadow line crosses its flux centroid, at
    `centroid_shift` from its centre (:func:`shadowcam._shared.flux_centroid.flux_centroid_shift`).
    With the local time gradient ``g`` (frames per px), the centre's time is
    ``t - g . shift`` to first order.

    Parameters
    ----------
    time, time_std : (H, W) ndarray
        Times at the flux centroids and their standard deviations, frames; NaN: no time.
    slope, slope_var : (H, W, 2) ndarray
        Time gradient along rows and columns (frames per px) and its variance; NaN: unknown
        (the time is kept).
    centroid_shift : (H, W, 2) ndarray
        Flux centroid minus pixel centre, px.
    shift_std : (H, W, 2) ndarray, optional
        Standard deviation of `centroid_shift`, px (e.g. the part of a first-order shift
        beyond the footprint).

    Returns
    -------
    time : (H, W) float64 ndarray
        Centre times.
    time_std : (H, W) float64 ndarray
        `time_std` with the correction's uncertainty added in quadrature:
        ``sum(shift**2 slope_var + slope**2 shift_std**2)``.
    """
    time = np.asarray(time, dtype=np.float64)
    check_array(time, "time", ndim=2)
    shape = time.shape + (2,)
    slope = check_array(slope, "slope", shape=shape, dtype_kind="f")
    slope_var = check_array(slope_var, "slope_var", shape=shape, dtype_kind="f")
    centroid_shift = check_array(centroid_shift, "centroid_shift", shape=shape, dtype_kind="iuf")
    shift_std = np.zeros(shape) if shift_std is None else check_array(shift_std, "shift_std", shape=shape,
                                                                      dtype_kind="iuf")
    known = np.all(np.isfinite(slope) & np.isfinite(slope_var), axis=-1)
    g = np.where(known[..., None], slope, 0.0)
    gv = np.where(known[..., None], slope_var, 0.0)
    correction = np.sum(g * centroid_shift, axis=-1)
    extra = np.sum(centroid_shift**2 * gv + g**2 * shift_std**2, axis=-1)
    return time - correction, np.sqrt(np.asarray(time_std, dtype=np.float64) ** 2 + extra)


def refine_times(time, time_std, *, radius=3, range_sigma=0.5, iterations=3, centroid_shift=None,
                 shift_std=None):
    """Edge-aware local plane fit of a shadow-time map, combined with each pixel's own time.

    Parameters
    ----------
    time : (H, W) float ndarray
        Per-pixel shadow times in frames; NaN where there is none (those
        pixels stay NaN and do not contribute).
    time_std : (H, W) float ndarray
        Per-pixel standard deviation of `time`, frames, up to a common factor
        (:func:`dispersion` rescales it); sets the weights. A pixel with zero standard deviation keeps its own time and
        does not take part in its neighbours' planes.
    radius : int, optional
        Half size of the square neighbourhood, pixels.
    range_sigma : float, optional
        Scale, in frames, of the range kernel on a neighbour's residual from
        the current local plane: neighbours further off (across a depth
        discontinuity) are ignored.
    iterations : int, optional
        Reweighting passes (1 = plain range kernel around the pixel's own time).
    centroid_shift : (H, W, 2) ndarray, optional
        Where each pixel's time was measured: its flux centroid minus its centre, px. The
        times are then first taken to the pixel centres (:func:`centre_times`, with the
        slopes of a first plane fit, which follow the pixel's own surface across
        discontinuities) and refined from there; the correction's uncertainty joins their
        variance.
    shift_std : (H, W, 2) ndarray, optional
        Standard deviation of `centroid_shift`, px.

    Returns
    -------
    refined : (H, W) ndarray
        Inverse-variance combination of the pixel's own time (variance
        ``phi * std**2``) and its neighbours' plane at the pixel (variance
        ``phi * var(a) + tau**2``), same dtype as `time`.
    refined_std : (H, W) ndarray
        Standard deviation of the refined times under that noise model.
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

    plane, plane_var, slope, slope_var, phi = _plane(t64, inv_var, radius, range_sigma, iterations)
    if centroid_shift is not None:
        own_std = np.sqrt(np.where(inv_var > 0, phi / np.where(inv_var > 0, inv_var, 1.0), 0.0))
        t64, centred_std = centre_times(t64, own_std, slope, slope_var, centroid_shift, shift_std=shift_std)
        with np.errstate(invalid="ignore", divide="ignore"):  # back to the stated scale
            inv_var = np.where(inv_var > 0, phi / centred_std**2, 0.0)
        plane, plane_var, _, _, phi = _plane(t64, inv_var, radius, range_sigma, iterations)
    own_var = np.where(inv_var > 0, phi / np.where(inv_var > 0, inv_var, 1.0), 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        # own_var == 0: an exact own time; plane_var == 0: an exact plane (both 0: the own time)
        w_own = np.where(own_var > 0, 1.0 / own_var, np.inf)
        w_plane = np.where(plane_var > 0, 1.0 / plane_var, np.where(own_var > 0, np.inf, 0.0))
        combined = np.where(np.isinf(w_own), t64,
                            np.where(np.isinf(w_plane), plane,
                                     (w_own * t64 + w_plane * plane) / (w_own + w_plane)))
        combined_std = np.sqrt(1.0 / (w_own + w_plane))
    has_plane = np.isfinite(plane)
    refined = np.where(valid & has_plane, combined, t64)
    refined_std = np.where(has_plane, combined_std, np.sqrt(own_var))
    return refined.astype(time.dtype), np.where(valid, refined_std, np.nan)
