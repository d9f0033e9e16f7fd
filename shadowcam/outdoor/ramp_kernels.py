"""Compiled per-pixel fits of the outdoor wing (numba): the disc-sun ramp and the half-level line.

One pixel at a time (pixels in parallel with ``prange``): its finite samples are gathered
once, the grid start is scanned, then Levenberg-Marquardt steps are taken with the 5x5
normal equations (centre, log duration, levels, speed change; fixed parameters' columns
zero) accumulated in the same pass as the residual and solved by Gaussian elimination; the
steps stop once the damping is small, the centre's step is below the tolerance and the log
duration's and speed change's below ``1e-9`` (a converged fit does not move further).
All arithmetic is float64. The law and the fit are those of
:func:`shadowcam.outdoor.penumbra.fit_ramps`, which validates the inputs and turns the
normal equations into the centre's standard error.

The half-level crossing (:func:`half_level_pixels`) takes one pass over a pixel's samples to
gather the finite ones and find the last downward crossing, then a line over the window
around it from its centred sums; :func:`shadowcam.outdoor.half_level.half_level_crossings`
validates the inputs.

The levels at the ends of a descent (:func:`end_level_pixels`, pixels in turn: a few hundred
operations per pixel, less than a parallel launch costs on a loaded machine) gather a
pixel's first (or last) finite samples in one pass from that end, then take their mean and line from centred
sums added in numpy's pairwise order (eight running sums, then the remainder; up to 128
samples), so that the results are those of the vectorised formulation bit for bit;
:func:`shadowcam.outdoor.half_level.end_level` validates the inputs.

Offers
------
fit_ramp_pixels : grid start and Levenberg-Marquardt fit of every pixel's series.
half_level_pixels : last downward crossing of each pixel's half level and its local line.
end_level_pixels : level, line slope, plateau test and lowest sample at an end of each pixel's series.
"""

import numba as nb
import numpy as np

_INV_PI = 1.0 / np.pi
_TWO_OVER_PI = 2.0 / np.pi
#: bound of the speed change ``beta``: ``u = 2 tau (1 + beta tau)`` stays monotonic over the ramp
_MAX_SPEED_CHANGE = 0.45


@nb.njit(cache=True, inline="always")
def _segment(u):
    """(v, sqrt(1 - u^2)) of the clipped `u`: the visible fraction and its slope's root."""
    if u >= 1.0:
        return 0.0, 0.0
    if u <= -1.0:
        return 1.0, 0.0
    root = np.sqrt(1.0 - u * u)
    return (np.arccos(u) - u * root) * _INV_PI, root


@nb.njit(cache=True, inline="always")
def _edge(tau, beta):
    """The edge's distance from the disc's centre, ``2 tau (1 + beta tau)``, held beyond the disc
    where the quadratic turns back (``1 + 2 beta tau <= 0``, at ``|u| >= 1 / (2 |beta|) > 1``)."""
    if 1.0 + 2.0 * beta * tau <= 0.0:
        return -2.0 if beta > 0.0 else 2.0
    return 2.0 * tau * (1.0 + beta * tau)


@nb.njit(cache=True)
def _grid_sse(t, y, m, yy, tc, dur, shadow_known, out):
    """Least-squares levels of the ramp (tc, dur) and its residual; `out` = (lit, shadow); inf if degenerate.

    One pass: at the solution of the normal equations the residual is ``yy - L a.y - S b.y``
    (`yy` the sum of squares of the series). With `shadow_known` finite (the series then
    taken relative to it: ``y - S``, `yy` its sum of squares) only the lit level is solved.
    """
    aa = 0.0
    bb = 0.0
    ab = 0.0
    ay = 0.0
    by = 0.0
    for k in range(m):
        v, _ = _segment(2.0 * (t[k] - tc) / dur)
        c = 1.0 - v
        aa += v * v
        bb += c * c
        ab += v * c
        ay += v * y[k]
        by += c * y[k]
    if np.isfinite(shadow_known):
        ay -= shadow_known * (aa + ab)  # sum of v (y - S)
        if not aa > 1e-30:
            return np.inf
        amplitude = ay / aa
        out[0] = shadow_known + amplitude
        out[1] = shadow_known
        return max(yy - amplitude * ay, 0.0)
    det = aa * bb - ab * ab
    if not det > 1e-9 * max(aa * bb, 1e-30):
        return np.inf
    lit = (ay * bb - by * ab) / det
    shadow = (by * aa - ay * ab) / det
    out[0] = lit
    out[1] = shadow
    return max(yy - lit * ay - shadow * by, 0.0)


