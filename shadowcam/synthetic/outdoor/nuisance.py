"""Nuisances of real time-lapse captures, each switchable and recorded per frame.

Offers
------
capture_times : frame times of an intervalometer (regular, or irregular with dropped frames).
auto_exposure : auto-exposure gain per frame: 1/3-EV steps from centre-weighted metering,
    plus shutter flicker.
metered_level : the centre-weighted mean that auto-exposure meters.
shake_offsets : per-frame camera shake (dx, dy) in pixels, AR(1) jitter plus gust jolts.
apply_shake : move an image's content by a sub-pixel offset (cubic spline, edges replicated).
cloud_transmittance : sun-term transmittance of a cloud shadow (soft, or a disk with a sharp or
    soft rim) drifting over the ground.
"""

import numpy as np

from shadowcam._shared.validation import check_positive
from shadowcam.outdoor.translation import translate


def capture_times(duration_s, frames, *, seed, irregular=True, dropped=0):
    """Times (s since frame 0) of the kept frames; first 0, last `duration_s`.

    Parameters
    ----------
    duration_s : float
        Time from the first to the last kept frame.
    frames : int
        Number of kept frames.
    seed : int, keyword-only
    irregular : bool, keyword-only
        False: regular intervals. True: three intervalometer regimes (x0.85, x1.0, x1.2),
        +-6% jitter and a few slow card writes (+40%), scaled to `duration_s`.
    dropped : int, keyword-only
        Slots of the nominal schedule (never the first or last) whose frame is missing.

    Returns
    -------
    times_s : (frames,) ndarray
        Rounded to 1 ms (the precision written into the frames' metadata).
    nominal_index : (frames,) ndarray of int
        Slot of each kept frame in the nominal schedule of ``frames + dropped`` slots.
    dropped_slots : (dropped,) ndarray of int
    """
    frames, dropped = int(frames), int(dropped)
    if frames < 2:
        raise ValueError(f"frames: need at least 2, got {frames}")
    if not 0 <= dropped <= max(0, (frames - 2) // 4):
        raise ValueError(f"dropped: must be in [0, {(frames - 2) // 4}], got {dropped}")
    check_positive(duration_s, "duration_s")
    rng = np.random.default_rng([int(seed), 41])
    slots = frames + dropped
    intervals = np.ones(slots - 1)
    if irregular:
        regime = np.repeat([0.85, 1.0, 1.2], -(-(slots - 1) // 3))[: slots - 1]
        intervals = regime * (1.0 + rng.uniform(-0.06, 0.06, slots - 1))
        slow = rng.choice(slots - 1, size=min(4, slots - 1), replace=False)
        intervals[slow] *= 1.4
    if dropped:
        dropped_slots = np.sort(rng.choice(np.arange(1, slots - 1), size=dropped, replace=False))
    else:
        dropped_slots = np.zeros(0, dtype=int)
    slot_times = np.concatenate([[0.0], np.cumsum(intervals)])
    slot_times *= duration_s / slot_times[-1]
    keep = np.setdiff1d(np.arange(slots), dropped_slots)
    times = np.round(slot_times[keep], 3)
    return times, keep, dropped_slots


def metered_level(radiance):
    """Centre-weighted mean of a (rows, cols, 3) radiance image (Gaussian weight, sigma =
    0.3 x the image size)."""
    rows, cols = radiance.shape[:2]
    y = (np.arange(rows) + 0.5) / rows - 0.5
    x = (np.arange(cols) + 0.5) / cols - 0.5
    w = np.exp(-0.5 * (y[:, None] ** 2 + x[None, :] ** 2) / 0.3**2)
    return float((radiance.mean(axis=2) * w).sum() / w.sum())


def auto_exposure(levels, *, seed, enabled=True, tolerance_ev=0.5, flicker=0.006,
                  max_ev=4.0):
    """Auto-exposure of a sequence from its metered levels.

    The step part ``ae_ev`` starts at 0 and moves, in 1/3 EV steps, to the rounded
    correction ``log2(level_0 / level_k)`` whenever that leaves ``+-tolerance_ev`` of the
    current step; the true gain is ``2**ae_ev * exp(N(0, flicker))``.

    Parameters
    ----------
    levels : (K,) ndarray
        Metered levels (:func:`metered_level`) of the noise-free frames.
    seed : int, keyword-only
    enabled : bool, keyword-only
        False: gain 1 in every frame.

    Returns
    -------
    gain, ae_ev : (K,) ndarray
    """
    levels = np.asarray(levels, dtype=np.float64)
    if levels.ndim != 1 or not np.all(levels > 0):
        raise ValueError("levels: expected a 1-D array of positive metered levels")
    if not enabled:
        return np.ones(len(levels)), np.zeros(len(levels))
    rng = np.random.default_rng([int(seed), 43])
    ae = np.zeros(len(levels))
    current = 0.0
    for k, level in enumerate(levels):
        want = np.log2(levels[0] / level)
        if abs(want - current) > tolerance_ev:
            current = float(np.clip(np.round(want * 3.0) / 3.0, -max_ev, max_ev))
        ae[k] = current
    gain = 2.0**ae * np.exp(rng.normal(0.0, flicker, len(levels)))
    return gain, ae


def shake_offsets(frames, *, seed, max_px=1.0):
    """Per-frame camera shake in pixels (content moves by +dx, +dy).

    AR(1) jitter (coefficient 0.7, rms ~0.3 `max_px`) plus gust jolts of 0.6-1.0 `max_px`
    in ~4% of the frames, clipped to ``|(dx, dy)| <= max_px``. ``max_px = 0``: no shake.

    Returns
    -------
    dx, dy : (frames,) ndarray
    """
    if not max_px >= 0:
        raise ValueError(f"max_px must be >= 0; got {max_px}")
    if max_px == 0:
        return np.zeros(frames), np.zeros(frames)
    rng = np.random.default_rng([int(seed), 47])
    jitter = np.zeros((frames, 2))
    sigma = 0.3 * max_px * np.sqrt(1 - 0.7**2)
    for k in range(1, frames):
        jitter[k] = 0.7 * jitter[k - 1] + rng.normal(0.0, sigma, 2)
    gust = rng.random(frames) < 0.04
    angle = rng.uniform(0, 2 * np.pi, frames)
    size = rng.uniform(0.6, 1.0, frames) * max_px
    jitter[gust] += (size * np.stack([np.cos(angle), np.sin(angle)], axis=1).T).T[gust]
    norm = np.hypot(jitter[:, 0], jitter[:, 1])
    limit = max_px - 1e-4  # so that rounding to 1e-4 px stays within max_px
    jitter *= np.minimum(1.0, limit / np.maximum(norm, 1e-12))[:, None]
    return np.round(jitter[:, 0], 4), np.round(jitter[:, 1], 4)


def apply_shake(image, dx, dy):
    """``out(u, v) = image(u - dx, v - dy)`` for a (rows, cols, C) image: cubic spline,
    edges replicated, clipped at 0 (radiance stays non-negative)."""
    if dx == 0 and dy == 0:
        return image
    out = translate(image, (-dy, -dx), method="spline")
    return np.clip(out, 0, None, out=out)


def cloud_transmittance(points_xy, t_s, *, start_xy, velocity_xy, sigma_m=250.0, depth=0.5, rim_m=None):
    """Transmittance of the sun term under a drifting cloud shadow.

    Soft (``rim_m`` None): ``c = 1 - depth exp(-r^2 / (2 sigma^2))``; with a rim: a disk of
    radius ``sigma_m`` whose border is a logistic ramp of width ``rim_m``,
    ``c = 1 - depth / (1 + exp((r - sigma) / rim))`` (small `rim_m`: a hard-edged cloud);
    ``r = |p - (start + velocity t)|`` on the ground (x, y).

    Parameters
    ----------
    points_xy : (N, 2) ndarray
        World (x, y) of the terrain points (m).
    t_s : float
    start_xy, velocity_xy : 2-sequences, keyword-only
        Centre of the cloud shadow at t = 0 (m) and its drift (m/s).
    sigma_m, depth : float, keyword-only
        Radius (m) and depth (1 - the smallest transmittance).
    rim_m : float, keyword-only, optional
        Width of the border ramp (m); None for the Gaussian profile.

    Returns
    -------
    (N,) ndarray in [1 - depth, 1]
    """
    if not 0 <= depth < 1:
        raise ValueError(f"depth must be in [0, 1); got {depth}")
    check_positive(sigma_m, "sigma_m")
    centre = np.asarray(start_xy, dtype=np.float64) + np.asarray(velocity_xy) * float(t_s)
    r2 = ((np.asarray(points_xy) - centre) ** 2).sum(axis=1)
    if rim_m is None:
        return 1.0 - depth * np.exp(-0.5 * r2 / sigma_m**2)
    check_positive(rim_m, "rim_m")
    u = np.clip((np.sqrt(r2) - sigma_m) / rim_m, -60.0, 60.0)
    return 1.0 - depth / (1.0 + np.exp(u))
