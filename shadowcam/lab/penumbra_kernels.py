"""Compiled per-pixel fit of the penumbra law (numba, ``prange`` over pixels).

Each pixel's fit of :func:`shadowcam.lab.penumbra_law.fit_penumbra_law`: the grid start
(its best points kept), damped Gauss-Newton from each of them on the residual with lit and
full solved inside, the lowest residual kept. The Jacobian is the forward difference of
that residual with the share moved along its exact slopes (one ``arcsin`` pass per step,
not four), samples beyond a law's penumbrae cost none, and the steps stop once one moves
every parameter by less than a given fraction. Sums run in frame order.

Offers
------
hidden_share_at : the law's hidden share of one pixel at one frame and its slopes (scalars).
fit_laws : per pixel, the law's parameters, levels, sum of squares and normal matrix.
"""

import numba as nb
import numpy as np

_STEP = 1e-6  # forward-difference step, relative to max(1, |parameter|)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _share_below(z, box):
    """Share of the source below `z` half extents (a unit disc's circular segment or a box)
    and its slope in `z`."""
    if z <= -1.0:
        return 0.0, 0.0
    if z >= 1.0:
        return 1.0, 0.0
    if box:
        return 0.5 * (z + 1.0), 0.5
    root = np.sqrt(1.0 - z * z)
    return 0.5 + (z * root + np.arcsin(z)) / np.pi, 2.0 * root / np.pi


@nb.njit(cache=True, error_model="numpy")
def hidden_share_at(t, centre, extent, width, spread, box):
    """The hidden share F(t) of :func:`shadowcam.lab.penumbra_law.hidden_share` (scalars),
    and its slopes in centre, extent and width.

    Parameters
    ----------
    t, centre, extent, width, spread : float
        Frame, the law's centre, half extent and width, the footprint's spread (frames).
    box : bool
        The box profile (else the disc).

    Returns
    -------
    share, d_centre, d_extent, d_width : float
        Exactly 0 beyond the penumbrae (``|t - centre| >= width / 2 + extent + |spread|``).
    """
    if abs(t - centre) >= 0.5 * width + extent + abs(spread):
        return 0.0, 0.0, 0.0, 0.0
    scale = 1.0 / extent
    total = 0.0
    d_centre = 0.0
    d_extent = 0.0
    d_width = 0.0
    for side in (-1.0, 1.0):
        lag = t + side * spread - centre
        high = (lag + 0.5 * width) * scale
        low = (lag - 0.5 * width) * scale
        share_high, slope_high = _share_below(high, box)
        share_low, slope_low = _share_below(low, box)
        total = total + share_high - share_low
        d_centre -= (slope_high - slope_low) * scale
        d_extent += (slope_low * low - slope_high * high) * scale
        d_width += 0.5 * (slope_high + slope_low) * scale
    return 0.5 * total, 0.5 * d_centre, 0.5 * d_extent, 0.5 * d_width


@nb.njit(cache=True, error_model="numpy")
def _shares(times, centre, extent, width, spread, box, share, slopes):
    """Each sample's hidden share (K,) and, when `slopes` has rows, its slopes (K, 3) in
    (centre, extent, width), in place."""
    with_slopes = slopes.shape[0] > 0
    for j in range(times.shape[0]):
        f, dc, de, dw = hidden_share_at(times[j], centre, extent, width, spread, box)
        share[j] = f
        if with_slopes:
            slopes[j, 0] = dc
            slopes[j, 1] = de
            slopes[j, 2] = dw


@nb.njit(cache=True, inline="always", error_model="numpy")
def _solve_levels(aa, ab, bb, ay, by):
    """Least-squares lit and full (>= 0) of ``lit a + full b`` from the sums of ``a a``,
    ``a b``, ``b b``, ``a y``, ``b y`` (a = 1 - F, b = F)."""
    det = aa * bb - ab * ab
    lit = (bb * ay - ab * by) / det
    full = (aa * by - ab * ay) / det
    # no sample in the dip's hidden part, or a negative full level: full = 0 (or lit) and
    # lit alone by least squares
    flat = not (abs(det) > 1e-12 * max(aa * bb, 1e-300))
    dark = (not flat) and not (full >= 0.0)
    if flat or dark:
        lit = ay / max(aa, 1e-300)
    if flat:
        full = lit
    elif dark:
        full = 0.0
    return lit, full


