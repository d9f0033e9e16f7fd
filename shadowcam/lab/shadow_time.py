"""Per-pixel shadow time of a sweep: when the mask's shadow passes each pixel.

The frames of one sweep stream through a :class:`~shadowcam.lab.dip_tracker.DipTracker`
(memory independent of the frame count); each pixel's dip is then classified once
(:mod:`shadowcam.lab.dip_classification`: is there a reliable shadow at all?) and timed
to a fraction of a frame by one of the methods of
:data:`~shadowcam.lab.shadow_time_methods.SHADOW_TIME_METHODS`. With the dips' measured
intervals, a dip wider than the tracker's window is timed at its interval's centre
(cut by the sweep's start or end: from its one edge and the neighbours' width), a thin
dip cut by the sweep's first or last frame from its neighbours' removed light, and one
with several minima that never returns to the lit level between them at its removed
light's centroid (:mod:`shadowcam.lab.connected_dips`).

Offers
------
shadow_times : timing of one sweep's classified :class:`DipSummary`.
footprint_spread_std : time uncertainty of a footprint that sees two surfaces' shadow times.
cut_by_sweep : pixels whose dip the sweep's first or last frame cuts.
track_sweep : stream frame blocks of one sweep into a summary and per-channel colour.
sweep_shadow_times : frames of one sweep (streamed) -> shadow times, colour, flags.
summary_shadow_times : the same from a summary (e.g. merged time-chunk partials).
measured_shadow_times : a tracked sweep's interval, connected dips and own sites, then its times
    (the one path of frame stores and of files).
shadow_time_dataset : assemble the per-sweep results into the ``shadow_time`` dataset.
check_timed : fail with the reason counts when a sweep has (almost) no timed pixel.
shadow_time_of_stores : frame stores of the sweeps (or their time-chunk partials) -> the ``shadow_time`` dataset.
"""

import logging
from dataclasses import replace
from functools import partial

import numpy as np

from shadowcam._shared.coverage import MIN_COVERAGE, check_coverage
from shadowcam._shared.progress import Progress
from shadowcam._shared.validation import check_in_interval
from shadowcam.lab.connected_dips import support_intervals, time_connected_dips
from shadowcam.lab.dip_classification import (
    _SMOOTHED_NOISE, DIP_AT_SWEEP_END, DIP_AT_SWEEP_END_TIMED, INVALID_INPUT, NEVER_SHADOWED, OK, REASONS, TIMED,
    WIDE_DIP, classify_dips, detection_threshold, supported_by_neighbours,
)
from shadowcam.lab.dip_tracker import DipTracker, lit_colour, track_intervals, without_interval
from shadowcam.lab.penumbra_law import penumbra_edges
from shadowcam.lab.shadow_time_methods import SHADOW_TIME_METHODS
from shadowcam.lab.site_signal import blend_variance, cfa_site_colours, track_site_window
from shadowcam.lab.timing_kernels import neighbour_median, removed_light

