"""Whether each pixel's dip is a reliable shadow, and why not: the reason codes of a sweep.

A dip is detected when it is deeper than pure noise gets within the sweep, or when a
looser test passes and its timing agrees with detected neighbours'; a detected dip is
then examined for what makes its time unreliable: a cast-shadow boundary across the
footprint with the centre in shadow, a second dip, a dip wider than the tracker's
window, broken samples (:func:`classify_dips`). Pixels whose dip agrees in time with its
neighbours' (:func:`supported_by_neighbours`) are also how a wide or connected dip's
time is confirmed (:mod:`shadowcam.lab.shadow_time`, :mod:`shadowcam.lab.connected_dips`).

Offers
------
REASONS : flag code -> meaning, for pixels without a reliable time.
TIMED : the codes of the pixels with a time.
detection_threshold : dip depth, in smoothed-noise units, that pure noise rarely reaches.
neighbour_offsets : the ``(dr, dc)`` offsets within a radius.
supported_by_neighbours : dips whose time agrees with enough strong neighbours'.
classify_dips : reason code and contrast per pixel.
"""

import numpy as np
from scipy.special import ndtri

from shadowcam._shared.validation import check_in_interval
from shadowcam.lab.dip_tracker import lit_colour
from shadowcam.lab.edge_refine import shifted

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
#: codes of the pixels with a time: a reliable one, and one of a dip cut by the sweep's first
#: or last frame, from its part in the sweep and its neighbours' dip width or removed light
#: (their spread in ``time_std``)
TIMED = (OK, DIP_AT_SWEEP_END_TIMED)
#: standard deviation of a [1, 2, 1]/4-smoothed sample relative to a raw one
_SMOOTHED_NOISE = float(np.sqrt(0.25**2 * 2 + 0.5**2))


def _window_times(summary):
    """Frame index of each window slot, ``(K, H, W)`` float64."""
    k = summary.window.shape[0]
    return summary.window_start[None] + np.arange(k)[:, None, None]


def detection_threshold(n_frames, *, false_alarm=1e-3):
    """Dip depth, in units of the smoothed-sample noise, that pure noise rarely reaches.

    The deepest of `n_frames` smoothed noise samples exceeds ``z`` standard
    deviations with probability about ``n_frames * Q(z)``; ``z`` is chosen so
    that this is `false_alarm`.
    """
    check_in_interval(false_alarm, "false_alarm", 0, 1, closed="neither")
    return float(-ndtri(false_alarm / max(int(n_frames), 1)))


def neighbour_offsets(radius):
    """Neighbour offsets ``(dr, dc)`` within `radius`, excluding ``(0, 0)``."""
    return [(dr, dc) for dr in range(-radius, radius + 1) for dc in range(-radius, radius + 1)
            if (dr, dc) != (0, 0)]


def supported_by_neighbours(candidate, strong, minimum_frame, *, radius=2, frames_per_pixel=1.5,
                             min_support=3):
    """Weak dips whose timing agrees with enough strong neighbours.

    A real but faint shadow dip occurs when the neighbours' dips occur (the
    edge sweeps across them); a dip of pure noise falls at a random frame. A
    candidate is supported when at least `min_support` strong neighbours, and
    at least half of the strong neighbours, have their minimum within
    ``1 + frames_per_pixel * distance`` frames of the candidate's.
    """
    h, w = candidate.shape
    rows, cols = np.nonzero(candidate)  # only the candidates are tested
    agree = np.zeros(rows.shape, np.int32)
    total = np.zeros(rows.shape, np.int32)
    frame = minimum_frame.astype(np.float64)
    own = frame[rows, cols]
    for dr, dc in neighbour_offsets(radius):
        r, c = rows + dr, cols + dc
        inside = (r >= 0) & (r < h) & (c >= 0) & (c < w)
        r, c = np.clip(r, 0, h - 1), np.clip(c, 0, w - 1)
        n_strong = inside & strong[r, c]
        tolerance = 1.0 + frames_per_pixel * np.hypot(dr, dc)
        total += n_strong
        agree += n_strong & (np.abs(frame[r, c] - own) <= tolerance)
    supported = np.zeros(candidate.shape, bool)
    supported[rows, cols] = (agree >= min_support) & (2 * agree >= total)
    return supported


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
    for dr, dc in neighbour_offsets(1 if site_colour is None else 2):
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
    detected = strong | supported_by_neighbours(weak, strong, summary.minimum_frame)
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
