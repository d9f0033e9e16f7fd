"""Per-pixel shadow time of a sweep: when the mask's shadow passes each pixel.

The frames of one sweep stream through a :class:`~shadowcam.lab.dip_tracker.DipTracker`
(memory independent of the frame count); each pixel's dip is then classified
(is there a reliable shadow at all?) and timed to a fraction of a frame by one
of the methods of :data:`SHADOW_TIME_METHODS`. The default, ``edge_fit``, adds
the spatial structure of the shadow edge (:mod:`shadowcam.lab.edge_refine`): a
pixel's own samples are nearly on/off when the shadow crosses it within a
frame, so its neighbours' times sharpen it (paper II-A: the shadow camera's
resolution depends on the edge detector, not on the shadow width).

Offers
------
SHADOW_TIME_METHODS : name -> timing function ``f(summary) -> (time, entry, exit, time_std)``.
REASONS : flag code -> meaning, for pixels without a reliable time.
TIMED : the codes of the pixels with a time.
classify_dips : reason code, contrast and confidence per pixel.
shadow_times : timing of one sweep's classified :class:`DipSummary`.
footprint_spread_std : time uncertainty of a footprint that sees two surfaces' shadow times.
support_threshold, support_intervals, DipSupport : a dip's excursion below the lit level (several minima, one dip).
track_sweep : stream frame blocks of one sweep into a summary and per-channel colour.
lit_colour : unshadowed colour per pixel from a summary with channel sums.
sweep_shadow_times : frames of one sweep (streamed) -> shadow times, colour, flags.
summary_shadow_times : the same from a summary (e.g. merged time-chunk partials).
shadow_time_dataset : assemble the per-sweep results into the ``shadow_time`` dataset.
check_timed : fail with the reason counts when a sweep has (almost) no timed pixel.
shadow_time_of_stores : frame stores of the sweeps (or their time-chunk partials) -> the ``shadow_time`` dataset.
"""

import logging
from dataclasses import dataclass, replace
from functools import partial

import numba as nb
import numpy as np
from scipy.special import ndtri

from shadowcam._shared.flux_centroid import flux_centroid_shift
from shadowcam._shared.progress import Progress
from shadowcam._shared.coverage import MIN_COVERAGE, check_coverage
from shadowcam._shared.validation import check_in_interval, check_positive
from shadowcam.lab.dip_tracker import DipTracker, lit_without, track_intervals
from shadowcam.lab.edge_refine import refine_times, shifted
from shadowcam.lab.site_signal import blend_variance, track_site_window

log = logging.getLogger(__name__)

#: flag code -> meaning (0 = a reliable time)
REASONS = {
    0: "ok",
    1: "never_shadowed",
    2: "low_contrast",
    3: "saturated",
    4: "several_minima",
    5: "invalid_input",
    6: "wide_dip",
    7: "dip_at_sweep_end",
    8: "dip_at_sweep_end_timed",
}
(OK, NEVER_SHADOWED, LOW_CONTRAST, SATURATED, SEVERAL_MINIMA, INVALID_INPUT, WIDE_DIP, DIP_AT_SWEEP_END,
 DIP_AT_SWEEP_END_TIMED) = range(9)
#: codes of the pixels with a time: a reliable one, and one from a dip's one edge and its
#: neighbours' shadow width (its uncertainty in ``time_std``)
TIMED = (OK, DIP_AT_SWEEP_END_TIMED)

#: standard deviation of a [1, 2, 1]/4-smoothed sample relative to a raw one
_SMOOTHED_NOISE = float(np.sqrt(0.25**2 * 2 + 0.5**2))
#: probability that a RAW site's own samples of pure noise pass as a dip (``classify_dips``'
#: default `false_alarm`): below it a pixel is timed from the channel sum
_SITE_FALSE_ALARM = 1e-2


def _window_times(summary):
    """Frame index of each window slot, ``(K, H, W)`` float64."""
    k = summary.window.shape[0]
    return summary.window_start[None] + np.arange(k)[:, None, None]


def _coverage(summary):
    """Fraction of light removed in each window frame, ``(K, H, W)``; NaN outside."""
    return _removed_fraction(summary.window, summary.lit_level)


def _removed_fraction(window, lit_level):
    """``1 - window / lit_level`` clipped to [0, 1], ``(K, H, W)``; NaN where `window` is."""
    with np.errstate(invalid="ignore", divide="ignore"):
        level = lit_level[None]
        return np.clip(1.0 - window / level, 0.0, 1.0)


@nb.njit(cache=True, parallel=True, error_model="numpy")
def _centroid_kernel(coverage, window_start, noise, lit_level):
    """:func:`_centroid` per pixel (one pass over the window, both cores)."""
    n_k, rows, cols = coverage.shape
    centre = np.empty((rows, cols))
    std = np.empty((rows, cols))
    for r in nb.prange(rows):
        for c in range(cols):
            total = 0.0
            moment = 0.0
            for k in range(n_k):
                v = coverage[k, r, c]
                if np.isfinite(v):
                    total += v
                    moment += v * np.float64(window_start[r, c] + k)
            mean = moment / total
            spread = 0.0
            for k in range(n_k):
                if np.isfinite(coverage[k, r, c]):
                    spread += (np.float64(window_start[r, c] + k) - mean) ** 2
            centre[r, c] = mean
            std[r, c] = noise[r, c] / lit_level[r, c] * np.sqrt(spread) / total
    return centre, std


def _centroid(summary, coverage):
    """Coverage-weighted mean time and its noise standard deviation, ``(H, W)`` each.

    Each coverage sample carries noise ``sigma / level``, propagated to the
    mean; non-finite samples take no part.
    """
    return _centroid_kernel(coverage, summary.window_start, summary.noise, summary.lit_level)