log = logging.getLogger(__name__)


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
        end, ``invalid_input`` with a non-finite sample inside), a thin dip cut by
        the sweep's first or last frame (:func:`cut_by_sweep`) from its neighbours'
        removed light (``dip_at_sweep_end_timed``, or ``dip_at_sweep_end`` when its
        centre is outside the sweep), the ``interval_*`` variables are returned, and
        ``time_std`` adds the footprint's excess span (:func:`footprint_spread_std`).
    support : DipSupport, optional
        The dips' excursions below the lit level (:func:`support_intervals` of `reason`):
        a ``several_minima`` or ``wide_dip`` pixel whose minima lie in one excursion
        below the lit level is one dip, timed at its removed light's centroid
        (:func:`time_connected_dips`). Needs `interval`.

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
            reason, time, entry, exit_, std, extra = time_connected_dips(
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
    reference = neighbour_median(np.ascontiguousarray(width, np.float64))
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
    # a flagged wide dip open at the sweep's start or end has no time; a thin dip the window
    # holds that the sweep cuts is timed from its samples below (_time_cut_thin_dips)
    cut_start, cut_end = cut_by_sweep(summary, interval)
    cut_thin = (reason == OK) & ~beyond & (cut_start != cut_end)
    wide = ((reason == WIDE_DIP) & (beyond | opened)) | ((reason == OK) & beyond)
    at_end = wide & opened
    broken = wide & ~at_end & ((interval.invalid > 0) | ~np.isfinite(interval.entry) | ~np.isfinite(interval.exit))
    timed = wide & ~at_end & ~broken
    centre = interval.at(0.5)
    # a dip the window flagged wide is a shadow only where the shadow's edge sweeps on: its
    # centre agrees with timed neighbours' (a dip of some other event falls at its own time)
    flagged = timed & (reason == WIDE_DIP)
    others = (reason == OK) | timed
    timed &= ~flagged | supported_by_neighbours(flagged, others, np.where(timed, centre, time))
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
    one_edge = at_end & (interval.entry_open != interval.exit_open) & (interval.invalid == 0)
    width, width_std = _local_width(interval_exit - interval_entry, uncut, one_edge)
    with np.errstate(invalid="ignore"):
        cut_centre = np.where(interval.exit_open, interval_entry + 0.5 * width, interval_exit - 0.5 * width)
        cut = one_edge & np.isfinite(cut_centre) & (cut_centre >= 0) & (cut_centre <= summary.n_frames - 1)
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
    # a thin dip cut by the sweep, from the removed light of its uncut neighbours' dips
    removed = _removed_light(summary)
    whole = (reason == OK) & ~cut_thin & ~(cut_start | cut_end) & np.isfinite(removed[0])
    total, total_std = _local_width(removed[0], whole, cut_thin)
    cut_time, cut_std = _time_cut_thin_dips(summary, removed, cut_thin, cut_start, total, total_std)
    with np.errstate(invalid="ignore"):
        inside = cut_thin & np.isfinite(cut_time) & (cut_time >= 0) & (cut_time <= summary.n_frames - 1)
    reason[cut_thin] = DIP_AT_SWEEP_END
    reason[inside] = DIP_AT_SWEEP_END_TIMED
    time = np.where(inside, cut_time, time)
    std = np.where(inside, cut_std, std)
    # the crossing inside the sweep mirrored about the centre gives the one beyond it
    interval_entry = np.where(inside & cut_start, 2 * cut_time - interval_exit, interval_entry)
    interval_exit = np.where(inside & ~cut_start, 2 * cut_time - interval_entry, interval_exit)
    entry_std = np.where(inside & cut_start, np.hypot(exit_std, 2 * cut_std), entry_std)
    exit_std = np.where(inside & ~cut_start, np.hypot(entry_std, 2 * cut_std), exit_std)
    entry = np.where(inside, interval_entry, entry)
    exit_ = np.where(inside, interval_exit, exit_)
    extra = {"interval_entry": interval_entry, "interval_exit": interval_exit,
             "interval_entry_std": entry_std, "interval_exit_std": exit_std}
    return reason, time, entry, exit_, std, extra


def cut_by_sweep(summary, interval, *, false_alarm=1e-3):
    """Pixels whose dip the sweep's first or last frame cuts.

    A dip is cut by the sweep's start (end) when its window holds the sweep's first (last)
    frame and the signal there is not back at the lit level: its half-depth interval is
    open on that side, or the sample is darker than the lit level by more than pure noise
    reaches with probability `false_alarm`.

    Parameters
    ----------
    summary : DipSummary
        ``window (K, H, W)``, ``window_start``, ``lit_level``, ``noise`` ``(H, W)``.
    interval : DipInterval
        ``entry_open``, ``exit_open`` ``(H, W)``.
    false_alarm : float, optional
        Probability that a lit sample of pure noise is taken for a cut dip.

    Returns
    -------
    cut_start, cut_end : (H, W) bool ndarray
    """
    k = summary.window.shape[0]
    z = detection_threshold(1, false_alarm=false_alarm)
    rows, cols = np.indices(summary.window_start.shape)
    cut = []
    for frame, open_ in ((0, interval.entry_open), (summary.n_frames - 1, interval.exit_open)):
        slot = frame - summary.window_start
        held = (slot >= 0) & (slot < k)
        sample = summary.window[np.clip(slot, 0, k - 1), rows, cols].astype(np.float64)
        with np.errstate(invalid="ignore"):
            cut.append(held & (open_ | (summary.lit_level - sample > z * summary.noise)))
    return cut[0], cut[1]


def _removed_light(summary):
    """Removed light of each pixel's window, ``1 - I / I_lit`` summed, and its first moment in frames.

    Not clipped, so lit samples add zero-mean noise only. Returns ``(total, moment, floor)``,
    ``(H, W)`` each: the sum over the window's frames inside the sweep, the sum of frame
    times the removed fraction, the largest removed fraction.
    """
    k = summary.window.shape[0]
    shape = summary.lit_level.shape
    total, moment, floor = removed_light(
        np.ascontiguousarray(summary.window, np.float32).reshape(k, -1),
        np.ascontiguousarray(summary.window_start, np.int64).ravel(),
        np.ascontiguousarray(summary.lit_level, np.float64).ravel())
    return total.reshape(shape), moment.reshape(shape), floor.reshape(shape)


def _time_cut_thin_dips(summary, removed, pixels, cut_start, total, total_std):
    """Centre of each thin dip cut by the sweep's first (`cut_start`) or last frame.

    A dip removes the same light summed over its frames (``1 - I / I_lit``: the wire's
    width in frames) wherever a planar sweep's shadow passes, so the uncut neighbours'
    `total` says how much of it lies beyond the sweep. That part is put in the frames
    beyond the cut end, nearest first, each up to the deepest removed fraction seen (the
    dip's floor), and the centre is the centroid of the whole dip. It is exact for a
    hard-edged dip sampled over whole frames whose floor the sweep shows, and errs outward
    otherwise (a floor not seen is taken shallower: the dip reaches further beyond).

    Parameters
    ----------
    summary : DipSummary
    removed : tuple of (H, W) ndarray
        :func:`_removed_light` of `summary`.
    pixels : (H, W) bool ndarray
        The cut dips to time (the others are NaN).
    cut_start : (H, W) bool ndarray
        The cut is at the sweep's first frame (else at its last).
    total, total_std : (H, W) ndarray
        Removed light of the uncut neighbours' dips (frames) and its spread.

    Returns
    -------
    time, time_std : (H, W) float64 ndarray
        Frames; outside ``[0, n_frames - 1]`` where the centre lies beyond the sweep,
        NaN where `total` is unknown or outside `pixels`. ``time_std`` from the samples'
        noise and `total_std`.
    """
    time_map, std_map = np.full(pixels.shape, np.nan), np.full(pixels.shape, np.nan)
    seen, moment, floor = (part[pixels] for part in removed)
    cut_start, total, total_std = cut_start[pixels], total[pixels], total_std[pixels]
    window = summary.window[:, pixels]
    floor = np.clip(floor, 1e-3, 1.0)
    with np.errstate(invalid="ignore"):
        missing = np.maximum(total - seen, 0.0)
    beyond_first = np.where(cut_start, -1.0, float(summary.n_frames))
    step = np.where(cut_start, -1.0, 1.0)
    k = window.shape[0]
    placed, placed_moment = np.zeros(seen.shape), np.zeros(seen.shape)
    for j in range(k):
        mass = np.clip(missing - j * floor, 0.0, floor)
        placed += mass
        placed_moment += mass * (beyond_first + j * step)
    with np.errstate(invalid="ignore", divide="ignore"):
        time = (moment + placed_moment) / (seen + placed)
        # more missing than the window's length of floor: the centre is far beyond the sweep
        time = np.where(missing > k * floor, beyond_first + k * step, time)
        frames = summary.window_start[pixels][None] + np.arange(k)[:, None]
        held = np.isfinite(window)
        lever = np.sqrt(np.where(held, (frames - beyond_first[None]) ** 2, 0.0).sum(axis=0))
        sample_std = summary.noise[pixels] / summary.lit_level[pixels] * lever / total
        time_std = np.hypot(sample_std, np.abs(time - beyond_first) * total_std / total)
    time_map[pixels] = np.where(np.isfinite(total), time, np.nan)
    std_map[pixels] = time_std
    return time_map, std_map


def _local_width(width, known, wanted, *, min_count=8):
    """Mean and standard deviation of `width` over the nearest `known` pixels, ``(H, W)`` each.

    Over the smallest square of side ``2 r + 1`` (``r`` = 1, 2, 4, ...) holding at
    least `min_count` known pixels; NaN where the whole image holds fewer and outside
    the `wanted` pixels (``(H, W)`` bool: the squares grow until these have theirs).
    """
    from scipy import ndimage

    values = np.where(known, width, 0.0)
    mean, spread = np.full(width.shape, np.nan), np.full(width.shape, np.nan)
    left = np.array(wanted, bool)
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
                         classify_params=None, interval=None, read=None, own_site=False, site_window=None):
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
    site_window : callable, optional
        ``site_window(summary, site_colour)`` -> the :class:`~shadowcam.lab.site_signal.SiteWindow`
        of `own_site` measured otherwise than from ``read()``'s demosaiced blocks (e.g.
        straight from the mosaics, in time chunks).

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
        colour = cfa_site_colours(summary.lit_level.shape, cfa_pattern)
        site = (site_window(summary, colour) if site_window is not None
                else track_site_window(read(), summary, site_colour=colour))
        summary = replace(summary, site=site)
    results = shadow_times(summary, reason, contrast, method=method, method_params=method_params,
                           interval=interval, support=support)
    results["lit_image"] = lit_image
    if summary.saturated is not None:
        results["saturated"] = summary.saturated
    results["n_frames"] = summary.n_frames
    return results


