"""Photometric normalisation of an outdoor time-lapse.

Outdoors the brightness of a frame changes for reasons that are not shadows:
auto-exposure steps and flicker, and the sunset dimming and reddening of the
sun and the sky. A pixel's value is modelled as

    Y_k(p) = gain_lit_k * b(p)    while the sun reaches p (lit),
    Y_k(p) = gain_sky_k * a(p)    once p is in shadow (sky light only),

with ``Y`` the mean of R, G, B. ``gain_sky`` (exposure x sky) is estimated per
frame on pixels that are shadowed in the first frame, ``gain_lit`` (exposure x
sun + sky) on pixels that stay lit; exposure metadata, where present, only
seeds the search. A cloud shadow removes part of the sun term only: it lowers
the ratio frame / reference of the lit pixels it covers and leaves the sky-lit
pixels alone. The lit gain is therefore the gain of the *brightest* population
of lit pixels (those the cloud left unchanged), searched for where the sky gain
times the previous frame's lit-to-sky ratio puts it; when a cloud covers every
lit pixel that population is missing and the lit gain is the sky gain times
that ratio (:func:`estimate_lit_gain`). Dividing by ``gain_lit`` keeps lit pixels at their own
lit level, so the fading light is never taken for a shadow. The per-pixel
coverage ``(Y - gain_sky a) / (gain_lit b - gain_sky a)`` is then 1 where
lit, 0 where shadowed and the lit fraction of the footprint in between.

Offers
------
luminance : mean of the colour channels, float32 (:func:`shadowcam.io.luminance.channel_mean`).
exposure_gains : per-frame gain relative to the first frame from exposure times.
lit_at_start : split the first frame into lit and shadowed pixels (Otsu on log Y).
estimate_gain : robust gain of a frame relative to the reference on given pixels.
estimate_lit_gain : the gain of the lit pixels a cloud shadow left unchanged.
coverage : per-pixel lit fraction of a frame from its lit and shadow levels.
"""

import numpy as np

from shadowcam._shared.validation import check_array, check_in_interval, check_positive, check_same_shape
from shadowcam.io.luminance import channel_mean


#: the pipeline's luminance: mean of the linear colour channels (float32)
luminance = channel_mean


def exposure_gains(exposure_s):
    """Return per-frame gains relative to the first frame with a known exposure.

    Parameters
    ----------
    exposure_s : (T,) array_like
        Exposure time in seconds per frame, NaN (or <= 0) where unknown.

    Returns
    -------
    (T,) float64 ndarray
        ``exposure_s / exposure_s[first known]``; NaN where unknown (all NaN
        if no frame has an exposure time).
    """
    exposure = np.asarray(exposure_s, dtype=np.float64)
    check_array(exposure, "exposure_s", ndim=1)
    known = np.isfinite(exposure) & (exposure > 0)
    out = np.full(exposure.shape, np.nan)
    if known.any():
        out[known] = exposure[known] / exposure[np.argmax(known)]
    return out


def lit_at_start(reference_luma, *, valid):
    """Split the first frame into sunlit and shadowed pixels.

    Sunlit and sky-lit (shadowed) surfaces differ by a large factor outdoors,
    so the histogram of ``log Y`` is bimodal; Otsu's threshold separates it.

    Parameters
    ----------
    reference_luma : (H, W) ndarray
        Luminance of the reference (first) frame.
    valid : (H, W) bool ndarray
        Pixels to classify (not sky).

    Returns
    -------
    lit : (H, W) bool ndarray
        True where the pixel is sunlit (False outside `valid`).
    threshold : float
        The luminance threshold.
    """
    luma = np.asarray(reference_luma, dtype=np.float64)
    valid = np.asarray(valid, dtype=bool)
    if luma.shape != valid.shape or luma.ndim != 2:
        raise ValueError(f"reference_luma {luma.shape} and valid {valid.shape} must be the same (H, W) shape")
    values = np.log(np.maximum(luma[valid], 1e-6))
    if values.size < 2 or np.ptp(values) == 0:
        return valid.copy(), 0.0
    hist, edges = np.histogram(values, bins=256)
    centres = 0.5 * (edges[:-1] + edges[1:])
    weight0 = np.cumsum(hist)
    weight1 = weight0[-1] - weight0
    mean0 = np.cumsum(hist * centres) / np.maximum(weight0, 1)
    mean1 = (np.sum(hist * centres) - np.cumsum(hist * centres)) / np.maximum(weight1, 1)
    between = weight0 * weight1 * (mean0 - mean1) ** 2
    threshold = float(np.exp(centres[np.argmax(between)]))
    return valid & (luma > threshold), threshold