def _crossings(summary, threshold):
    """Entry and exit times where the signal crosses `threshold` (linear interpolation).

    The crossings nearest to the minimum on each side are used; NaN where the
    dip does not come back above `threshold` inside the window.
    """
    win = summary.window
    k = win.shape[0]
    h = summary.half_window
    above = win >= threshold[None]
    idx = np.arange(k)[:, None, None]
    # entry: last slot before the centre that is above the threshold
    left = np.where(above & (idx < h), idx, -1).max(axis=0)
    # exit: first slot after the centre that is above the threshold
    right = np.where(above & (idx > h), idx, k).min(axis=0)
    rows, cols = np.indices(threshold.shape)

    def interpolate(a, b):
        ok = (a >= 0) & (a < k) & (b >= 0) & (b < k)
        a_c, b_c = np.clip(a, 0, k - 1), np.clip(b, 0, k - 1)
        va, vb = win[a_c, rows, cols], win[b_c, rows, cols]
        with np.errstate(invalid="ignore", divide="ignore"):
            frac = (va - threshold) / (va - vb)
            crossing = summary.window_start + a_c + frac * (b_c - a_c)
        return np.where(ok & np.isfinite(frac), crossing, np.nan)

    entry = interpolate(left, left + 1)
    exit_ = interpolate(right, right - 1)
    centre_below = win[h] < threshold
    entry = np.where(centre_below, entry, np.nan)
    exit_ = np.where(centre_below, exit_, np.nan)
    return entry, exit_


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
    coverage = _coverage(summary)
    time, std = _centroid(summary, coverage)
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
    own_time, own_std = _centroid_kernel(_removed_fraction(own, site.level), summary.window_start,
                                         own_noise, site.level)
    smooth = 0.25 * own[:-2] + 0.5 * own[1:-1] + 0.25 * own[2:]
    with np.errstate(invalid="ignore", divide="ignore"):
        floor = np.nanmin(np.where(np.isfinite(smooth), smooth, np.inf), axis=0)
        contrast = (site.level - floor) / (own_noise * _SMOOTHED_NOISE)
    z = detection_threshold(summary.n_frames, false_alarm=_SITE_FALSE_ALARM)
    significant = (contrast > z) & np.isfinite(own_time) & (own_std > 0)
    rest = np.where(keep, summary.window - site.window, np.nan)
    rest_time, rest_std = _centroid_kernel(_removed_fraction(rest, site.neighbour_level), summary.window_start,
                                           rest_noise, site.neighbour_level)
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


def detection_threshold(n_frames, *, false_alarm=1e-3):
    """Dip depth, in units of the smoothed-sample noise, that pure noise rarely reaches.

    The deepest of `n_frames` smoothed noise samples exceeds ``z`` standard
    deviations with probability about ``n_frames * Q(z)``; ``z`` is chosen so
    that this is `false_alarm`.
    """
    check_in_interval(false_alarm, "false_alarm", 0, 1, closed="neither")
    return float(-ndtri(false_alarm / max(int(n_frames), 1)))


def _shifts(radius):
    """Neighbour offsets ``(dr, dc)`` within `radius`, excluding ``(0, 0)``."""
    return [(dr, dc) for dr in range(-radius, radius + 1) for dc in range(-radius, radius + 1)
            if (dr, dc) != (0, 0)]


def _supported_by_neighbours(candidate, strong, minimum_frame, *, radius=2, frames_per_pixel=1.5,
                             min_support=3):
    """Weak dips whose timing agrees with enough strong neighbours.

    A real but faint shadow dip occurs when the neighbours' dips occur (the
    edge sweeps across them); a dip of pure noise falls at a random frame. A
    candidate is supported when at least `min_support` strong neighbours, and
    at least half of the strong neighbours, have their minimum within
    ``1 + frames_per_pixel * distance`` frames of the candidate's.
    """
    agree = np.zeros(candidate.shape, np.int32)
    total = np.zeros(candidate.shape, np.int32)
    frame = minimum_frame.astype(np.float64)
    for dr, dc in _shifts(radius):
        n_strong = shifted(strong, dr, dc, False)
        n_frame = shifted(frame, dr, dc, np.nan)
        tolerance = 1.0 + frames_per_pixel * np.hypot(dr, dc)
        total += n_strong
        agree += n_strong & (np.abs(n_frame - frame) <= tolerance)
    return candidate & (agree >= min_support) & (2 * agree >= total)


def _partially_lit(detected, level, *, site_colour=None, site_image=None, resolution=0.0,
                   min_lit_fraction=0.5, shadow_ratio=0.1):
    """Detected pixels at a shadow boundary whose lit part is under `min_lit_fraction`.

    A pixel straddling the boundary of a cast (scene) shadow dips when the
    mask passes, although its centre is in shadow. A boundary that crosses the
    pixel's footprint leaves one of the eight pixels touching it on the shadow
    side: an undetected one, or one darker than `shadow_ratio` times the
    pixel's own level in that neighbour's colour (a cast shadow keeps only
    ambient light, an order of magnitude below direct light, while
    neighbouring albedos of a texture rarely differ that much), within
    `resolution`, the noise of the levels (a pixel too dim to tell a shadowed
    neighbour from a lit one counts it as shadow side). The lit fraction of a
    pixel beside the shadow side is its level over the brightest detected
    neighbour of the same colour (within 1 pixel, or 2 on a CFA's colour
    lattice); its centre is in shadow when that is under `min_lit_fraction`
    (1/2 for a straight boundary).

    Parameters
    ----------
    detected : (H, W) bool ndarray
        Pixels with a detected dip.
    level : (H, W) ndarray
        Lit level; for demosaiced RAW each site's own measured channel.
    site_colour : (H, W) int ndarray, optional
        CFA colour index of each site (demosaiced RAW).
    site_image : (H, W, C) ndarray, optional
        With `site_colour`: the lit colour of each pixel (its level in every channel).
        Interpolated channels carry light from lit neighbours into shadowed sites, so
        those are detected too and only the darkness test finds them.
    resolution : float or (H, W) ndarray, optional
        Noise of the pixel's lit level (signal units).
    min_lit_fraction, shadow_ratio : float, optional
        As :func:`classify_dips`.

    Returns
    -------
    (H, W) bool ndarray
    """
    if site_colour is None:
        colour = np.zeros(level.shape, np.intp)
        site_image = np.asarray(level)[..., None]
    else:
        colour = np.asarray(site_colour).astype(np.intp)
    lit_level = np.where(detected, level, 0.0)
    brightest = np.zeros_like(lit_level)
    shadow_side = np.zeros(detected.shape, bool)
    for dr, dc in _shifts(1 if site_colour is None else 2):
        same = shifted(colour, dr, dc, -1) == colour
        brightest = np.maximum(brightest, np.where(same, shifted(lit_level, dr, dc, 0.0), 0.0))
        if max(abs(dr), abs(dc)) > 1:
            continue
        own = np.take_along_axis(site_image, shifted(colour, dr, dc, 0)[..., None], axis=2)[..., 0]
        darker = shifted(level, dr, dc, np.inf) < shadow_ratio * own + resolution
        shadow_side |= darker | ~shifted(detected, dr, dc, True)
    with np.errstate(invalid="ignore", divide="ignore"):
        fraction = level / brightest
    return detected & shadow_side & (fraction < min_lit_fraction)


def _wider_than_window(summary, depth, significant):
    """The window's first or last sample (when inside the sweep) is still shadowed by more
    than 3/4 of the dip's depth (and by more than `significant`, capped at 0.9 `depth`):
    the dip goes on beyond the window (thick wire, area source) and its time would be
    biased toward the window."""
    need = np.maximum(0.75 * depth, np.minimum(significant, 0.9 * depth))
    with np.errstate(invalid="ignore"):
        return ((summary.lit_level - summary.window[0] > need)
                | (summary.lit_level - summary.window[-1] > need))