@nb.njit(cache=True)
def _normal(t, y, m, p, free, jtj, jtr):
    """Residual sum of squares at `p` and the normal equations ``J^T J``, ``J^T r`` (filled in place).

    The edge's distance from the disc's centre is ``u = 2 tau (1 + beta tau)``, ``tau = (t - t_c) / D``
    (``beta = 0``: a constant speed); `free` zeroes the columns of fixed parameters.
    """
    tc, q, lit, shadow, beta = p[0], p[1], p[2], p[3], p[4]
    duration = np.exp(q)
    for i in range(5):
        jtr[i] = 0.0
        for j in range(5):
            jtj[i, j] = 0.0
    col = np.empty(5)
    sse = 0.0
    for k in range(m):
        tau = (t[k] - tc) / duration
        u = _edge(tau, beta)
        v, root = _segment(u)
        r = y[k] - (shadow + (lit - shadow) * v)
        amp = (lit - shadow) * (-_TWO_OVER_PI) * root
        rate = 1.0 + 2.0 * beta * tau
        col[0] = amp * (-2.0 / duration) * rate * free[0]
        col[1] = amp * (-2.0 * tau) * rate * free[1]
        col[2] = v * free[2]
        col[3] = (1.0 - v) * free[3]
        col[4] = amp * 2.0 * tau * tau * free[4]
        sse += r * r
        for i in range(5):
            jtr[i] += col[i] * r
            for j in range(i, 5):
                jtj[i, j] += col[i] * col[j]
    for i in range(5):
        for j in range(i):
            jtj[i, j] = jtj[j, i]
    return sse


@nb.njit(cache=True)
def _solve(a, b, x):
    """Solve the small system ``a x = b`` by Gaussian elimination with partial pivoting (`a`, `b` overwritten)."""
    n = b.size
    for c in range(n):
        piv = c
        for r in range(c + 1, n):
            if abs(a[r, c]) > abs(a[piv, c]):
                piv = r
        if piv != c:
            for j in range(n):
                a[c, j], a[piv, j] = a[piv, j], a[c, j]
            b[c], b[piv] = b[piv], b[c]
        for r in range(c + 1, n):
            f = a[r, c] / a[c, c]
            for j in range(c, n):
                a[r, j] -= f * a[c, j]
            b[r] -= f * b[c]
    for c in range(n - 1, -1, -1):
        s = b[c]
        for j in range(c + 1, n):
            s -= a[c, j] * x[j]
        x[c] = s / a[c, c]