def estimate_gain(luma, reference_luma, *, pixels, prior=1.0, min_ratio=0.5, iterations=3):
    """Robust gain of a frame relative to the reference on pixels that keep their state.

    Parameters
    ----------
    luma, reference_luma : (H, W) ndarray
        Luminance of the (registered) frame and of the reference frame.
    pixels : (H, W) bool ndarray
        Candidate pixels (e.g. sunlit in the reference).
    prior : float, optional
        Expected gain (previous frame's, or from exposure metadata). If too
        few pixels lie near it (a global change: cloud, missed exposure
        step), the search restarts from the 90th percentile of the ratios.
    min_ratio : float, optional
        Pixels whose ratio is below ``min_ratio`` times the current estimate
        are taken as having changed state (newly shadowed) and are ignored.
    iterations : int, optional

    Returns
    -------
    gain : float
        Median of ``luma / reference_luma`` over the kept pixels (the prior
        if fewer than 10 pixels remain).
    kept : int
        Number of pixels used.
    """
    luma = np.asarray(luma, dtype=np.float64)
    ref = np.asarray(reference_luma, dtype=np.float64)
    pixels = np.asarray(pixels, dtype=bool)
    check_same_shape({"luma": luma, "reference_luma": ref, "pixels": pixels})
    check_positive(prior, "prior")
    use = pixels & (ref > 0)
    ratio = luma[use] / ref[use]
    if ratio.size < 10:
        return float(prior), int(ratio.size)
    for attempt in range(2):
        # the 90th percentile of the ratios only when the prior fails (a partition less per frame)
        gain, kept = (float(prior) if attempt == 0 else float(np.percentile(ratio, 90))), 0
        for _ in range(iterations):
            keep = (ratio > min_ratio * gain) & (ratio < gain / min_ratio)
            kept = int(keep.sum())
            if kept < 10:
                break
            gain = float(np.median(ratio[keep]))
        if kept >= max(10, 0.05 * ratio.size):
            return gain, kept
    return float(prior), kept


#: lower quartile of a half-normal variable over its scale (``Phi^-1(5 / 8)``)
HALF_NORMAL_QUARTILE = 0.31863936396437514


def _sorted_median(values):
    """Median of a sorted 1-D array (as :func:`numpy.median`)."""
    middle = values.size // 2
    return float(values[middle]) if values.size % 2 else float(0.5 * (values[middle - 1] + values[middle]))