def classify_dips(summary, *, saturated=None, site_level=None, site_colour=None,
                  false_alarm=1e-2, weak_false_alarm=0.5,
                  min_relative_depth=0.1, min_lit_fraction=0.5, shadow_ratio=0.1,
                  noise_floor=1e-4, second_dip_ratio=0.5, interval=None):
    """Decide per pixel whether its dip is a reliable shadow, and why not.

    A dip is detected when it is deeper than pure noise gets within the
    sweep (threshold from the measured per-pixel noise and `false_alarm`),
    or when it passes the looser `weak_false_alarm` threshold and its timing
    agrees with detected neighbours. Detected pixels at a cast-shadow
    boundary whose lit fraction is below `min_lit_fraction` (centre in
    shadow) are then rejected.

    Parameters
    ----------
    summary : DipSummary
        One sweep.
    saturated : (H, W) bool ndarray, optional
        Pixels that reached the white level in any channel. Their dip is timed
        from the samples below the clip (censoring keeps a symmetric dip's
        centre); one that shows no dip is ``saturated`` rather than
        ``never_shadowed``.
    site_level, site_colour : (H, W) ndarray, optional
        For demosaiced RAW: each pixel's lit level in its own CFA channel and
        that channel's index, used by the cast-shadow boundary test.
    false_alarm : float, optional
        Wanted probability that a pixel of pure noise is given a time on its own.
    weak_false_alarm : float, optional
        The same for a dip that neighbours must confirm.
    min_relative_depth : float, optional
        Smallest dip depth, as a fraction of the lit level, taken as a shadow.
    min_lit_fraction : float, optional
        Smallest lit fraction of a boundary pixel's footprint.
    shadow_ratio : float, optional
        A neighbour touching the pixel and darker than this fraction of the
        pixel's level in the neighbour's colour (plus the lit level's noise) is
        taken as the shadowed side of a cast-shadow boundary.
    noise_floor : float, optional
        Lower bound of the noise (signal units), for noise-free data.
    second_dip_ratio : float, optional
        A second dip (another local minimum more than half a window away) at
        least this deep (relative to the first) marks the pixel ``several_minima``.
    interval : DipInterval, optional
        The dip's measured interval (:func:`shadowcam.lab.dip_tracker.track_intervals`):
        a second minimum inside it is part of the same dip (the floor of a
        wide dip), not a second one.

    Returns
    -------
    reason : (H, W) uint8 ndarray
        Codes of :data:`REASONS`.
    contrast : (H, W) float32 ndarray
        Dip depth over its noise standard deviation.
    """
    z = detection_threshold(summary.n_frames, false_alarm=false_alarm)
    z_weak = detection_threshold(summary.n_frames, false_alarm=weak_false_alarm)
    noise = np.maximum(np.nan_to_num(summary.noise, nan=np.inf), noise_floor)
    level = summary.lit_level
    depth = level - summary.minimum_value
    with np.errstate(invalid="ignore", divide="ignore"):
        contrast = depth / (noise * _SMOOTHED_NOISE)
        second_depth = level - summary.second_value
    deep_enough = depth > min_relative_depth * level
    strong = (contrast > z) & deep_enough
    weak = (contrast > z_weak) & deep_enough & ~strong
    detected = strong | _supported_by_neighbours(weak, strong, summary.minimum_frame)
    # the lit level's noise at the detection threshold
    level_noise = z * noise / np.sqrt(np.maximum(summary.lit_count, 1))
    significant_level = level > level_noise

    reason = np.zeros(level.shape, np.uint8)
    reason[~detected] = NEVER_SHADOWED
    reason[~significant_level] = LOW_CONTRAST
    boundary_level = level if site_level is None else site_level
    partial = _partially_lit(detected, boundary_level, site_colour=site_colour,
                             site_image=None if site_colour is None else lit_colour(summary),
                             resolution=level_noise, min_lit_fraction=min_lit_fraction,
                             shadow_ratio=shadow_ratio)
    reason[partial] = LOW_CONTRAST
    several = detected & (second_depth >= second_dip_ratio * depth) & (
        second_depth / (noise * _SMOOTHED_NOISE) > z
    )
    if interval is not None:
        with np.errstate(invalid="ignore"):
            first = np.where(interval.entry_open, -np.inf, np.floor(interval.entry))
            last = np.where(interval.exit_open, np.inf, np.ceil(interval.exit))
            several &= ~((summary.second_frame >= first) & (summary.second_frame <= last))
    reason[(reason == OK) & several] = SEVERAL_MINIMA
    reason[(reason == OK) & _wider_than_window(summary, depth, z * noise)] = WIDE_DIP
    if saturated is not None:
        # a clipped channel censors the samples above the white level; the part of the dip
        # below it is a monotone image of the symmetric dip, so a detected dip keeps its
        # centre (its smaller depth widens the time's noise). A pixel that shows no dip at all
        # may have it above the clip
        reason[(reason == NEVER_SHADOWED) & saturated & ~deep_enough] = SATURATED
    # a non-finite sample in the window at a frame inside the sweep (slots outside the
    # sweep are NaN padding)
    frame = _window_times(summary)
    in_sweep = (frame >= 0) & (frame < summary.n_frames)
    window_invalid = (in_sweep & ~np.isfinite(summary.window)).any(axis=0)
    broken = (summary.invalid_count > 0) & window_invalid
    broken |= summary.lit_count < 3
    broken |= summary.minimum_frame < 0
    reason[broken] = INVALID_INPUT
    return reason, np.nan_to_num(contrast, nan=0.0, posinf=0.0).astype(np.float32)