@nb.njit(cache=True, parallel=True)
def fit_ramp_pixels(t_all, y_all, start, fixed, shadow_fixed, durations, shifts, log_bounds, iterations, tolerance,
                    speed_change):
    """Fit ``S + (L - S) v(2 (t - t_c) / exp(q))`` to each pixel's finite samples.

    Parameters
    ----------
    t_all, y_all : (N, K) float64 ndarray
        Times and values; a sample takes part where both are finite.
    start : (N,) float64 ndarray
        Centre guess (finite).
    fixed : (N,) float64 ndarray
        Known duration (NaN: fitted).
    shadow_fixed : (N,) float64 ndarray
        Known shadow level (NaN: fitted).
    durations, shifts : (D,), (S,) float64 ndarray
        Grid start: durations, and centre shifts in durations about the guess.
    log_bounds : (2,) float64 ndarray
        Bounds of the log duration.
    iterations : int
        Largest number of Levenberg-Marquardt steps.
    tolerance : float
        Step of the centre (s) below which a fit with small damping has converged.
    speed_change : bool
        Fit ``beta`` too (where the duration is fitted), within +-0.45 (the edge's distance
        then grows monotonically over the ramp).

    Returns
    -------
    p : (N, 5) float64 ndarray
        ``(t_c, log D, L, S, beta)``.
    sse : (N,) float64 ndarray
        Residual sum of squares.
    jtj : (N, 5, 5) float64 ndarray
        Normal matrix at `p` (the rows and columns of fixed parameters are zero).
    lag : (N,) float64 ndarray
        Sum of the products of consecutive residuals (both samples finite).
    n_inside : (N,) int64 ndarray
        Finite samples strictly inside the ramp.
    count : (N,) int64 ndarray
        Finite samples.
    """
    n, kk = y_all.shape
    p_out = np.zeros((n, 5))
    sse_out = np.zeros(n)
    jtj_out = np.zeros((n, 5, 5))
    lag_out = np.zeros(n)
    inside_out = np.zeros(n, np.int64)
    count_out = np.zeros(n, np.int64)
    for i in nb.prange(n):
        t = np.empty(kk)
        y = np.empty(kk)
        index = np.empty(kk, np.int64)
        m = 0
        for k in range(kk):
            if np.isfinite(t_all[i, k]) and np.isfinite(y_all[i, k]):
                t[m] = t_all[i, k]
                y[m] = y_all[i, k]
                index[m] = k
                m += 1
        count_out[i] = m
        known_s = np.isfinite(shadow_fixed[i])
        offset = shadow_fixed[i] if known_s else 0.0
        yy = 0.0
        for k in range(m):
            yy += (y[k] - offset) * (y[k] - offset)
        levels = np.empty(2)
        p = np.zeros(5)
        best = np.inf
        known = np.isfinite(fixed[i])
        for d in range(durations.size):
            dur = fixed[i] if known else durations[d]
            for s in range(shifts.size):
                tc = start[i] + shifts[s] * dur
                sse = _grid_sse(t, y, m, yy, tc, dur, shadow_fixed[i], levels)
                if np.isfinite(sse) and sse < best:
                    best = sse
                    p[0] = tc
                    p[1] = np.log(dur)
                    p[2] = levels[0]
                    p[3] = levels[1]
            if known:
                break
        free = np.ones(5)
        free[1] = 0.0 if known else 1.0
        free[3] = 0.0 if known_s else 1.0
        free[4] = 1.0 if speed_change and not known else 0.0
        jtj = np.empty((5, 5))
        jtr = np.empty(5)
        a = np.empty((5, 5))
        b = np.empty(5)
        step = np.empty(5)
        trial = np.empty(5)
        jtj2 = np.empty((5, 5))
        jtr2 = np.empty(5)
        sse = _normal(t, y, m, p, free, jtj, jtr)
        lam = 1e-3
        for _ in range(iterations):
            dmax = 0.0
            for r in range(5):
                dmax = max(dmax, jtj[r, r])
            floor = 1e-12 * (dmax + 1e-30)
            for r in range(5):
                for c in range(5):
                    a[r, c] = jtj[r, c]
                a[r, r] += lam * max(jtj[r, r], floor) + 1e-12
                b[r] = jtr[r]
            _solve(a, b, step)
            for r in range(5):
                trial[r] = p[r] + step[r] * free[r]
            trial[1] = min(max(trial[1], log_bounds[0]), log_bounds[1])
            trial[4] = min(max(trial[4], -_MAX_SPEED_CHANGE), _MAX_SPEED_CHANGE)
            sse2 = _normal(t, y, m, trial, free, jtj2, jtr2)
            if np.isfinite(sse2) and sse2 <= sse:
                small = (lam <= 1e-2 and abs(step[0]) <= tolerance and abs(step[1] * free[1]) <= 1e-9
                         and abs(step[4] * free[4]) <= 1e-9)
                for r in range(5):
                    p[r] = trial[r]
                    jtr[r] = jtr2[r]
                    for c in range(5):
                        jtj[r, c] = jtj2[r, c]
                sse = sse2
                lam = max(lam / 3.0, 1e-9)
                if small:
                    break
            else:
                lam = min(lam * 10.0, 1e9)
        duration = np.exp(p[1])
        lag = 0.0
        previous = 0.0
        inside = 0
        for k in range(m):
            tau = (t[k] - p[0]) / duration
            u = _edge(tau, p[4])
            v, _ = _segment(u)
            r = y[k] - (p[3] + (p[2] - p[3]) * v)
            if k > 0 and index[k] == index[k - 1] + 1:
                lag += r * previous
            previous = r
            if abs(u) < 1.0:
                inside += 1
        for r in range(5):
            p_out[i, r] = p[r]
            for c in range(5):
                jtj_out[i, r, c] = jtj[r, c]
        sse_out[i] = sse
        lag_out[i] = lag
        inside_out[i] = inside
    return p_out, sse_out, jtj_out, lag_out, inside_out, count_out


