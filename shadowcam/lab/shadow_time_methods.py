"""The shadow-time methods: a classified dip's window -> its time to a fraction of a frame.

Each method takes a :class:`~shadowcam.lab.dip_tracker.DipSummary` whose window is NaN
outside the pixels to time and returns ``(time, entry, exit, time_std)``. The default,
``edge_fit``, adds the spatial structure of the shadow edge
(:mod:`shadowcam.lab.edge_refine`): a pixel's own samples are nearly on/off when the
shadow crosses it within a frame, so its neighbours' times sharpen it (paper II-A: the
shadow camera's resolution depends on the edge detector, not on the shadow width). On
demosaiced RAW it times each pixel from its own mosaic site where that dip is
significant (:func:`_site_times`, :mod:`shadowcam.lab.site_signal`).

Offers
------
SHADOW_TIME_METHODS : name -> timing function ``f(summary) -> (time, entry, exit, time_std)``.
time_midpoint_crossing_BouguetPerona1998, time_argmin_parabolic, time_dip_centroid,
time_gaussian_fit_Caruana1986, time_argmin_gaussian_smoothed, time_edge_fit : the methods.
"""

import numba as nb
import numpy as np

from shadowcam._shared.flux_centroid import flux_centroid_shift
from shadowcam._shared.validation import check_positive
from shadowcam.lab.dip_classification import _SMOOTHED_NOISE, detection_threshold
from shadowcam.lab.edge_refine import refine_times
from shadowcam.lab.site_signal import blend_variance

#: probability that a RAW site's own samples of pure noise pass as a dip (``classify_dips``'
#: default `false_alarm`): below it a pixel is timed from the channel sum
_SITE_FALSE_ALARM = 1e-2


def _coverage(summary):
    """Fraction of light removed in each window frame, ``(K, H, W)``; NaN outside."""
    return _removed_fraction(summary.window, summary.lit_level)


def _removed_fraction(window, lit_level):
    """``1 - window / lit_level`` clipped to [0, 1], ``(K, H, W)``; NaN where `window` is."""
    with np.errstate(invalid="ignore", divide="ignore"):
        level = lit_level[None]
        return np.clip(1.0 - window / level, 0.0, 1.0)


@nb.njit(cache=True, parallel=True, error_model="numpy")
def _centroid_kernel(window, lit_level, window_start, noise):
    """:func:`_centroid` per pixel of ``window (K, H, W)``: its coverage (as
    :func:`_removed_fraction` of a float64 `lit_level`, the quotient in float64) and the
    centroid in one pass over the window, both cores."""
    n_k, rows, cols = window.shape
    centre = np.empty((rows, cols))
    std = np.empty((rows, cols))
    for r in nb.prange(rows):
        coverage = np.empty(n_k)
        for c in range(cols):
            total = 0.0
            moment = 0.0
            for k in range(n_k):
                v = 1.0 - np.float64(window[k, r, c]) / lit_level[r, c]
                v = 0.0 if v < 0.0 else (1.0 if v > 1.0 else v)  # np.clip: NaN stays NaN
                coverage[k] = v
                if np.isfinite(v):
                    total += v
                    moment += v * np.float64(window_start[r, c] + k)
            mean = moment / total
            spread = 0.0
            for k in range(n_k):
                if np.isfinite(coverage[k]):
                    spread += (np.float64(window_start[r, c] + k) - mean) ** 2
            centre[r, c] = mean
            std[r, c] = noise[r, c] / lit_level[r, c] * np.sqrt(spread) / total
    return centre, std


def _centroid(window, lit_level, window_start, noise):
    """Coverage-weighted mean time and its noise standard deviation, ``(H, W)`` each.

    The coverage is :func:`_removed_fraction` of ``window (K, H, W)`` and ``lit_level
    (H, W)``; each coverage sample carries noise ``noise / lit_level``, propagated to the
    mean; non-finite samples take no part.
    """
    return _centroid_kernel(window, np.asarray(lit_level, np.float64), window_start, noise)


def _crossings(summary, threshold):
    """Entry and exit times where the signal crosses `threshold` (linear interpolation).

    The crossings nearest to the minimum on each side are used; NaN where the
    dip does not come back above `threshold` inside the window.
    """
    return _crossings_kernel(summary.window, np.asarray(threshold, np.float64), summary.window_start,
                             summary.half_window)