def shadow_times(summary, reason, contrast, *, method="edge_fit", method_params=None, interval=None,
                 support=None):
    """Time the dips of one classified sweep.

    Parameters
    ----------
    summary : DipSummary
    reason, contrast : (H, W) ndarray
        The sweep's :func:`classify_dips` (with the same `interval`).
    method : str, optional
        Key of :data:`SHADOW_TIME_METHODS`.
    method_params : dict, optional
        Keyword options of the timing method.
    interval : DipInterval, optional
        The measured dip intervals (:func:`shadowcam.lab.dip_tracker.track_intervals`):
        a dip wider than the window is then timed at its interval's centre
        (``dip_at_sweep_end`` when the interval reaches the sweep's start or
        end, ``invalid_input`` with a non-finite sample inside), the
        ``interval_*`` variables are returned, and ``time_std`` adds the
        footprint's excess span (:func:`footprint_spread_std`).
    support : DipSupport, optional
        The dips' excursions below the lit level (:func:`support_intervals` of `reason`):
        a ``several_minima`` or ``wide_dip`` pixel whose minima lie in one excursion
        below the lit level is one dip, timed at its removed light's centroid
        (:func:`_time_connected_dips`). Needs `interval`.

    Returns
    -------
    dict of (H, W) ndarrays
        ``shadow_time``, ``entry_time``, ``exit_time`` (frames, NaN where
        unreliable), ``time_std`` (frames), ``confidence`` (0..1),
        ``contrast``, ``reason`` (uint8), ``lit_level``, ``noise``; with
        `interval` also ``interval_entry``, ``interval_exit`` (half-depth
        crossings, frames) and ``interval_entry_std``, ``interval_exit_std``.
    """
    if method not in SHADOW_TIME_METHODS:
        raise ValueError(
            f"method must be one of {sorted(SHADOW_TIME_METHODS)}, got {method!r}"
        )
    if support is not None and interval is None:
        raise ValueError("support needs the interval it was measured with")
    masked = _masked_summary(summary, reason == OK)
    time, entry, exit_, std = SHADOW_TIME_METHODS[method](masked, **(method_params or {}))
    if interval is not None:
        reason, time, entry, exit_, std, extra = _time_wide_dips(summary, interval, reason, time, entry, exit_, std)
        std = np.hypot(std, footprint_spread_std(interval, reason == OK))
        if support is not None:
            reason, time, entry, exit_, std, extra = _time_connected_dips(
                summary, support, reason, time, entry, exit_, std, extra)
    last = summary.n_frames - 1
    outside = ~((time >= 0) & (time <= last))
    reason = reason.copy()
    reason[(reason == OK) & outside] = NEVER_SHADOWED
    good = np.isin(reason, TIMED)
    std = np.where(good, std, np.nan)
    confidence = np.where(good, np.exp(-0.5 * (std / 0.25) ** 2), 0.0)
    nan = np.float32(np.nan)
    return {
        "shadow_time": np.where(good, time, nan).astype(np.float32),
        "entry_time": np.where(good, np.clip(entry, 0, last), nan).astype(np.float32),
        "exit_time": np.where(good, np.clip(exit_, 0, last), nan).astype(np.float32),
        "time_std": std.astype(np.float32),
        "confidence": np.nan_to_num(confidence, nan=0.0).astype(np.float32),
        "contrast": contrast,
        "reason": reason,
        "lit_level": summary.lit_level.astype(np.float32),
        "noise": summary.noise.astype(np.float32),
        **({} if interval is None else {
            key: np.where(good, value, nan).astype(np.float32) for key, value in extra.items()}),
    }


def footprint_spread_std(interval, timed):
    """Time uncertainty of a pixel whose footprint sees more shadow times than one surface's.

    A pixel's half-depth dip spans the times its footprint's points are shadowed; on one
    surface a neighbour's footprint spans as long. A footprint that sees two surfaces (a
    silhouette) or a surface and a cast shadow spans more, and its centroid is that of
    whichever part is lit, while the pixel's centre sees one of the surfaces: its time is at
    one end of the excess span, half of it from the centroid (standard deviation
    ``excess / 2``).

    Parameters
    ----------
    interval : DipInterval
        Measured half-depth ``entry`` and ``exit`` per pixel, ``(H, W)`` each.
    timed : (H, W) bool ndarray
        Pixels with a time; the reference span is the median of the timed 8-neighbours'.

    Returns
    -------
    (H, W) float64 ndarray
        Frames; 0 where the dip spans no more than the reference (or none is known).
    """
    with np.errstate(invalid="ignore"):
        width = np.where(timed, interval.exit - interval.entry, np.nan)
    neighbours = np.stack([shifted(width, dr, dc, np.nan) for dr, dc in _shifts(1)])
    known = np.isfinite(neighbours).any(axis=0)
    reference = np.full(width.shape, np.nan)
    reference[known] = np.nanmedian(neighbours[:, known], axis=0)
    with np.errstate(invalid="ignore"):
        excess = np.maximum(width - reference, 0.0)
    return 0.5 * np.nan_to_num(excess, nan=0.0, posinf=0.0)


def _time_wide_dips(summary, interval, reason, time, entry, exit_, std):
    """Time the ``wide_dip`` and ``ok`` pixels whose half-depth interval reaches the window's
    edge at the centre of their measured interval.

    Returns the updated ``reason, time, entry, exit, std`` and the
    ``interval_*`` variables (noise over the crossing's slope for the
    standard deviations).
    """
    sigma = summary.noise * _SMOOTHED_NOISE
    with np.errstate(invalid="ignore", divide="ignore"):
        entry_std = sigma / interval.entry_slope
        exit_std = sigma / interval.exit_slope
    interval_entry, interval_exit = interval.entry, interval.exit
    # the half-depth interval reaches the window's first or last frame: the window truncates
    # the dip (window methods are biased toward its centre), the interval does not. A dip
    # flagged wide whose interval fits the window is dark at the window's edge for another
    # reason (a step, a second shadow): it stays wide_dip
    h = summary.half_window
    opened = interval.entry_open | interval.exit_open
    with np.errstate(invalid="ignore"):
        beyond = (interval.entry < summary.minimum_frame - h + 1) | (interval.exit > summary.minimum_frame + h - 1)
    # a flagged wide dip open at the sweep's start or end has no time; a dip the window
    # timed keeps its time there (its centre is inside the sweep)
    wide = ((reason == WIDE_DIP) & (beyond | opened)) | ((reason == OK) & beyond)
    at_end = wide & opened
    broken = wide & ~at_end & ((interval.invalid > 0) | ~np.isfinite(interval.entry) | ~np.isfinite(interval.exit))
    timed = wide & ~at_end & ~broken
    centre = interval.at(0.5)
    # a dip the window flagged wide is a shadow only where the shadow's edge sweeps on: its
    # centre agrees with timed neighbours' (a dip of some other event falls at its own time)
    flagged = timed & (reason == WIDE_DIP)
    others = (reason == OK) | timed
    timed &= ~flagged | _supported_by_neighbours(flagged, others, np.where(timed, centre, time))
    reason = reason.copy()
    reason[at_end] = DIP_AT_SWEEP_END
    reason[broken] = INVALID_INPUT  # a non-finite sample inside, or next to a crossing
    reason[timed] = OK
    time = np.where(timed, centre, time)
    entry = np.where(timed, interval_entry, entry)
    exit_ = np.where(timed, interval_exit, exit_)
    std = np.where(timed, 0.5 * np.hypot(entry_std, exit_std), std)
    # a dip cut by the sweep's start or end, timed from its one crossing and the shadow's
    # half-depth width: the wire's width over its step (the same for every point a planar
    # sweep shadows), measured as the uncut neighbours' mean width, their spread the width's
    # uncertainty
    uncut = (reason == OK) & ~opened & np.isfinite(interval_entry) & np.isfinite(interval_exit)
    width, width_std = _local_width(interval_exit - interval_entry, uncut)
    with np.errstate(invalid="ignore"):
        cut_centre = np.where(interval.exit_open, interval_entry + 0.5 * width, interval_exit - 0.5 * width)
        cut = (at_end & (interval.entry_open != interval.exit_open) & (interval.invalid == 0)
               & np.isfinite(cut_centre) & (cut_centre >= 0) & (cut_centre <= summary.n_frames - 1))
    edge_std = np.where(interval.exit_open, entry_std, exit_std)
    reason[cut] = DIP_AT_SWEEP_END_TIMED
    time = np.where(cut, cut_centre, time)
    interval_entry = np.where(cut & interval.entry_open, interval_exit - width, interval_entry)
    interval_exit = np.where(cut & interval.exit_open, interval_entry + width, interval_exit)
    entry_std = np.where(cut & interval.entry_open, np.hypot(edge_std, width_std), entry_std)
    exit_std = np.where(cut & interval.exit_open, np.hypot(edge_std, width_std), exit_std)
    entry = np.where(cut, interval_entry, entry)
    exit_ = np.where(cut, interval_exit, exit_)
    std = np.where(cut, np.hypot(edge_std, 0.5 * width_std), std)
    extra = {"interval_entry": interval_entry, "interval_exit": interval_exit,
             "interval_entry_std": entry_std, "interval_exit_std": exit_std}
    return reason, time, entry, exit_, std, extra