def estimate_lit_gain(luma, reference_luma, *, pixels, expected=None, spread=3.0, min_ratio=0.5,
                      iterations=3):
    """Gain of the lit pixels a cloud shadow left unchanged: the brightest population of ratios.

    A cloud shadow only removes sunlight, so on pixels lit in the reference the
    ratios ``luma / reference_luma`` of the pixels it covers lie *below* the
    gain of the unchanged ones, whatever its size, depth or border; noise and
    the pixels' own spread are on both sides. The population's scale is
    measured on the side a cloud cannot reach (above the current estimate: the
    lower quartile of a half-normal deviation is ``HALF_NORMAL_QUARTILE`` scales;
    the quartile, not the median, because pixels darker in the reference than
    now (a cloud or the penumbra over them then) lie above too), the
    gain is the median of the ratios within `spread` scales of it, repeated
    with the scale never growing (so that the band cannot widen into the
    pixels below the population).

    Parameters
    ----------
    luma, reference_luma : (H, W) ndarray
        Luminance of the (registered) frame and of the reference frame.
    pixels : (H, W) bool ndarray
        Pixels sunlit in the reference.
    expected : float, optional
        Where the unchanged population is expected (the sky gain times the
        previous frame's lit-to-sky gain ratio: no cloud moves it). None: the
        90th percentile of the ratios (the unchanged population must then hold
        more than a tenth of the lit pixels).
    spread : float, optional
        Half-width of the population in scales (a Gaussian's 3 keeps 99.7 %).
    min_ratio : float, optional
        Ratios below ``min_ratio`` times the starting level (pixels the ridge
        has shadowed since) or above it divided by ``min_ratio`` (glints, pixels
        not fully lit in the reference) are left out.
    iterations : int, optional

    Returns
    -------
    gain : float
        The unchanged population's gain; `expected` when it is missing (fewer
        than 10 ratios at or above the estimate: a cloud covers every lit
        pixel), or when `pixels` hold fewer than 10 ratios.
    kept : int
        Ratios the gain is the median of (0 when it is missing).
    found : bool
        Whether the population was found.
    """
    luma = np.asarray(luma, dtype=np.float64)
    ref = np.asarray(reference_luma, dtype=np.float64)
    pixels = np.asarray(pixels, dtype=bool)
    check_same_shape({"luma": luma, "reference_luma": ref, "pixels": pixels})
    check_positive(spread, "spread")
    check_in_interval(min_ratio, "min_ratio", 0.0, 1.0, closed="neither")
    if expected is not None:
        check_positive(expected, "expected")
    use = pixels & (ref > 0)
    ratio = np.sort(luma[use] / ref[use])  # once: every band below is a slice, its median an index
    if ratio.size < 10:
        return (np.nan if expected is None else float(expected)), 0, False
    gain = float(np.percentile(ratio, 90)) if expected is None else float(expected)
    start, kept, scale = gain, 0, np.inf
    # ratios beyond min_ratio of the start either way changed state (newly shadowed, glints)
    bottom = np.searchsorted(ratio, min_ratio * start, side="right")
    top = np.searchsorted(ratio, start / min_ratio, side="left")
    for _ in range(iterations):
        above = ratio[np.searchsorted(ratio, gain, side="left"):top]
        if above.size < 10:
            return start, 0, False
        # the scale never grows: the band slides toward the population's centre, it cannot
        # widen into the pixels below it (a cloud's, clipped ones)
        scale = min(scale, (above[(above.size - 1) // 4] - gain) / HALF_NORMAL_QUARTILE)
        half_width = spread * scale
        band = ratio[max(np.searchsorted(ratio, gain - half_width, side="left"), bottom):
                     min(np.searchsorted(ratio, gain + half_width, side="right"), top)]
        kept = band.size
        gain = _sorted_median(band)
    return gain, int(kept), True


def coverage(luma, *, lit_level, shadow_level):
    """Per-pixel lit fraction of the footprint.

    Parameters
    ----------
    luma : (H, W) ndarray
        Luminance of the (registered) frame.
    lit_level, shadow_level : (H, W) ndarray
        The pixel's luminance in this frame if fully lit / fully shadowed.

    Returns
    -------
    (H, W) float32 ndarray
        ``(luma - shadow) / (lit - shadow)`` (not clipped); NaN where
        ``lit <= shadow``.
    """
    luma = np.asarray(luma, dtype=np.float32)
    lit = np.asarray(lit_level, dtype=np.float32)
    shadow = np.asarray(shadow_level, dtype=np.float32)
    check_same_shape({"luma": luma, "lit_level": lit, "shadow_level": shadow})
    span = lit - shadow
    out = luma - shadow
    with np.errstate(divide="ignore", invalid="ignore"):
        out /= span
    out[~(span > 0)] = np.nan
    return out
