"""The penumbra ramp of a disc sun behind a straight edge, fitted per pixel.

The sun is a uniform disc of angular diameter ~0.53 deg. As it sets behind a ridge, the
ridge's skyline seen from a ground point is, over the disc, a straight edge moving at the
sun's angular speed across that skyline, which is nearly constant over the few minutes a
disc takes to pass. The direct-sun light at the point is the visible fraction of the disc,
the circular-segment area law

    v(u) = (arccos u - u sqrt(1 - u^2)) / pi,   u = 2 (t - t_c) / D  clipped to [-1, 1],

with ``t_c`` the time the edge crosses the disc centre (half the disc occluded: the
arrival) and ``D`` the penumbra's duration (disc diameter over the edge's angular speed).
The duration is the same for neighbouring points (the same sun behind the same skyline;
it varies only with the skyline's slope), which is what :func:`coherent_durations` uses.
The pixel's normalised luminance (coverage) is ``S + (L - S) v``: the lit and shadow
levels are fitted with the ramp, so level errors of the first pass do not move ``t_c``.

:func:`fit_ramps` fits ``(t_c, D, L, S)`` (or ``(t_c, L, S)`` with ``D`` given) by
Levenberg-Marquardt from a grid start, pixel by pixel in a compiled kernel
(:mod:`shadowcam.outdoor.ramp_kernels`; work proportional to the samples, no per-pixel
arrays beyond the series), with the
centre's standard error from the fit residual. A ramp with fewer than ``min_samples``
samples inside it is shorter than the sampling resolves: the fit's centre is then not
determined by the law and the caller keeps the level crossing between the two frames
around it (the midpoint crossing).

Offers
------
visible_fraction : the circular-segment law v(u).
ramp_model : coverage of a pixel over time for given centre, duration and levels.
fit_ramps : per-pixel fit of the law to luminance series, with the centre's uncertainty.
coherent_durations : the median fitted duration of each pixel's confident neighbours.
neighbour_median : the median of each pixel's confident neighbours' values.
"""

import numpy as np

from shadowcam._shared.validation import check_positive
from shadowcam.outdoor.ramp_kernels import fit_ramp_pixels

#: fit parameters, in order
PARAMETERS = ("centre_s", "duration_s", "lit", "shadow")
#: centre shifts of the grid start, in durations about the guess
_SHIFTS = np.array([-0.4, -0.2, 0.0, 0.2, 0.4])
#: centre step (intervals) below which a Levenberg-Marquardt fit has converged
_TOLERANCE = 1e-9


def visible_fraction(u):
    """Visible fraction of a uniform disc whose occluding straight edge is at `u` radii.

    Parameters
    ----------
    u : ndarray
        Signed distance of the edge from the disc's centre in radii (-1: the edge touches
        the disc, nothing occluded; 0: half; 1: all). Values outside [-1, 1] are clipped.

    Returns
    -------
    ndarray
        ``(arccos u - u sqrt(1 - u^2)) / pi``, same shape as `u`, in [0, 1].
    """
    u = np.clip(np.asarray(u, dtype=np.float64), -1.0, 1.0)
    return (np.arccos(u) - u * np.sqrt(1.0 - u * u)) / np.pi


def ramp_model(time_s, *, centre_s, duration_s, lit, shadow):
    """Coverage of a pixel as the disc passes: ``shadow + (lit - shadow) v(2 (t - centre) / duration)``.

    Parameters
    ----------
    time_s : ndarray
        Times (s), broadcast against the parameters.
    centre_s, duration_s, lit, shadow : float or ndarray
        Ramp centre (s), duration (s, > 0), lit and shadow levels.

    Returns
    -------
    ndarray
        Broadcast shape of the inputs.
    """
    duration_s = np.asarray(duration_s, dtype=np.float64)
    if np.any(~(duration_s > 0)):
        raise ValueError("duration_s must be > 0")
    u = 2.0 * (np.asarray(time_s, dtype=np.float64) - centre_s) / duration_s
    return shadow + (np.asarray(lit) - shadow) * visible_fraction(u)


