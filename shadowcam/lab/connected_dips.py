"""A thin wire under a light wider than it: one dip with several minima, timed as one.

A wire narrower than an area light's projection casts no umbra: its dip is the light's
profile swept by the wire, shallow and as wide as the light's projection, and a sampled
or noisy profile shows several minima in it. They are one dip where the signal between
them never returns to the lit level (:func:`support_intervals`, the excursion below
:func:`support_threshold`); such a dip is timed at its removed light's centroid
(:func:`time_connected_dips`).

Offers
------
support_threshold : the level below which a pixel's light is still removed.
support_intervals, DipSupport : each candidate dip's excursion below the lit level, its centroid and width.
time_connected_dips : time the ``several_minima`` / ``wide_dip`` pixels whose minima form one dip.
"""

from dataclasses import dataclass, replace

import numpy as np

from shadowcam._shared.validation import check_in_interval, check_positive
from shadowcam.lab.dip_classification import (
    _SMOOTHED_NOISE, OK, SEVERAL_MINIMA, WIDE_DIP, detection_threshold, supported_by_neighbours,
)
from shadowcam.lab.dip_tracker import lit_without, track_intervals

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


def time_connected_dips(summary, support, reason, time, entry, exit_, std, extra):
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
    connected = candidate & supported_by_neighbours(candidate, candidate, centroid)
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