def support_threshold(summary, *, false_alarm=1e-2, noise_floor=1e-4):
    """Level below which a pixel's light is still removed: its lit level less what noise reaches.

    A shadow removes light from the moment any part of the light is hidden until the
    light is whole again; the smoothed signal is back at the lit level, within noise,
    only outside that excursion. The threshold is the lit level less the depth pure
    noise reaches within the sweep (:func:`detection_threshold` of `false_alarm`, as
    :func:`classify_dips`), and never below half the dip's depth.

    Parameters
    ----------
    summary : DipSummary
    false_alarm : float, optional
    noise_floor : float, optional
        Lower bound of the noise (signal units), for noise-free data.

    Returns
    -------
    (H, W) float64 ndarray
    """
    check_in_interval(false_alarm, "false_alarm", 0.0, 1.0)
    check_positive(noise_floor, "noise_floor")
    z = detection_threshold(summary.n_frames, false_alarm=false_alarm)
    noise = np.maximum(np.nan_to_num(summary.noise, nan=np.inf), noise_floor) * _SMOOTHED_NOISE
    level = np.asarray(summary.lit_level, np.float64)
    depth = level - summary.minimum_value
    return level - np.minimum(z * noise, 0.5 * depth)


def support_intervals(read, summary, interval, reason, *, false_alarm=1e-2):
    """The crossings of :func:`support_threshold` of the pixels whose dip shows several minima.

    Only the ``several_minima`` and ``wide_dip`` pixels of `reason` are measured. Their lit noise counts the parts of the dip outside the
    half-depth interval as lit (a second lobe of a sampled light inflates it to a
    fraction of the depth), so the support is found in two passes: first at the
    lit level itself (the signal's first return to it, a frame or so outside the
    dip for noisy data), then, with the lit level and noise of the samples
    outside that first support (:func:`shadowcam.lab.dip_tracker.lit_without`),
    at :func:`support_threshold`.

    Parameters
    ----------
    read : callable
        ``read()`` -> an iterable of the sweep's ``(T, H, W[, C])`` frame blocks in time
        order (read lazily: only when some pixel's window does not resolve it).
    summary : DipSummary
    interval : DipInterval
        The half-depth intervals (whose ``beyond_*`` samples `summary` no longer counts as lit).
    reason : (H, W) uint8 ndarray
        The sweep's :func:`classify_dips` with `interval`.
    false_alarm : float, optional
        Of :func:`support_threshold`.

    Returns
    -------
    DipSupport
    """
    candidate = np.isin(reason, (SEVERAL_MINIMA, WIDE_DIP))
    first = track_intervals(read(), summary, threshold=np.where(candidate, summary.lit_level, np.nan))
    level, noise, _, _ = lit_without(summary, np.maximum(first.beyond_count - interval.beyond_count, 0),
                                     first.beyond_sum - interval.beyond_sum,
                                     first.beyond_square - interval.beyond_square)
    outside = replace(summary, lit_level=level, noise=noise)
    threshold = np.where(candidate, support_threshold(outside, false_alarm=false_alarm), np.nan)
    support = track_intervals(read(), summary, threshold=threshold)
    with np.errstate(invalid="ignore"):
        closed = (candidate & ~support.entry_open & ~support.exit_open & (support.invalid == 0)
                  & np.isfinite(support.entry) & np.isfinite(support.exit))
    return DipSupport(support, *_removed_light_centroid(read(), closed, support, level, noise))


@dataclass
class DipSupport:
    """The dips' excursions below the lit level (:func:`support_intervals`).

    Attributes
    ----------
    interval : DipInterval
        Crossings of :func:`support_threshold` (threshold NaN where not measured).
    centroid, centroid_std : (H, W) float64 ndarray
        Centroid of the removed light over the frames inside the interval, and its
        standard deviation from the noise (frames; NaN where not measured).
    width, width_std : (H, W) float64 ndarray
        The removed light over the lit level, summed over those frames (frames), and its
        standard deviation: an opaque wire narrower than the light hides each of the
        light's chords for the time its width takes to pass, so this is the wire's
        width in frames, whatever the light's shape.
    """

    interval: object
    centroid: np.ndarray
    centroid_std: np.ndarray
    width: np.ndarray
    width_std: np.ndarray


def _removed_light_centroid(blocks, pixels, support, level, noise):
    """Centroid of ``level - signal`` over the frames strictly inside `support` of the `pixels`.

    Streams `blocks` (``(T, H, W[, C])``, channels summed, from frame 0) once,
    keeping two sums per selected pixel; nothing is read when none is selected.
    Returns the centroid, its standard deviation (`noise` per sample), the
    removed light over `level` (frames) and its standard deviation, ``(H, W)``
    each, NaN elsewhere.
    """
    out = [np.full(pixels.shape, np.nan) for _ in range(4)]
    if not pixels.any():
        return tuple(out)
    rows, cols = np.nonzero(pixels)
    first, last = support.entry[rows, cols], support.exit[rows, cols]
    lit = level[rows, cols]
    removed = np.zeros(len(rows))
    moment = np.zeros(len(rows))
    count, total, square = (np.zeros(len(rows)) for _ in range(3))
    start = 0
    for block in blocks:
        block = np.asarray(block, np.float64)
        samples = block[:, rows, cols] if block.ndim == 3 else block[:, rows, cols].sum(axis=-1)
        frame = np.arange(start, start + len(block), dtype=np.float64)[:, None]
        inside = (frame > first) & (frame < last) & np.isfinite(samples)
        weight = np.where(inside, lit - samples, 0.0)
        removed += weight.sum(axis=0)
        moment += (weight * frame).sum(axis=0)
        count += inside.sum(axis=0)
        total += (inside * frame).sum(axis=0)
        square += (inside * frame**2).sum(axis=0)
        start += len(block)
    with np.errstate(invalid="ignore", divide="ignore"):
        centre = moment / removed
        # each frame's noise moves the centroid by (t - centre) / removed
        spread = square - 2 * centre * total + count * centre**2
        sigma = noise[rows, cols]
        out[0][rows, cols] = np.where(removed > 0, centre, np.nan)
        out[1][rows, cols] = sigma * np.sqrt(np.maximum(spread, 0.0)) / removed
        out[2][rows, cols] = removed / lit
        out[3][rows, cols] = sigma * np.sqrt(count) / lit
    return tuple(out)