@nb.njit(cache=True, parallel=True, error_model="numpy")
def _crossings_kernel(window, threshold, window_start, half_window):
    """:func:`_crossings` per pixel: the last slot before the centre (``half_window``) at or
    above the threshold and the next one, the first after it and the one before, each pair
    interpolated as ``start + a + (w[a] - t) / (w[a] - w[b]) * (b - a)``."""
    k, rows, cols = window.shape
    h = half_window
    entry = np.full((rows, cols), np.nan)
    exit_ = np.full((rows, cols), np.nan)
    for r in nb.prange(rows):
        for c in range(cols):
            t = threshold[r, c]
            if not window[h, r, c] < t:  # the centre must be below the threshold
                continue
            start = window_start[r, c]
            left = -1
            for j in range(h):
                if window[j, r, c] >= t:
                    left = j
            right = k
            for j in range(k - 1, h, -1):
                if window[j, r, c] >= t:
                    right = j
            entry[r, c] = _interpolated(window, r, c, left, left + 1, t, start)
            exit_[r, c] = _interpolated(window, r, c, right, right - 1, t, start)
    return entry, exit_


@nb.njit(cache=True, inline="always", error_model="numpy")
def _interpolated(window, r, c, a, b, t, start):
    """Crossing of `t` between slots `a` and `b` of pixel ``(r, c)``; NaN outside the window
    or where the quotient is not finite."""
    k = window.shape[0]
    if a >= 0 and a < k and b >= 0 and b < k:
        va, vb = window[a, r, c], window[b, r, c]
        frac = (va - t) / (va - vb)
        if np.isfinite(frac):
            return np.float64(start + a) + frac * np.float64(b - a)
    return np.nan