def fit_ramps(series, time_s, *, centre_s, interval_s, duration_s=None, shadow=None, speed_change=False, min_samples=3,
              iterations=30):
    """Fit the disc-sun ramp to each pixel's series.

    The law ``S + (L - S) v(2 (t - t_c) / D)`` is fitted by Levenberg-Marquardt from a grid
    start (durations from half an interval to twice the series' length in intervals,
    centres around the guess). The centre's standard error is that of the least-squares covariance scaled by
    the residual, widened by ``(1 + rho) / (1 - rho)`` (``rho`` the residuals' lag-1
    autocorrelation): residuals correlated in time, where the law does not describe the
    ramp exactly (a shade over it, a direct light that drifts, an edge speed that changes),
    carry fewer independent samples.

    Parameters
    ----------
    series : (N, K) ndarray
        Coverage (or luminance) of N pixels at K times each; NaN where unknown. Only the
        final descent should be given (lit before, shadowed after).
    time_s : (N, K) or (K,) ndarray
        Times of the samples (s).
    centre_s : (N,) ndarray
        Start guess of the centre (e.g. the level crossing).
    interval_s : float, keyword-only
        Median capture interval (s): sets the grid of start durations.
    duration_s : (N,) ndarray, optional, keyword-only
        Known durations (s): only the centre and the levels are fitted (NaN: fitted too).
    shadow : (N,) ndarray, optional, keyword-only
        Known shadow levels (NaN: fitted). With the duration known too, only the centre
        and the lit level are fitted: a ramp whose second half the sequence's end cut.
    speed_change : bool, keyword-only
        Let the edge's speed change linearly over the ramp (where the duration is fitted):
        ``u = 2 tau (1 + beta tau)``, ``tau = (t - t_c) / D``, ``|beta| <= 0.45`` (the sun
        along a sloping, curved skyline); the centre is still where half the disc is occluded.
    min_samples : int, keyword-only
        Samples inside the fitted ramp needed for its centre to be resolved.
    iterations : int, keyword-only
        Levenberg-Marquardt iterations.

    Returns
    -------
    dict of (N,) ndarray
        ``centre_s``, ``duration_s``, ``lit``, ``shadow``, ``speed_change`` (``beta``); ``sigma_s`` (standard error of
        the centre; inf where undetermined), ``rms`` (residual rms),
        ``n_inside`` (samples strictly inside the ramp), ``resolved`` (``n_inside >=
        min_samples`` and a finite centre).
    """
    y = np.asarray(series, dtype=np.float64)
    if y.ndim != 2:
        raise ValueError(f"series must be (N, K); got shape {y.shape}")
    t = np.broadcast_to(np.asarray(time_s, dtype=np.float64), y.shape)
    n = y.shape[0]
    c0 = np.asarray(centre_s, dtype=np.float64).reshape(-1)
    if c0.shape != (n,):
        raise ValueError(f"centre_s must be ({n},); got shape {np.shape(centre_s)}")
    check_positive(interval_s, "interval_s", finite=True)
    if int(min_samples) < 1:
        raise ValueError(f"min_samples must be >= 1; got {min_samples}")
    fixed = np.full(n, np.nan) if duration_s is None else np.asarray(duration_s, dtype=np.float64).reshape(-1)
    if fixed.shape != (n,):
        raise ValueError(f"duration_s must be ({n},); got shape {np.shape(duration_s)}")
    level = np.full(n, np.nan) if shadow is None else np.asarray(shadow, dtype=np.float64).reshape(-1)
    if level.shape != (n,):
        raise ValueError(f"shadow must be ({n},); got shape {np.shape(shadow)}")
    span = float(interval_s) * max(y.shape[1] - 1, 1)
    start = np.where(np.isfinite(c0), c0, 0.0)
    # grid start (it depends on the series' length only: pixels fitted together or apart agree):
    # durations from half an interval to twice the span, centres around the guess
    durations = interval_s * np.geomspace(0.5, max(2.0 * span / interval_s, 1.0), 14)
    bounds = np.log([0.05 * interval_s, 4.0 * span + interval_s])
    p, sse, jtj, lag, n_inside, count = fit_ramp_pixels(
        np.ascontiguousarray(t), np.ascontiguousarray(y), start, fixed, level, durations, _SHIFTS, bounds, int(iterations),
        _TOLERANCE * float(interval_s), bool(speed_change))
    free = np.ones((n, 5))
    free[np.isfinite(fixed), 1] = 0.0
    free[np.isfinite(level), 3] = 0.0
    free[:, 4] = 0.0 if not speed_change else np.where(np.isfinite(fixed), 0.0, 1.0)
    n_params = free.sum(-1)
    jtj = jtj + (1.0 - free)[:, :, None] * np.eye(5)  # fixed: unit diagonal
    with np.errstate(invalid="ignore", divide="ignore"):
        rho = np.clip(lag / np.maximum(sse, 1e-300), 0.0, 0.95)
        cond_ok = np.linalg.cond(jtj) < 1e12
        cov = np.linalg.pinv(jtj)
        sigma = np.sqrt(np.maximum(sse / np.maximum(count - n_params, 1), 0.0) * cov[:, 0, 0]
                        * (1.0 + rho) / (1.0 - rho))
    sigma = np.where(cond_ok & (n_inside >= 2) & np.isfinite(sigma), sigma, np.inf)
    duration = np.exp(p[:, 1])
    centre = np.where(np.isfinite(c0), p[:, 0], np.nan)
    resolved = (n_inside >= int(min_samples)) & np.isfinite(centre) & (count > n_params)
    return {"centre_s": centre, "duration_s": duration, "lit": p[:, 2], "shadow": p[:, 3], "sigma_s": sigma,
            "speed_change": p[:, 4], "rms": np.sqrt(sse / np.maximum(count, 1)), "n_inside": n_inside,
            "resolved": resolved}