def _time_connected_dips(summary, support, reason, time, entry, exit_, std, extra):
    """Time the dips whose several minima lie in one excursion below the lit level.

    A wire narrower than an area light's projection casts no umbra: its dip is the
    light's profile swept by the wire, shallow and as wide as the light's
    projection, and a sampled or noisy profile shows several minima in it. They
    are one dip when the signal between them never returns to the lit level: a
    ``several_minima`` pixel whose second minimum lies inside the support
    (:func:`support_threshold` crossings), or a ``wide_dip`` pixel whose support
    closes inside the sweep. The dip is the light's profile swept by the wire: the
    centroid of the removed light is the time the wire passes the light's centre
    (:class:`DipSupport`'s ``centroid``, its ``centroid_std`` the time's). Kept where the
    time agrees with timed neighbours' (as a flagged wide dip in
    :func:`_time_wide_dips`). ``entry`` / ``exit`` and the ``interval_*``
    variables are the wire's edges passing the light's centre: the centroid less
    and plus half the wire's width (:class:`DipSupport`'s ``width``).

    Returns the updated ``reason, time, entry, exit, std, extra``.
    """
    bounds, centroid = support.interval, support.centroid
    edge_std = np.hypot(support.centroid_std, 0.5 * support.width_std)
    with np.errstate(invalid="ignore", divide="ignore"):
        # centroid is finite only where the support closes inside the sweep with finite samples
        inside = (summary.second_frame >= np.floor(bounds.entry)) & (summary.second_frame <= np.ceil(bounds.exit))
        candidate = (np.isfinite(centroid) & (centroid >= 0) & (centroid <= summary.n_frames - 1)
                     & (((reason == SEVERAL_MINIMA) & inside) | (reason == WIDE_DIP)))
    # the light's extent shapes every neighbour's dip alike: a connected dip agrees with
    # neighbouring connected dips (a pixel whose footprint runs two surfaces' shadows
    # together stands alone among single dips)
    connected = candidate & _supported_by_neighbours(candidate, candidate, centroid)
    reason = reason.copy()
    reason[connected] = OK
    time = np.where(connected, centroid, time)
    first, last = centroid - 0.5 * support.width, centroid + 0.5 * support.width
    entry = np.where(connected, first, entry)
    exit_ = np.where(connected, last, exit_)
    std = np.where(connected, support.centroid_std, std)
    extra = dict(extra)
    for name, value in (("interval_entry", first), ("interval_exit", last),
                        ("interval_entry_std", edge_std), ("interval_exit_std", edge_std)):
        extra[name] = np.where(connected, value, extra[name])
    return reason, time, entry, exit_, std, extra


def _local_width(width, known, *, min_count=8):
    """Mean and standard deviation of `width` over the nearest `known` pixels, ``(H, W)`` each.

    Over the smallest square of side ``2 r + 1`` (``r`` = 1, 2, 4, ...) holding at
    least `min_count` known pixels; NaN where the whole image holds fewer.
    """
    from scipy import ndimage

    values = np.where(known, width, 0.0)
    mean, spread = np.full(width.shape, np.nan), np.full(width.shape, np.nan)
    left = np.ones(width.shape, bool)
    radius = 1
    while left.any():
        size = 2 * radius + 1
        count = np.rint(ndimage.uniform_filter(known.astype(np.float64), size, mode="constant") * size**2)
        total = ndimage.uniform_filter(values, size, mode="constant") * size**2
        square = ndimage.uniform_filter(values**2, size, mode="constant") * size**2
        here = left & (count >= min_count)
        with np.errstate(invalid="ignore", divide="ignore"):
            m = total / count
            v = np.maximum(square / count - m**2, 0.0) * count / np.maximum(count - 1, 1)
        mean[here], spread[here] = m[here], np.sqrt(v[here])
        left &= ~here
        if size >= 2 * max(width.shape):
            break
        radius *= 2
    return mean, spread


def _masked_summary(summary, keep):
    """Copy of `summary` whose window is NaN outside `keep` (so methods ignore them)."""
    return replace(summary, window=np.where(keep[None], summary.window, np.nan))


def track_sweep(blocks, shape, *, half_window=4, saturation_level=0.999, progress=None):
    """Stream one sweep's frames through a :class:`DipTracker`.

    Parameters
    ----------
    blocks : iterable of (T, H, W, C) float ndarray
        Frames in time order (any block sizes).
    shape : tuple of int
        ``(H, W)``.
    half_window : int, optional
    saturation_level : float, optional
        Linear value (white = 1) at or above which a channel is saturated.
    progress : callable, optional
        Called with the number of frames done after each block.

    Returns
    -------
    summary : DipSummary
        Of the channel-summed signal.
    lit_image : (H, W, C) float32 ndarray
        Unshadowed colour per pixel (see :func:`lit_colour`).
    saturated : (H, W) bool ndarray
    """
    tracker = DipTracker(shape, half_window=half_window, saturation_level=saturation_level)
    for block in blocks:
        block = np.asarray(block, np.float32)
        if block.ndim != 4 or block.shape[1:3] != tuple(shape):
            raise ValueError(f"blocks must be (T, {shape[0]}, {shape[1]}, C), got {block.shape}")
        tracker.update(block)
        if progress is not None:
            progress(tracker.n_frames)
    if tracker.n_frames == 0:
        raise ValueError("blocks is empty: the sweep has no frames")
    summary = tracker.result()
    return summary, lit_colour(summary), summary.saturated


def lit_colour(summary):
    """Unshadowed colour per pixel, ``(H, W, C)`` float32.

    The channel means scaled by the ratio of the lit level to the mean level
    (the mask removes light from all channels alike).
    """
    if summary.channel_sum is None:
        raise ValueError("summary has no channel sums: feed the tracker (T, H, W, C) blocks")
    with np.errstate(invalid="ignore", divide="ignore"):
        # a pixel with no light at all (mean 0) has no colour, not an infinite one
        scale = np.where(summary.mean_level > 0, summary.lit_level / summary.mean_level, 0.0)
        lit_image = summary.channel_sum / summary.n_frames * scale[..., None]
    return np.nan_to_num(lit_image, nan=0.0).astype(np.float32)


def cfa_site_colours(shape, pattern):
    """Channel index (0 R, 1 G, 2 B) measured at each pixel of a Bayer mosaic.

    Parameters
    ----------
    shape : tuple of int
        ``(H, W)``.
    pattern : str
        CFA letters of the top-left 2x2 block in reading order, e.g. ``"RGGB"``.

    Returns
    -------
    (H, W) int8 ndarray
    """
    if len(pattern) != 4 or set(pattern) - set("RGB"):
        raise ValueError(f"pattern must be four letters of R, G, B such as 'RGGB'; got {pattern!r}")
    tile = np.array(["RGB".index(ch) for ch in pattern], np.int8).reshape(2, 2)
    rows = np.arange(shape[0])[:, None] % 2
    cols = np.arange(shape[1])[None, :] % 2
    return tile[rows, cols]