def _noise_time_std(summary, depth):
    """Rough time uncertainty of a crossing: noise / slope of a one-frame edge."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return summary.noise / depth


def time_midpoint_crossing_BouguetPerona1998(summary):
    """Midpoint of the entry and exit crossings of (Imax + Imin) / 2.

    Bouguet & Perona, "3D photography on your desk", ICCV 1998: the shadow
    time is where the temporal profile crosses the mean of its extremes, with
    linear interpolation between frames; entry and exit are both kept.
    """
    minimum = np.nanmin(np.where(np.isfinite(summary.window), summary.window, np.inf), axis=0)
    threshold = 0.5 * (summary.lit_level + minimum)
    entry, exit_ = _crossings(summary, threshold)
    depth = summary.lit_level - minimum
    return 0.5 * (entry + exit_), entry, exit_, _noise_time_std(summary, depth)


def time_argmin_parabolic(summary):
    """Deepest frame of the [1, 2, 1]-smoothed profile, refined by a parabola.

    The vertex of the parabola through the smoothed samples at the minimum
    and its two neighbours gives the sub-frame offset (clipped to +-0.5).
    """
    win = summary.window.astype(np.float64)
    h = summary.half_window
    padded = np.concatenate([win[:1], win, win[-1:]])
    padded = np.where(np.isfinite(padded), padded, np.nan)
    smooth = 0.25 * padded[:-2] + 0.5 * padded[1:-1] + 0.25 * padded[2:]
    s_m, s_0, s_p = smooth[h - 1], smooth[h], smooth[h + 1]
    curvature = s_m - 2 * s_0 + s_p
    with np.errstate(invalid="ignore", divide="ignore"):
        offset = np.clip(0.5 * (s_m - s_p) / curvature, -0.5, 0.5)
    offset = np.where(np.isfinite(offset), offset, 0.0)
    time = summary.minimum_frame + offset
    depth = summary.lit_level - summary.minimum_value
    with np.errstate(invalid="ignore", divide="ignore"):
        std = summary.noise * _SMOOTHED_NOISE / np.abs(curvature)
    entry, exit_ = _crossings(summary, 0.5 * (summary.lit_level + summary.minimum_value))
    return time, entry, exit_, np.minimum(std, 0.5) + 0 * depth


def time_dip_centroid(summary):
    """Centroid of the removed-light fraction over the window around the minimum.

    With the dip fully inside the window, the centroid of ``1 - I / I_lit``
    is the time the shadow's centre line crosses the pixel, using the partial
    coverage of the frames at the dip's edges.
    """
    time, std = _centroid(summary.window, summary.lit_level, summary.window_start, summary.noise)
    threshold = summary.lit_level * 0.5 + 0.5 * summary.minimum_value
    entry, exit_ = _crossings(summary, threshold)
    return time, entry, exit_, std


def time_gaussian_fit_Caruana1986(summary):
    """Vertex of a Gaussian through the three most covered frames of the dip.

    Caruana, Searle, Heller & Shupack, "Fast algorithm for the resolution of
    spectra", Anal. Chem. 58 (1986): the logarithm of a Gaussian is a
    parabola, so the vertex of the parabola through ``log coverage`` at the
    most covered frame and its two neighbours is the Gaussian's centre
    (offset clipped to +-1 frame; a flat top falls back to the middle of the
    most covered frames).
    """
    coverage = np.nan_to_num(_coverage(summary), nan=0.0)
    k = coverage.shape[0]
    first, last = np.argmax(coverage, axis=0), k - 1 - np.argmax(coverage[::-1], axis=0)
    peak = np.clip((first + last + 1) // 2, 1, k - 2)[None]
    c_m, c_0, c_p = (np.take_along_axis(coverage, peak + d, 0)[0] for d in (-1, 0, 1))
    l_m, l_0, l_p = (np.log(np.maximum(c, 1e-3)) for c in (c_m, c_0, c_p))
    curvature = l_m - 2 * l_0 + l_p
    with np.errstate(invalid="ignore", divide="ignore"):
        offset = np.where(curvature < 0, 0.5 * (l_m - l_p) / curvature, 0.0)
        # noise sigma / level on each coverage sample, through d offset / d log c = 1 / c
        rel = summary.noise / summary.lit_level
        std = 0.5 * rel * np.sqrt(1 / np.maximum(c_m, 1e-3) ** 2 + 1 / np.maximum(c_p, 1e-3) ** 2)
        std = std / np.abs(curvature)
    time = summary.window_start + peak[0] + np.clip(offset, -1.0, 1.0)
    threshold = 0.5 * (summary.lit_level + summary.minimum_value)
    entry, exit_ = _crossings(summary, threshold)
    return time, entry, exit_, np.minimum(std, 1.0)


def time_argmin_gaussian_smoothed(summary, *, sigma=1.0):
    """Deepest frame of the Gaussian-smoothed profile, refined by a parabola.

    Temporal smoothing before the minimum: the window is convolved with a
    Gaussian of `sigma` frames (samples outside the window or non-finite
    replaced by the nearest valid edge), then the parabola through the
    smoothed minimum and its neighbours gives the sub-frame offset.
    """
    check_positive(sigma, "sigma")
    win = summary.window.astype(np.float64)
    k = win.shape[0]
    radius = max(1, int(np.ceil(3 * sigma)))
    taps = np.exp(-0.5 * (np.arange(-radius, radius + 1) / sigma) ** 2)
    taps /= taps.sum()
    filled = np.where(np.isfinite(win), win, summary.lit_level[None])
    padded = np.concatenate([np.repeat(filled[:1], radius, 0), filled, np.repeat(filled[-1:], radius, 0)])
    smooth = sum(t * padded[i:i + k] for i, t in enumerate(taps))
    centre = np.clip(np.argmin(smooth[1:-1], axis=0) + 1, 1, k - 2)[None]
    s_m, s_0, s_p = (np.take_along_axis(smooth, centre + d, 0)[0] for d in (-1, 0, 1))
    curvature = s_m - 2 * s_0 + s_p
    with np.errstate(invalid="ignore", divide="ignore"):
        offset = np.clip(0.5 * (s_m - s_p) / curvature, -0.5, 0.5)
        noise = summary.noise * np.sqrt(np.sum(taps**2))
        std = np.minimum(noise / np.abs(curvature), 0.5)
    time = summary.window_start + centre[0] + np.where(np.isfinite(offset), offset, 0.0)
    entry, exit_ = _crossings(summary, 0.5 * (summary.lit_level + summary.minimum_value))
    return time, entry, exit_, std


def _site_times(summary, site, *, noise_floor=1e-4):
    """Each RAW pixel's time from its own site, joined by its neighbours' where they agree.

    The own site's samples (``site.window``, masked as `summary`'s window) give the
    removed-light centroid of the site's own footprint, where the own dip is deeper than
    pure noise gets within the sweep (:func:`detection_threshold` at
    :data:`_SITE_FALSE_ALARM`, on the [1, 2, 1]-smoothed samples, as the tracker's).
    The neighbours' part of the tracked signal (channel sum less the own value: other
    sites, independent noise) gives a second centroid, at the centre of the demosaic's
    symmetric taps. The two are combined by inverse variance where the estimated squared
    bias of the neighbours' time, ``(t_n - t_o)**2 - var_o - var_n``, is not positive
    (their difference is noise); otherwise the own time stands alone. Both noises are
    bounded below by `noise_floor` (signal units), as in :func:`classify_dips`.

    Returns
    -------
    time, std : (H, W) float64 ndarray
        NaN where the own dip is not significant (the channel sum's centroid is then used).
    neighbour_share : (H, W) float64 ndarray
        Weight of the neighbours' time in `time` (0 where not joined).
    """
    keep = np.isfinite(summary.window)
    own = np.where(keep, site.window, np.nan)
    own_noise = np.maximum(np.nan_to_num(site.noise, nan=np.inf), noise_floor)
    rest_noise = np.maximum(np.nan_to_num(site.neighbour_noise, nan=np.inf), noise_floor)
    own_time, own_std = _centroid(own, site.level, summary.window_start, own_noise)
    smooth = 0.25 * own[:-2] + 0.5 * own[1:-1] + 0.25 * own[2:]
    with np.errstate(invalid="ignore", divide="ignore"):
        floor = np.nanmin(np.where(np.isfinite(smooth), smooth, np.inf), axis=0)
        contrast = (site.level - floor) / (own_noise * _SMOOTHED_NOISE)
    z = detection_threshold(summary.n_frames, false_alarm=_SITE_FALSE_ALARM)
    significant = (contrast > z) & np.isfinite(own_time) & (own_std > 0)
    rest = np.where(keep, summary.window - site.window, np.nan)
    rest_time, rest_std = _centroid(rest, site.neighbour_level, summary.window_start, rest_noise)
    with np.errstate(invalid="ignore", divide="ignore"):
        joined = significant & np.isfinite(rest_time) & (rest_std > 0) & (
            (rest_time - own_time) ** 2 <= own_std**2 + rest_std**2)
        w_own, w_rest = 1.0 / own_std**2, np.where(joined, 1.0 / rest_std**2, 0.0)
        time = (w_own * own_time + w_rest * np.where(joined, rest_time, 0.0)) / (w_own + w_rest)
        std = 1.0 / np.sqrt(w_own + w_rest)
        share = w_rest / (w_own + w_rest)
    return (np.where(significant, time, np.nan), np.where(significant, std, np.nan),
            np.where(significant, share, 0.0))


def time_edge_fit(summary, *, radius=3, range_sigma=0.5, floor_std=0.15, footprint_variance=None):
    """Dip centroid combined with an edge-aware local plane fit of neighbours' times.

    See :func:`shadowcam.lab.edge_refine.refine_times`: each pixel's centroid
    and its neighbours' plane are weighed by their variances, so a clean
    centroid on a curved surface is kept and a noisy one is replaced by the
    plane. `floor_std` is the prior per-pixel error, in frames, without noise
    (the on/off staircase of a shadow that crosses a pixel within one frame);
    it sets that part's share against the centroid's noise, while the common
    scale of both is measured from the map (:func:`~shadowcam.lab.edge_refine.dispersion`).
    `footprint_variance` (px^2 per axis, a camera fact): a dip is timed at the pixel's
    flux centroid (:func:`shadowcam._shared.flux_centroid.flux_centroid_shift` of the lit
    level), which the refinement takes to the pixel centre; None: at the centre.
    With the summary's `site` (:class:`shadowcam.lab.site_signal.SiteWindow`, demosaiced
    RAW), each pixel is timed from its own mosaic site where that dip is significant, joined by its
    neighbours' part where the two agree (:func:`_site_times`), else from the channel
    sum; the footprint's second moment is then the site's plus the demosaic taps' share
    in the time (:func:`shadowcam.lab.site_signal.blend_variance`).
    """
    time, entry, exit_, std = time_dip_centroid(summary)
    timed = time
    site = summary.site
    if site is not None:
        site_time, site_std, share = _site_times(summary, site)
        own = np.isfinite(site_time)
        timed, std = np.where(own, site_time, time), np.where(own, site_std, std)
        if footprint_variance is not None:
            footprint_variance = footprint_variance + np.where(
                own, share * blend_variance(site.colour, own=False), blend_variance(site.colour))
    shift = clipped = None
    if footprint_variance is not None:
        shift, clipped = flux_centroid_shift(summary.lit_level, footprint_variance=footprint_variance)
    refined, refined_std = refine_times(
        timed, np.hypot(std, floor_std), radius=radius, range_sigma=range_sigma, centroid_shift=shift,
        shift_std=None if clipped is None else np.abs(clipped)
    )
    shift = refined - time
    return refined, entry + shift, exit_ + shift, refined_std


#: shadow-time methods: name -> function(summary) -> (time, entry, exit, time_std)
SHADOW_TIME_METHODS = {
    "argmin_parabolic": time_argmin_parabolic,
    "midpoint_crossing_BouguetPerona1998": time_midpoint_crossing_BouguetPerona1998,
    "dip_centroid": time_dip_centroid,
    "gaussian_fit_Caruana1986": time_gaussian_fit_Caruana1986,
    "argmin_gaussian_smoothed": time_argmin_gaussian_smoothed,
    "edge_fit": time_edge_fit,
}