@nb.njit(cache=True, error_model="numpy")
def _levels(share, samples, residual):
    """Least-squares lit and full (>= 0) of ``lit (1 - F) + full F`` for one pixel's
    samples, the residual (K,) in place. Returns (lit, full, sum of squares)."""
    aa = 0.0
    ab = 0.0
    bb = 0.0
    ay = 0.0
    by = 0.0
    for j in range(share.shape[0]):
        b = share[j]
        a = 1.0 - b
        y = samples[j]
        aa += a * a
        ab += a * b
        bb += b * b
        ay += a * y
        by += b * y
    lit, full = _solve_levels(aa, ab, bb, ay, by)
    cost = 0.0
    for j in range(share.shape[0]):
        r = samples[j] - lit * (1.0 - share[j]) - full * share[j]
        residual[j] = r
        cost += r * r
    return lit, full, cost


@nb.njit(cache=True, error_model="numpy")
def _normal_equations(times, samples, params, spread, box, work, jacobian, normal, gradient):
    """Residual (``work[0]``), Jacobian (K, 3), normal matrix (3, 3) and gradient (3,) of one
    pixel's residual with lit and full solved inside, in (centre, extent, width), in place.

    The Jacobian is the forward difference of that residual over a step of ``1e-6 max(1,
    |parameter|)``, the share moved along its exact slopes (no ``arcsin`` per step).
    Returns the sum of squares. `work` is (4, K) scratch: residual, share, moved share,
    moved residual.
    """
    k = times.shape[0]
    residual, share, moved, moved_residual = work[0], work[1], work[2], work[3]
    _shares(times, params[0], params[1], params[2], spread, box, share, jacobian)
    cost = _levels(share, samples, residual)[2]
    for i in range(3):
        h = (params[i] + _STEP * max(1.0, abs(params[i]))) - params[i]
        for j in range(k):
            moved[j] = share[j] + h * jacobian[j, i]
        _levels(moved, samples, moved_residual)
        for j in range(k):
            jacobian[j, i] = (moved_residual[j] - residual[j]) / h
    for i in range(3):
        g = 0.0
        for j in range(k):
            g += jacobian[j, i] * residual[j]
        gradient[i] = g
        for m in range(i, 3):
            total = 0.0
            for j in range(k):
                total += jacobian[j, i] * jacobian[j, m]
            normal[i, m] = total
            normal[m, i] = total
    return cost


@nb.njit(cache=True, error_model="numpy")
def _pseudo_inverse(matrix):
    """Inverse of a symmetric 3 x 3 matrix by cofactors where it is well conditioned, else
    its pseudo-inverse (LAPACK SVD, numpy's cut-off); NaN where not finite."""
    out = np.full((3, 3), np.nan)
    for i in range(3):
        for m in range(3):
            if not np.isfinite(matrix[i, m]):
                return out
    a, b, c = matrix[0, 0], matrix[0, 1], matrix[0, 2]
    d, e, f = matrix[1, 1], matrix[1, 2], matrix[2, 2]
    c00 = d * f - e * e
    c01 = c * e - b * f
    c02 = b * e - c * d
    det = a * c00 + b * c01 + c * c02
    scale = max(abs(a), abs(d), abs(f))
    if scale > 0.0 and abs(det) > 1e-9 * scale * scale * scale:
        out[0, 0] = c00 / det
        out[0, 1] = c01 / det
        out[0, 2] = c02 / det
        out[1, 1] = (a * f - c * c) / det
        out[1, 2] = (b * c - a * e) / det
        out[2, 2] = (a * d - b * b) / det
        out[1, 0] = out[0, 1]
        out[2, 0] = out[0, 2]
        out[2, 1] = out[1, 2]
        return out
    return np.linalg.pinv(matrix)


@nb.njit(cache=True, error_model="numpy")
def _refine(t, y, params, cost, spread, box, iterations, floor, converged, work, jacobian, normal, gradient):
    """Damped Gauss-Newton steps of one pixel's law from `params` (3,), in place; returns
    the sum of squares reached (`cost`: at the start)."""
    no_slopes = np.empty((0, 3))
    trial = np.empty(3)
    damping = 1e-3
    for _ in range(iterations):
        _normal_equations(t, y, params, spread, box, work, jacobian, normal, gradient)
        system = normal.copy()
        for i in range(3):
            system[i, i] += damping * (normal[i, i] + 1e-12)
        inverse = _pseudo_inverse(system)
        largest = 0.0
        for i in range(3):
            step = -(inverse[i, 0] * gradient[0] + inverse[i, 1] * gradient[1] + inverse[i, 2] * gradient[2])
            step = step if np.isfinite(step) else 0.0
            trial[i] = params[i] + step
            largest = max(largest, abs(step) / max(1.0, abs(params[i])))
        trial[1] = max(trial[1], floor)
        trial[2] = max(trial[2], floor)
        _shares(t, trial[0], trial[1], trial[2], spread, box, work[1], no_slopes)
        trial_cost = _levels(work[1], y, work[0])[2]
        if trial_cost < cost:
            params[:] = trial
            cost = trial_cost
            damping = damping / 3.0
        else:
            damping = damping * 4.0
        damping = min(max(damping, 1e-9), 1e9)
        if largest < converged:
            break  # the steps left move the parameters by less than this, relative
    return cost