def sweep_shadow_times(blocks, shape, *, method="edge_fit", half_window=4, cfa_pattern=None,
                       own_site=False, method_params=None, classify_params=None, progress=None):
    """Shadow times of one sweep from its frames, streamed.

    Parameters
    ----------
    blocks : iterable of (T, H, W, C) float ndarray
        Linear frames in time order; read once, or twice with `own_site`.
    shape : tuple of int
        ``(H, W)``.
    method : str, optional
        Key of :data:`SHADOW_TIME_METHODS`.
    half_window : int, optional
        Frames kept each side of the dip (see :class:`DipTracker`).
    cfa_pattern : str, optional
        Bayer pattern when the frames were demosaiced from RAW (e.g. ``"RGGB"``);
        the shadow-boundary test then uses each site's measured channel.
    own_site : bool, optional
        Time each pixel from its own mosaic site where its noise allows (as
        :func:`summary_shadow_times`): needs `cfa_pattern`, ``edge_fit`` and `blocks`
        that can be read again (a collection such as a list, not a one-shot iterator).
    method_params, classify_params : dict, optional
        Options of the timing method and of :func:`classify_dips`.
    progress : callable, optional
        Called with the number of frames done.

    Returns
    -------
    results : dict of (H, W) ndarrays
        As :func:`shadow_times`, plus ``lit_image`` ``(H, W, C)`` and ``n_frames``.
    """
    if own_site and iter(blocks) is blocks:
        raise ValueError("own_site reads the frames a second time: blocks must be a collection such as a "
                         "list of blocks, not a one-shot iterator")
    summary, _, _ = track_sweep(blocks, shape, half_window=half_window, progress=progress)
    return summary_shadow_times(summary, method=method, cfa_pattern=cfa_pattern, own_site=own_site,
                                read=(lambda: blocks) if own_site else None,
                                method_params=method_params, classify_params=classify_params)


def summary_shadow_times(summary, *, method="edge_fit", cfa_pattern=None, method_params=None,
                         classify_params=None, interval=None, read=None, own_site=False):
    """Shadow times of one sweep from its tracked :class:`DipSummary`.

    The second half of :func:`sweep_shadow_times`, for a summary obtained
    otherwise, e.g. :func:`shadowcam.lab.dip_tracker.merge_partials` of time chunks
    tracked in separate jobs (the result is then the same bit for bit). The dips are
    classified once (:func:`classify_dips`); that classification chooses the pixels
    whose support is measured and is then timed.

    Parameters
    ----------
    summary : DipSummary
        With channel sums (the tracker was fed ``(T, H, W, C)`` blocks).
    method, cfa_pattern, method_params, classify_params
        As :func:`sweep_shadow_times`.
    interval : DipInterval, optional
        As :func:`shadow_times`.
    read : callable, optional
        ``read()`` -> an iterable of the sweep's ``(T, H, W, C)`` frame blocks in time
        order, from its first frame (read lazily, only for what needs the frames
        again). With `interval`, the dips' support (:func:`support_intervals`) is
        measured and ``several_minima`` / ``wide_dip`` pixels whose minima form one
        dip are timed (:func:`shadow_times`); without it they are not.
    own_site : bool, optional
        ``edge_fit`` times each demosaiced RAW pixel from its own mosaic site where
        its noise allows (:func:`shadowcam.lab.site_signal.track_site_window`, one more
        `read`); needs `cfa_pattern`, ``edge_fit`` and `read`.

    Returns
    -------
    results : dict of (H, W) ndarrays
        As :func:`shadow_times`, plus ``lit_image`` ``(H, W, C)``, ``saturated`` (bool)
        and ``n_frames``.

    Raises
    ------
    ValueError
        If `own_site` is asked for without a CFA pattern, with a method other than
        ``edge_fit`` or without `read`.
    """
    if own_site and not (cfa_pattern and method == "edge_fit" and read is not None):
        raise ValueError("own_site timing needs the frames' CFA pattern (cfa_pattern), method 'edge_fit' and a "
                         f"way to read the frames again (read); got cfa_pattern={cfa_pattern!r}, "
                         f"method={method!r}, read={'given' if read is not None else None}")
    lit_image = lit_colour(summary)
    classify_params = dict(classify_params or {})
    if cfa_pattern:
        colour = cfa_site_colours(summary.lit_level.shape, cfa_pattern)
        classify_params.update(
            site_colour=colour,
            site_level=np.take_along_axis(lit_image, colour[..., None].astype(np.intp), axis=2)[..., 0],
        )
    reason, contrast = classify_dips(summary, saturated=summary.saturated, interval=interval, **classify_params)
    support = None
    if interval is not None and read is not None:
        support = support_intervals(read, summary, interval, reason)
    if own_site:
        site = track_site_window(read(), summary, site_colour=cfa_site_colours(summary.lit_level.shape, cfa_pattern))
        summary = replace(summary, site=site)
    results = shadow_times(summary, reason, contrast, method=method, method_params=method_params,
                           interval=interval, support=support)
    results["lit_image"] = lit_image
    if summary.saturated is not None:
        results["saturated"] = summary.saturated
    results["n_frames"] = summary.n_frames
    return results


_VARIABLE_ATTRS = {
    "shadow_time": ("frame", "time the mask shadow's centre crosses the pixel"),
    "entry_time": ("frame", "time the shadow enters the pixel (half depth)"),
    "exit_time": ("frame", "time the shadow leaves the pixel (half depth)"),
    "time_std": ("frame", "standard deviation of shadow_time (noise model)"),
    "confidence": ("1", "confidence of shadow_time, exp(-std^2 / (2 * 0.25^2))"),
    "contrast": ("1", "dip depth over the noise of a smoothed sample"),
    "lit_level": ("linear", "unshadowed level of the channel sum"),
    "noise": ("linear", "temporal noise standard deviation of the channel sum"),
    "lit_image": ("linear", "unshadowed colour per channel"),
    "saturated": ("1", "a channel reached the white level: the unshadowed colour is a lower bound"),
    "interval_entry": ("frame", "time the smoothed signal falls below half the dip's depth (dip interval entry)"),
    "interval_exit": ("frame", "time the smoothed signal comes back above half the dip's depth (interval exit)"),
    "interval_entry_std": ("frame", "standard deviation of interval_entry (noise over the crossing's slope)"),
    "interval_exit_std": ("frame", "standard deviation of interval_exit (noise over the crossing's slope)"),
}