@nb.njit(cache=True, parallel=True, error_model="numpy")
def half_level_pixels(t_all, y_all, level, half_window):
    """The last downward crossing of each pixel's `level`, refined by a line over +-`half_window` samples.

    Parameters
    ----------
    t_all, y_all : (N, K) float64 ndarray
        Times and values; a sample takes part where both are finite.
    level : (N,) float64 ndarray
        Half level (not finite: no crossing).
    half_window : (N,) int64 ndarray
        ``k`` (>= 1): the line runs over the ``k`` finite samples each side of the crossing.

    Returns
    -------
    crossing, sigma, step, slope : (N,) float64 ndarray
        As :func:`shadowcam.outdoor.half_level.half_level_crossings` (NaN where there is no
        crossing).
    """
    n, kk = y_all.shape
    out = np.full((4, n), np.nan)
    crossing, sigma, step, rate = out[0], out[1], out[2], out[3]
    for i in nb.prange(n):
        if not np.isfinite(level[i]):
            continue
        t = np.empty(kk)
        y = np.empty(kk)
        m = 0
        j = -1
        for k in range(kk):
            if np.isfinite(t_all[i, k]) and np.isfinite(y_all[i, k]):
                t[m] = t_all[i, k]
                y[m] = y_all[i, k] - level[i]
                if m > 0 and y[m - 1] >= 0.0 and y[m] < 0.0:
                    j = m - 1
                m += 1
        if j < 0:
            continue
        step[i] = y[j] - y[j + 1]
        a = max(j - half_window[i] + 1, 0)
        b = min(j + half_window[i] + 1, m)
        w = b - a
        tm = 0.0
        ym = 0.0
        for q in range(a, b):
            tm += t[q]
            ym += y[q]
        tm /= w
        ym /= w
        sxx = 0.0
        sxy = 0.0
        for q in range(a, b):
            sxx += (t[q] - tm) * (t[q] - tm)
            sxy += (t[q] - tm) * (y[q] - ym)
        slope = sxy / sxx
        if slope < 0.0 and w > 2:
            crossing[i] = tm - ym / slope
            s2 = 0.0
            for q in range(a, b):
                r = y[q] - ym - slope * (t[q] - tm)
                s2 += r * r
            s2 /= w - 2
            sigma[i] = np.sqrt(s2 * (1.0 / w + (crossing[i] - tm) ** 2 / sxx)) / -slope
            rate[i] = slope
        else:
            crossing[i] = t[j] + y[j] / (y[j] - y[j + 1]) * (t[j + 1] - t[j])
            sigma[i] = np.inf
            rate[i] = -step[i] / (t[j + 1] - t[j])
    return crossing, sigma, step, rate


@nb.njit(cache=True)
def _pairwise_block(a, lo, hi):
    """Sum of ``a[lo:hi]`` (at most 128 values) in numpy's pairwise order."""
    n = hi - lo
    if n < 8:
        s = 0.0
        for q in range(lo, hi):
            s += a[q]
        return s
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    q = lo + 8
    stop = lo + n - n % 8
    while q < stop:
        r0 += a[q]
        r1 += a[q + 1]
        r2 += a[q + 2]
        r3 += a[q + 3]
        r4 += a[q + 4]
        r5 += a[q + 5]
        r6 += a[q + 6]
        r7 += a[q + 7]
        q += 8
    s = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while q < hi:
        s += a[q]
        q += 1
    return s


@nb.njit(cache=True)
def _pairwise_sum(a, n):
    """Sum of ``a[:n]``: numpy's ``add.reduce`` order up to 128 values, its 128-value blocks added in turn beyond."""
    s = _pairwise_block(a, 0, min(n, 128))
    for lo in range(128, n, 128):
        s += _pairwise_block(a, lo, min(n, lo + 128))
    return s


@nb.njit(cache=True, error_model="numpy")
def end_level_pixels(t_all, y_all, samples, z_squared, from_end):
    """Level, line slope, plateau test and lowest value of each pixel's first (or last) `samples` finite samples.

    Parameters
    ----------
    t_all, y_all : (N, K) float64 ndarray
        Times and values; a sample takes part where both are finite.
    samples : int
        Samples at the end (at least 3).
    z_squared : float
        Square of the standard errors of the slope within which the samples are a plateau.
    from_end : bool
        The last samples (taken from the last one backwards) instead of the first.

    Returns
    -------
    level, slope, low : (N,) float64 ndarray
        Mean, line slope and smallest of the samples (NaN where fewer than `samples` are finite).
    plateau : (N,) bool ndarray
        The slope is within ``sqrt(z_squared)`` standard errors of zero (and the times differ).
    """
    n, kk = y_all.shape
    out = np.full((3, n), np.nan)
    level, rate, low = out[0], out[1], out[2]
    plateau = np.zeros(n, dtype=np.bool_)
    t = np.empty(samples)
    y = np.empty(samples)
    work = np.empty(samples)
    for i in range(n):
        m = 0
        for step in range(kk):
            k = kk - 1 - step if from_end else step
            if np.isfinite(t_all[i, k]) and np.isfinite(y_all[i, k]):
                t[m] = t_all[i, k]
                y[m] = y_all[i, k]
                m += 1
                if m == samples:
                    break
        if m < samples:
            continue
        mean_y = _pairwise_sum(y, samples) / samples
        mean_t = _pairwise_sum(t, samples) / samples
        smallest = y[0]
        for q in range(samples):
            t[q] -= mean_t
            work[q] = t[q] * t[q]
            smallest = min(smallest, y[q])
        sxx = _pairwise_sum(work, samples)
        for q in range(samples):
            work[q] = t[q] * (y[q] - mean_y)
        slope = _pairwise_sum(work, samples) / sxx
        for q in range(samples):
            r = y[q] - mean_y - slope * t[q]
            work[q] = r * r
        s2 = _pairwise_sum(work, samples) / (samples - 2)
        level[i] = mean_y
        rate[i] = slope
        low[i] = smallest
        plateau[i] = sxx > 0.0 and slope * slope <= z_squared * s2 / sxx
    return level, rate, low, plateau