@nb.njit(cache=True, parallel=True, error_model="numpy")
def fit_laws(times, samples, valid, centre0, width0, spread, box, extent_ratios, width_ratios, iterations, floor,
             converged, starts):
    """Fit the law to each pixel's samples: grid start, then damped Gauss-Newton.

    Parameters
    ----------
    times, samples : (N, K) float64 ndarray
        Frames and signal of the samples (any value where not `valid`).
    valid : (N, K) bool ndarray
    centre0, width0, spread : (N,) float64 ndarray
        Starting centre, starting width (the grid's unit), footprint spread.
    box : bool
        The box profile (else the disc).
    extent_ratios, width_ratios : (E,), (W,) float64 ndarray
        The grid's extents and widths in units of `width0`.
    iterations : int
    floor : float
        Least extent and width.
    converged : float
        The steps stop once a step moves every parameter by less than this, relative to
        ``max(1, |parameter|)`` (0: all `iterations` steps).
    starts : int
        The grid's best points refined; the lowest residual reached is kept (the best
        grid point's on ties).

    Returns
    -------
    params : (N, 3) float64 ndarray
        centre, extent, width.
    lit, full, sum_squares : (N,) float64 ndarray
    normal : (N, 3, 3) float64 ndarray
        The normal matrix at the fitted parameters.
    """
    n, k = times.shape
    params_out = np.empty((n, 3))
    lit_out = np.empty(n)
    full_out = np.empty(n)
    cost_out = np.empty(n)
    normal_out = np.empty((n, 3, 3))
    for p in nb.prange(n):
        # the pixel's valid samples, contiguous
        held = np.flatnonzero(valid[p])
        t = times[p][held]
        y = samples[p][held]
        s = spread[p]
        work = np.zeros((4, len(held)))
        no_slopes = np.empty((0, 3))
        jacobian = np.empty((len(held), 3))
        normal = np.empty((3, 3))
        gradient = np.empty(3)
        # the grid's `starts` best points, best first
        start_cost = np.full(starts, np.inf)
        start_extent = np.full(starts, extent_ratios[0] * width0[p])
        start_width = np.full(starts, width_ratios[0] * width0[p])
        for er in extent_ratios:
            for wr in width_ratios:
                extent = er * width0[p]
                width = wr * width0[p]
                _shares(t, centre0[p], extent, width, s, box, work[1], no_slopes)
                c = _levels(work[1], y, work[0])[2]
                i = starts
                while i > 0 and c < start_cost[i - 1]:
                    i -= 1
                if i < starts:
                    start_cost[i + 1:] = start_cost[i:-1].copy()
                    start_extent[i + 1:] = start_extent[i:-1].copy()
                    start_width[i + 1:] = start_width[i:-1].copy()
                    start_cost[i] = c
                    start_extent[i] = extent
                    start_width[i] = width
        params = np.empty(3)
        trial = np.empty(3)
        cost = np.inf
        for start in range(starts):
            if start > 0 and not np.isfinite(start_cost[start]):
                break
            trial[0] = centre0[p]
            trial[1] = start_extent[start]
            trial[2] = start_width[start]
            refined = _refine(t, y, trial, start_cost[start], s, box, iterations, floor, converged, work,
                              jacobian, normal, gradient)
            if start == 0 or refined < cost:
                params[:] = trial
                cost = refined
        _shares(t, params[0], params[1], params[2], s, box, work[1], no_slopes)
        lit, full, cost = _levels(work[1], y, work[0])
        _normal_equations(t, y, params, s, box, work, jacobian, normal, gradient)
        params_out[p] = params
        lit_out[p] = lit
        full_out[p] = full
        cost_out[p] = cost
        normal_out[p] = normal
    return params_out, lit_out, full_out, cost_out, normal_out