def measured_shadow_times(summary, *, read, method="edge_fit", cfa_pattern=None, measure=None, site_window=None,
                          method_params=None, classify_params=None):
    """Shadow times of one tracked sweep with every measurement that needs its frames again.

    The one path of a sweep's frame store (:func:`shadow_time_of_stores`) and of its
    files (:func:`shadowcam.lab.sweep_files.sweep_shadow_times_from_files`): the dip
    interval (:func:`shadowcam.lab.dip_tracker.track_intervals`, from the windows where
    they hold it), the lit statistics without it, the connected dips' support, and for
    RAW (a `cfa_pattern`) with ``edge_fit`` each pixel's own mosaic site; then
    :func:`summary_shadow_times`; where the sweep's dips are wider than the window, their
    outer edges and half-hidden crossings from the penumbra law
    (:func:`shadowcam.lab.penumbra_law.penumbra_edges`, with ``method_params``'
    ``footprint_variance``, for RAW plus the demosaic taps' second moment,
    :func:`shadowcam.lab.site_signal.blend_variance`).

    Parameters
    ----------
    summary : DipSummary
    read : callable
        ``read()`` -> the sweep's blocks of the tracked signal in time order, from its
        first frame (``(T, H, W, C)`` demosaiced frames when `site_window` is not given
        and the sweep is RAW); iterated only for what the windows do not hold.
    method, cfa_pattern, method_params, classify_params
        As :func:`summary_shadow_times`.
    measure : callable, optional
        As :func:`shadowcam.lab.dip_tracker.track_intervals` (e.g. time chunks in parallel).
    site_window : callable, optional
        As :func:`summary_shadow_times`.

    Returns
    -------
    dict
        As :func:`summary_shadow_times`, with the keys of
        :func:`~shadowcam.lab.penumbra_law.penumbra_edges` where it applies.
    """
    interval = track_intervals(read(), summary, measure=measure)
    summary, interval = without_interval(summary, interval)
    own_site = bool(cfa_pattern) and method == "edge_fit"
    results = summary_shadow_times(summary, method=method, cfa_pattern=cfa_pattern or None, interval=interval,
                                   read=read, own_site=own_site, site_window=site_window if own_site else None,
                                   method_params=method_params, classify_params=classify_params)
    variance = (method_params or {}).get("footprint_variance")
    if cfa_pattern:  # the law is fitted to the demosaic's channel sum: its taps widen each footprint
        variance = (variance or 0.0) + blend_variance(cfa_site_colours(summary.lit_level.shape, cfa_pattern))
    results.update(penumbra_edges(read, results, n_frames=summary.n_frames, half_window=summary.half_window,
                                  footprint_variance=variance))
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
    "penumbra_first": ("frame", "first contact: the wire's leading edge reaches the source's extreme point "
                                "(penumbra law, wide dips only)"),
    "penumbra_last": ("frame", "last release: the trailing edge frees the source's other extreme point "
                               "(penumbra law, wide dips only)"),
    "penumbra_first_std": ("frame", "standard deviation of penumbra_first (the law's fit)"),
    "penumbra_last_std": ("frame", "standard deviation of penumbra_last (the law's fit)"),
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
        if not all(key in per_sweep[n] for n in names) and not (
                key.startswith("penumbra_") and any(key in per_sweep[n] for n in names)):
            continue
        shape = per_sweep[names[0]]["reason"].shape
        # the law's edges of a sweep whose dips were not wide: none
        stacked = np.stack([per_sweep[n].get(key, np.full(shape, np.nan, np.float32)) for n in names])
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
    from shadowcam.lab.dip_tracker import DipPartial, merge_partials

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
        log.info("sweep %s: dip intervals (and what needs the frames again)", sweep)
        per_sweep[sweep] = measured_shadow_times(summary, read=partial(_store_blocks, frames), **options)
    dataset = shadow_time_dataset(per_sweep)
    check_timed(dataset, min_coverage=min_coverage)
    return dataset