def neighbour_median(values, confident, *, radius=3, at=None, spread=False):
    """Median of each pixel's confident, finite neighbours (the pixel included).

    Parameters
    ----------
    values : (H, W) ndarray
    confident : (H, W) bool ndarray
        Pixels whose values are trusted.
    radius : int or (int, int), keyword-only
        Half size of the neighbourhood (pixels), or ``(rows, cols)``.
    at : tuple of (N,) int ndarray, optional, keyword-only
        ``(rows, cols)`` of the pixels wanted (default: every pixel).
    spread : bool, keyword-only
        Also return the values' spread about the median (1.4826 times their median absolute
        deviation: the standard deviation of normal values) and their count.

    Returns
    -------
    (H, W) or (N,) float64 ndarray
        NaN where the neighbourhood has no confident finite value. With `spread`, a tuple
        ``(median, spread, count)`` of such arrays (``count`` int64).
    """
    values = np.asarray(values, dtype=np.float64)
    confident = np.asarray(confident, dtype=bool)
    if values.ndim != 2 or confident.shape != values.shape:
        raise ValueError(f"values {values.shape} and confident {confident.shape} must be the same (H, W) shape")
    rr, rc = (radius, radius) if np.ndim(radius) == 0 else radius
    if int(rr) < 0 or int(rc) < 0:
        raise ValueError(f"radius must be >= 0; got {radius}")
    rr, rc = int(rr), int(rc)
    if at is None:
        rows, cols = (g.ravel() for g in np.indices(values.shape))
    else:
        rows, cols = (np.asarray(a, dtype=np.int64).reshape(-1) for a in at)
    kept = np.where(confident & np.isfinite(values), values, np.nan).astype(np.float32)
    padded = np.pad(kept, ((rr, rr), (rc, rc)), constant_values=np.nan)
    dr, dc = (g.ravel() for g in np.indices((2 * rr + 1, 2 * rc + 1)))
    out = np.full(rows.size, np.nan)
    mad = np.full(rows.size, np.nan)
    count = np.zeros(rows.size, dtype=np.int64)
    candidates = np.nonzero(_any_in_window(np.isfinite(kept), rr, rc)[rows, cols])[0]
    step = max(1, 2**22 // dr.size)
    for a in range(0, candidates.size, step):
        idx = candidates[a:a + step]
        window = padded[rows[idx, None] + dr[None, :], cols[idx, None] + dc[None, :]]
        with np.errstate(all="ignore"):
            out[idx] = np.nanmedian(window, axis=-1)
            if spread:
                mad[idx] = 1.4826 * np.nanmedian(np.abs(window - out[idx, None]), axis=-1)
                count[idx] = np.isfinite(window).sum(axis=-1)
    shaped = (lambda a: a.reshape(values.shape)) if at is None else (lambda a: a)
    return (shaped(out), shaped(mad), shaped(count)) if spread else shaped(out)


def _any_in_window(mask, rr, rc):
    """Whether any pixel of the (2 rr + 1) x (2 rc + 1) window around each pixel is set."""
    c = np.pad(mask, ((rr + 1, rr), (rc + 1, rc))).astype(np.int64).cumsum(0).cumsum(1)
    h, w = mask.shape
    total = (c[2 * rr + 1:2 * rr + 1 + h, 2 * rc + 1:2 * rc + 1 + w] - c[:h, 2 * rc + 1:2 * rc + 1 + w]
             - c[2 * rr + 1:2 * rr + 1 + h, :w] + c[:h, :w])
    return total > 0


def coherent_durations(duration_s, confident, *, radius=3, at=None):
    """Median duration of each pixel's confident neighbours (the pixel included).

    Parameters
    ----------
    duration_s : (H, W) ndarray
        Fitted penumbra durations (s).
    confident : (H, W) bool ndarray
        Pixels whose fit is trusted (resolved, small uncertainty, not cut by the sequence end).
    radius : int or (int, int), keyword-only
        Half size of the neighbourhood (pixels), or ``(rows, cols)``.
    at : tuple of (N,) int ndarray, optional, keyword-only
        ``(rows, cols)`` of the pixels wanted (default: every pixel).

    Returns
    -------
    (H, W) or (N,) float64 ndarray
        NaN where the neighbourhood has no confident pixel.
    """
    duration = np.asarray(duration_s, dtype=np.float64)
    if duration.ndim != 2:
        raise ValueError(f"duration_s must be (H, W); got shape {duration.shape}")
    with np.errstate(all="ignore"):
        log = np.where(duration > 0, np.log(np.where(duration > 0, duration, 1.0)), np.nan)
    return np.exp(neighbour_median(log, confident, radius=radius, at=at))