def shadow_time_dataset(per_sweep, *, channels=("R", "G", "B")):
    """Assemble the ``shadow_time`` dataset from per-sweep results.

    Parameters
    ----------
    per_sweep : dict of str to dict
        Sweep name -> the dict returned by :func:`sweep_shadow_times`.
    channels : sequence of str, optional

    Returns
    -------
    xarray.Dataset
        Variables over ``(sweep, row, col)`` (``lit_image`` over
        ``(sweep, row, col, channel)``); ``reason`` carries CF
        ``flag_values``/``flag_meanings``; attrs ``n_frames_<sweep>``.
    """
    import xarray as xr

    if not per_sweep:
        raise ValueError("per_sweep is empty: no sweep to assemble")
    names = list(per_sweep)
    data = {}
    for key, (units, long_name) in _VARIABLE_ATTRS.items():
        if not all(key in per_sweep[n] for n in names):
            continue
        stacked = np.stack([per_sweep[n][key] for n in names])
        dims = ("sweep", "row", "col", "channel") if stacked.ndim == 4 else ("sweep", "row", "col")
        data[key] = (dims, stacked, {"units": units, "long_name": long_name})
    data["reason"] = (("sweep", "row", "col"), np.stack([per_sweep[n]["reason"] for n in names]), {
        "long_name": "why a pixel has no shadow time",
        "flag_values": np.array(sorted(REASONS), np.uint8),
        "flag_meanings": " ".join(REASONS[k] for k in sorted(REASONS)),
    })
    n_channels = data["lit_image"][1].shape[-1]
    ds = xr.Dataset(data, coords={"sweep": names, "channel": list(channels)[:n_channels]})
    for name in names:
        ds.attrs[f"n_frames_{name}"] = int(per_sweep[name]["n_frames"])
    return ds


#: what a sweep's most common reason says about the capture (message of an empty result)
_EMPTY_HINTS = {
    "never_shadowed": "the shadow crosses (almost) no pixel: check the sweep's files",
    "low_contrast": "the sweep shows no shadow: check the exposure and that the shadow is in view",
    "saturated": "the frames are saturated: lower the exposure",
    "several_minima": "the pixels see several shadows: check the sweep's files and order",
    "invalid_input": "the sweep is too short or its frames are invalid: it needs more frames than the dip window",
    "wide_dip": "the shadow passes slower than the dip window and its interval was not measured: "
                "run the interval pass (shadow_time_of_stores does)",
    "dip_at_sweep_end": "the shadow is still on the pixels at the sweep's first or last frame: "
                        "check that the sweep starts and ends with the mask out of view",
}


def check_timed(shadow_time, *, min_coverage=MIN_COVERAGE):
    """Raise ValueError with the reason counts if a sweep has (almost) no timed pixel.

    Parameters
    ----------
    shadow_time : xarray.Dataset
        :func:`shadow_time_dataset`: ``reason (sweep, row, col)``.
    min_coverage : float
        Smallest fraction of a sweep's pixels that must carry a shadow time.
    """
    for sweep in shadow_time["sweep"].values:
        codes = np.bincount(shadow_time["reason"].sel(sweep=sweep).values.ravel(), minlength=len(REASONS))
        counts = {REASONS[code]: int(codes[code]) for code in REASONS if code not in TIMED}
        worst = max(counts, key=counts.get)
        check_coverage(int(codes[list(TIMED)].sum()), codes.sum(), what=f"camera pixels timed in sweep {sweep}", reasons=counts,
                       hint=_EMPTY_HINTS[worst], min_coverage=min_coverage)


def _store_blocks(frames):
    """The frame blocks of a frame store, ``(T, H, W, C)`` each, in time order."""
    from shadowcam.io.frame_store import iter_frame_chunks

    return (block for _, block in iter_frame_chunks(frames))


def shadow_time_of_stores(stores, *, method="edge_fit", partials=None, half_window=4, method_params=None,
                          classify_params=None, min_coverage=MIN_COVERAGE):
    """Shadow times of every sweep of a capture.

    Parameters
    ----------
    stores : mapping of str to xarray.Dataset
        Sweep name -> its frame store (``image (time, row, col, channel)``), streamed one
        time chunk at a time. A store of demosaiced RAW (attr ``cfa_pattern``) is streamed
        once more for ``edge_fit``: each pixel's own site in its dip window
        (:func:`shadowcam.lab.site_signal.track_site_window`).
    method : str
        Key of :data:`SHADOW_TIME_METHODS`.
    partials : mapping of str to sequence of path, optional
        Sweep name -> the :class:`shadowcam.lab.dip_tracker.DipPartial` files of all its
        time chunks; those sweeps are merged from them instead of streamed (same result
        bit for bit).
    half_window : int
        Dip half window of the streamed sweeps.
    method_params, classify_params : mapping, optional
        Options of the timing method and of :func:`classify_dips`.
    min_coverage : float
        Smallest fraction of each sweep's pixels that must be timed (:func:`check_timed`).

    Returns
    -------
    xarray.Dataset
        :func:`shadow_time_dataset` of the sweeps.

    Raises
    ------
    ValueError
        If a sweep has (almost) no timed pixel, with the reason counts.
    """
    from shadowcam.lab.dip_tracker import DipPartial, merge_partials, track_intervals, without_interval

    if method not in SHADOW_TIME_METHODS:
        raise ValueError(f"method: unknown {method!r}; choose from {sorted(SHADOW_TIME_METHODS)}")
    check_in_interval(min_coverage, "min_coverage", 0.0, 1.0, closed="both")
    partials = dict(partials or {})
    unknown = set(partials) - set(stores)
    if unknown:
        raise ValueError(f"partials: sweeps {sorted(unknown)} are not among the stores {sorted(stores)}")
    per_sweep = {}
    for sweep, frames in stores.items():
        n_frames = frames.sizes["time"]
        shape = (frames.sizes["row"], frames.sizes["col"])
        options = dict(method=method, cfa_pattern=frames.attrs.get("cfa_pattern") or None,
                       method_params=method_params, classify_params=classify_params)
        if sweep in partials:
            log.info("sweep %s: merging %d time chunks of %d frames", sweep, len(partials[sweep]), n_frames)
            summary = merge_partials([DipPartial.load(p) for p in partials[sweep]], n_frames=n_frames)
        else:
            log.info("sweep %s: %d frames of %dx%d", sweep, n_frames, shape[0], shape[1])
            progress = Progress(max(n_frames, 1), f"shadow times of sweep {sweep}")
            summary, _, _ = track_sweep(_store_blocks(frames), shape,
                                        half_window=half_window, progress=progress.update)
        log.info("sweep %s: dip intervals", sweep)
        interval = track_intervals(_store_blocks(frames), summary)
        summary, interval = without_interval(summary, interval)
        own_site = bool(options["cfa_pattern"]) and method == "edge_fit"
        if own_site:
            log.info("sweep %s: own-site samples of the dip windows", sweep)
        per_sweep[sweep] = summary_shadow_times(summary, interval=interval, own_site=own_site,
                                                read=partial(_store_blocks, frames),
                                                **options)
    dataset = shadow_time_dataset(per_sweep)
    check_timed(dataset, min_coverage=min_coverage)
    return dataset
