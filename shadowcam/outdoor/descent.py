"""Each pixel's final descent into shadow, kept while streaming and fitted with the penumbra law.

With the real sun (a 0.53 deg disc) the shadow of a ridge kilometres away arrives over a
penumbra that lasts many frames at a photographer's cadence; the arrival (half the disc
occluded) is the centre of that ramp, which a level crossing between two frames finds only
when the ramp is shorter than an interval and the levels are right. :class:`DescentBuffer`
keeps, per pixel, the coverage of the last ``K`` frames, and stops writing once the
pixel's current dark episode has lasted ``K // 2`` frames: what it holds at the end is the
final descent (``K // 2`` frames before the final episode's level crossing and as many
after, or up to the last frame). An episode that ends (the pixel relights: a cloud passed)
restarts the pixel's record. Memory is ``K`` float16 values per pixel.

:func:`fit_descents` fits the circular-segment law (:mod:`shadowcam.outdoor.penumbra`) to
every descent, then refits, with the duration of their confident neighbours
(:func:`shadowcam.outdoor.penumbra.coherent_durations`), the pixels whose own fit is noisy
(uncertain centre) or whose ramp looks cut by the sequence's end: with the neighbours'
duration the ramp either ended by the last frame (the fit stands) or is shorter than the
sampling resolves (the crossing stands). Each pixel gets a state (:data:`RAMP_STATES`): ramps
shorter than the sampling resolves (``short``) keep the level crossing, and so do ramps whose
fit stays uncertain (a cloud's shade over the ramp) but agrees with the crossing within two
standard errors. A ramp still under way at the last frame whose centre the sequence saw
(the lit level and the descent's first half) is identifiable once its duration and its
shadow level are known: both are taken from the confident fits within the penumbra's width
in rows (the same sun behind the same skyline, the same shadowed ground), and only its
centre and lit level are fitted (``cut_centred``). Ramps whose centre is after the last
frame or that have no confident neighbours (``cut``) and uncertain fits that contradict the
crossing (``ambiguous``) get no time.

The law describes a straight skyline crossed at a constant speed; over a long penumbra the sun
moves along a sloping, curved skyline and a pixel's footprint may be reached in steps. With
the capture's shadow-to-lit ratio given (and the buffer keeping the exposure-normalised
luminance), a ramp that spans several frames and starts on its lit plateau is timed by the
crossing of its half level instead (:mod:`shadowcam.outdoor.half_level`, state
``half_level``): no law, only the lit level and the shadow level (its own plateau after the
ramp, or the lit level times the ratio). A ramp already under way at the start of its record
has no lit level of its own: its level crossing (read against a lit level that is too low) and
the law's fit of it (whose centre comes late) do not stand.

Its lit level follows from the physics: fully lit a pixel reads ``a (E cos i + sky)``,
fully shadowed ``a sky`` (``a`` its albedo), so its lit-to-shadow ratio depends on the surface's
orientation and the light, not on the albedo. Its neighbours on the same surface whose descents
start and end on plateaus give that ratio ``R`` (their median, within the penumbra's width in
rows), and the pixel's own shadow plateau ``S`` times ``R`` is its lit level: the crossing of
``S (1 + R) / 2`` times it (state ``neighbours_lit``), with the neighbours' spread of ``R``
carried into its standard error (``S spread / 2`` over the ramp's rate). A pixel with fewer than
:data:`MIN_RATIO_NEIGHBOURS` such neighbours or no shadow plateau of its own (``no_lit_level``), whose
neighbours' ratios spread too much for a time within ``max_sigma`` (``lit_ratio_spread``: not
one surface, or not one light), whose record starts below that half level (``before_record``:
the arrival came before the first frame), or whose crossing of it is unresolved or uncertain
beyond ``max_sigma`` with both levels known (``ambiguous``) gets no time.

Every step but the neighbours' duration and shadow level is per pixel; those read
``radius`` columns each side, within the halo of a column strip
(:mod:`shadowcam.outdoor.strips`), and ``radius`` or ``cut_rows`` rows (a strip holds
every row).

Offers
------
RAMP_STATES : ramp state code -> name.
DescentBuffer : the streaming record; :meth:`update` per frame, :meth:`series`.
fit_descents : per-pixel centre, duration, uncertainty and state of the final descent.
"""

import numpy as np

from shadowcam._shared.validation import check_positive
from shadowcam.outdoor.half_level import half_level_crossings, half_levels
from shadowcam.outdoor.penumbra import coherent_durations, fit_ramps, neighbour_median

#: ramp state code -> meaning
RAMP_STATES = {0: "none", 1: "short", 2: "fitted", 3: "neighbours_duration", 4: "cut", 5: "ambiguous",
               6: "cut_centred", 7: "half_level", 8: "neighbours_lit", 9: "no_lit_level", 10: "lit_ratio_spread",
               11: "before_record", 12: "clipped_crossing"}
STATE_CODE = {name: code for code, name in RAMP_STATES.items()}
#: states whose ramp centre is the arrival
TIMED_STATES = ("fitted", "neighbours_duration", "cut_centred", "half_level", "neighbours_lit")
#: states timed by the penumbra law's fit
LAW_STATES = [STATE_CODE[name] for name in ("fitted", "neighbours_duration", "cut_centred")]
#: pixels each side whose fitted durations steady a noisy ramp (:func:`fit_descents`)
NEIGHBOUR_RADIUS = 3
#: samples each side of the half level whose line gives the rate of a descent that does not start on its plateau
UNDER_WAY_WINDOW = 3
#: largest drop (share of the contrast) over the interval around a resolved ramp's centre: 4 / (pi 3)
RESOLVED_STEP = 4.0 / (np.pi * 3)
#: fewest neighbours whose lit-to-shadow ratios give a spread (:func:`fit_descents`)
MIN_RATIO_NEIGHBOURS = 3
#: pixels fitted at once (bounds the (N, K) float64 series gathered from the buffer)
_CHUNK = 4096


class DescentBuffer:
    """The last ``frames`` coverage values of every pixel, frozen into its final descent.

    Parameters
    ----------
    shape : tuple of int
        ``(H, W)``.
    frames : int, keyword-only
        ``K``: frames kept per pixel (even; ``K // 2`` each side of the crossing).
    luminance : bool, keyword-only
        Also keep the exposure-normalised luminance of the same frames (``K`` more float16
        values per pixel), whose levels give the half-level crossing
        (:mod:`shadowcam.outdoor.half_level`).
    """

    def __init__(self, shape, *, frames=128, luminance=False):
        shape = tuple(int(n) for n in shape)
        if int(frames) < 4:
            raise ValueError(f"frames must be >= 4; got {frames}")
        self.size = int(frames)
        self.values = np.full((self.size, *shape), np.nan, dtype=np.float16)
        self.luminance = np.full((self.size, *shape), np.nan, dtype=np.float16) if luminance else None
        self.count = np.zeros(shape, dtype=np.int32)  # consecutive frames held (<= K)
        self.last = np.full(shape, -1, dtype=np.int32)  # frame index of the newest value held
        self.frozen = np.zeros(shape, dtype=bool)
        self._dark_frames = np.zeros(shape, dtype=np.int32)
        self._k = 0

    def update(self, cover, *, dark, luminance=None):
        """Add the next frame's coverage ``(H, W)``; `dark` ``(H, W)`` marks the pixels in a dark episode.

        `luminance` ``(H, W)`` is the frame's exposure-normalised luminance (required when the
        buffer keeps it).
        """
        cover = np.asarray(cover)
        dark = np.asarray(dark, dtype=bool)
        if cover.shape != self.count.shape or dark.shape != self.count.shape:
            raise ValueError(f"cover {cover.shape} and dark {dark.shape} must have shape {self.count.shape}")
        if (self.luminance is not None) != (luminance is not None):
            raise ValueError("luminance must be given exactly when the buffer keeps it (DescentBuffer(luminance=True))")
        if luminance is not None and np.shape(luminance) != self.count.shape:
            raise ValueError(f"luminance {np.shape(luminance)} must have shape {self.count.shape}")
        k = self._k
        self._dark_frames = np.where(dark, self._dark_frames + 1, 0)
        restart = self.frozen & ~dark  # the episode ended: it was not the final one
        self.count[restart] = 0
        self.frozen &= dark
        write = ~self.frozen
        np.copyto(self.values[k % self.size], cover, where=write, casting="unsafe")
        if luminance is not None:
            np.copyto(self.luminance[k % self.size], luminance, where=write, casting="unsafe")
        self.count[write] = np.minimum(self.count[write] + 1, self.size)
        self.last[write] = k
        self.frozen |= dark & (self._dark_frames >= self.size // 2)
        self._k += 1

    def series(self, rows, cols, *, record="coverage"):
        """The held values of pixels ``(rows, cols)`` in time order.

        `record` is ``"coverage"`` or ``"luminance"`` (kept when the buffer was made with it).

        Returns
        -------
        values : (N, K) float64 ndarray
            NaN where nothing is held.
        frame : (N, K) int64 ndarray
            Frame index of each value (negative where nothing is held).
        """
        j = np.arange(self.size)
        last = self.last[rows, cols].astype(np.int64)[:, None]
        frame = last - (self.size - 1) + j[None, :]
        held = j[None, :] >= self.size - self.count[rows, cols][:, None]
        if record not in ("coverage", "luminance") or (record == "luminance" and self.luminance is None):
            raise ValueError(f"record must be 'coverage' or, kept with luminance=True, 'luminance'; got {record!r}")
        source = self.values if record == "coverage" else self.luminance
        values = source[np.mod(frame, self.size), rows[:, None], cols[:, None]].astype(np.float64)
        values[~held] = np.nan
        return values, np.where(held, frame, -1)


def _fit(buffer, rows, cols, time_s, centre, interval, duration=None, shadow=None, speed_change=False):
    out = []
    for a in range(0, rows.size, _CHUNK):
        s = slice(a, a + _CHUNK)
        values, frame = buffer.series(rows[s], cols[s])
        t = np.where(frame >= 0, time_s[np.maximum(frame, 0)], np.nan)
        out.append(fit_ramps(values, t, centre_s=centre[s], interval_s=interval,
                             duration_s=None if duration is None else duration[s],
                             shadow=None if shadow is None else shadow[s], speed_change=speed_change))
    return {key: np.concatenate([o[key] for o in out]) for key in out[0]} if out else None


def _half_level(buffer, time_s, centre, sigma, state, duration, *, shadow_ratio, limit, interval, window):
    """Time the ramps that span several frames and start on their lit plateau by their half level (in place).

    A ramp the law found shorter than the sampling resolves (``short``) is taken too when the
    two samples around its half-level crossing show that it is not: they drop by less than
    the disc law's ``4 / (pi n)`` of the contrast over an interval at its centre, ``n`` the
    law fit's ``min_samples`` (3). A resolved ramp (``short`` so taken, ``ambiguous`` or timed by
    the law) that was already under way at the start of its record has no lit level of its own
    (``no_lit_level``; the returned mask keeps the level crossing from standing in).

    The ramps under way at their start that end on their shadow plateau are then timed from
    their neighbours' lit-to-shadow ratio (:func:`_neighbours_lit`; `window` the neighbourhood's
    ``(rows, cols)`` half size).

    Returns
    -------
    (H, W) bool ndarray
        The ramps under way at the start of their record.
    """
    begun = np.zeros(state.shape, dtype=bool)
    ratio = np.full(state.shape, np.nan)  # lit over shadow level of the descents with both plateaus
    shadow = np.full(state.shape, np.nan)  # the shadow plateau of the descents under way at their start
    rows, cols = np.nonzero((state >= STATE_CODE["short"]) & (state <= STATE_CODE["half_level"]))
    for a in range(0, rows.size, _CHUNK):
        r, c = rows[a:a + _CHUNK], cols[a:a + _CHUNK]
        values, frame = buffer.series(r, c, record="luminance")
        t = np.where(frame >= 0, time_s[np.maximum(frame, 0)], np.nan)
        levels = half_levels(values, t, shadow_ratio=shadow_ratio)
        with np.errstate(invalid="ignore", divide="ignore"):
            both = levels["own_shadow"] & (levels["shadow"] > 0)
            ratio[r[both], c[both]] = levels["lit"][both] / levels["shadow"][both]
        probe = np.where(levels["lit_seen"], levels["half"], levels["lit"] - 0.5 * levels["contrast"])
        with np.errstate(invalid="ignore"):  # a line over an eighth of the fitted duration each side
            k = np.where(state[r, c] > STATE_CODE["short"], np.rint(0.125 * duration[r, c] / interval), 1)
        k = np.clip(np.nan_to_num(k, nan=1.0), 1, None).astype(np.int64)
        # a descent that does not start on its plateau: a wider line for its rate at the centre
        k = np.where(levels["lit_seen"], k, np.maximum(k, UNDER_WAY_WINDOW))
        crossing, error, step, rate = half_level_crossings(values, t, half_level=probe, half_window=k)
        with np.errstate(invalid="ignore"):
            long_ramp = step < RESOLVED_STEP * levels["contrast"]
        resolved = (state[r, c] > STATE_CODE["short"]) | long_ramp
        ok = levels["lit_seen"] & np.isfinite(crossing) & (error <= limit) & resolved
        centre[r[ok], c[ok]], sigma[r[ok], c[ok]] = crossing[ok], error[ok]
        state[r[ok], c[ok]] = STATE_CODE["half_level"]
        # under way at the record's start: descending there, and the ramp's duration at its centre
        # (the disc law's slope 4 / (pi D) of the contrast) reaches back to the start
        with np.errstate(invalid="ignore", divide="ignore"):
            reach = 4.0 / np.pi * levels["contrast"] / -rate
            first = np.nanmin(t, axis=1)
            under_way = levels["under_way"] & long_ramp & (crossing - first <= reach)
            own = under_way & levels["shadow_seen"] & (levels["shadow"] > 0)
        # such a ramp has no lit level of its own: the level crossing and the law's fit (its centre
        # comes late) do not stand; with its shadow plateau its neighbours' ratio may give one
        begun_here = under_way & np.isin(state[r, c], [STATE_CODE["short"], STATE_CODE["ambiguous"], *LAW_STATES])
        state[r[begun_here], c[begun_here]] = STATE_CODE["no_lit_level"]
        begun[r[begun_here], c[begun_here]] = True
        own &= begun_here
        shadow[r[own], c[own]] = levels["shadow"][own]
    _neighbours_lit(buffer, time_s, centre, sigma, state, duration, begun, ratio=ratio, shadow=shadow, limit=limit,
                    interval=interval, window=window)
    return begun


def _neighbours_lit(buffer, time_s, centre, sigma, state, duration, begun, *, ratio, shadow, limit, interval, window):
    """Time the descents under way at their record's start from their neighbours' lit-to-shadow ratio (in place).

    `ratio` ``(H, W)`` holds ``L / S`` of the descents with both plateaus seen (NaN elsewhere),
    `shadow` ``(H, W)`` the shadow plateau ``S`` of the descents under way at their start (NaN
    elsewhere). The arrival came before the record when the first sample is below the half level
    by more than twice its uncertainty; a descent that never crosses it otherwise has a ratio
    that does not hold (``lit_ratio_spread``). One that crosses it, but between two samples that
    do not resolve the ramp or with a standard error over `limit` not due to the ratio's spread
    alone, is ``ambiguous`` (its levels are known, its time is not).
    """
    rows, cols = np.nonzero(np.isfinite(shadow))
    if rows.size == 0:
        return
    median, spread, count = neighbour_median(ratio, np.isfinite(ratio), radius=window, at=(rows, cols), spread=True)
    known = (count >= MIN_RATIO_NEIGHBOURS) & np.isfinite(median)
    lone = ~known & begun[rows, cols]
    state[rows[lone], cols[lone]] = STATE_CODE["no_lit_level"]
    rows, cols, median, spread = rows[known], cols[known], median[known], spread[known]
    for a in range(0, rows.size, _CHUNK):
        s = slice(a, a + _CHUNK)
        r, c = rows[s], cols[s]
        values, frame = buffer.series(r, c, record="luminance")
        t = np.where(frame >= 0, time_s[np.maximum(frame, 0)], np.nan)
        low = shadow[r, c]
        lit = low * median[s]
        half = 0.5 * (lit + low)
        with np.errstate(invalid="ignore"):
            k = np.rint(0.125 * duration[r, c] / interval)
        k = np.maximum(np.nan_to_num(k, nan=1.0), UNDER_WAY_WINDOW).astype(np.int64)
        crossing, error, step, rate = half_level_crossings(values, t, half_level=half, half_window=k)
        first = values[np.arange(r.size), np.argmax(np.isfinite(values), axis=1)]
        level_error = 0.5 * low * spread[s]  # the half level's uncertainty from the neighbours' ratios
        with np.errstate(invalid="ignore", divide="ignore"):
            from_ratio = level_error / np.abs(rate)  # ... as time
            total = np.hypot(error, from_ratio)
            resolved = step < RESOLVED_STEP * (lit - low)
            crossed = np.isfinite(crossing)
            # never crossed: below the half level from the first sample by more than its uncertainty
            before = ~crossed & (first < half - 2.0 * level_error)
            ok = crossed & resolved & (total <= limit)
            spread_out = (crossed & resolved & (from_ratio > limit)) | (~crossed & ~before)
        # with its levels, a crossing that is unresolved or too uncertain is an ambiguous ramp
        untimed = begun[r, c] & ~ok
        state[r[untimed], c[untimed]] = STATE_CODE["ambiguous"]
        centre[r[ok], c[ok]], sigma[r[ok], c[ok]] = crossing[ok], total[ok]
        state[r[ok], c[ok]] = STATE_CODE["neighbours_lit"]
        state[r[spread_out], c[spread_out]] = STATE_CODE["lit_ratio_spread"]
        state[r[before], c[before]] = STATE_CODE["before_record"]


def fit_descents(buffer, crossing_s, time_s, *, max_sigma=1.0, radius=NEIGHBOUR_RADIUS, cut_rows=0, speed_change=False,
                 shadow_ratio=None):
    """Fit the penumbra law to every pixel's final descent.

    Parameters
    ----------
    buffer : DescentBuffer
        After the last frame.
    crossing_s : (H, W) ndarray
        Level crossing of the final dark episode (the fit's start; NaN: no final episode,
        no fit).
    time_s : (T,) ndarray
        Frame times (s).
    max_sigma : float, keyword-only
        Largest standard error of the centre, in median intervals, for a centre to be given.
    radius : int, keyword-only
        Neighbourhood of the duration's coherence (pixels each side).
    cut_rows : int, keyword-only
        Rows each side (at least `radius`; columns: `radius`) whose confident fits give a ramp
        cut by the sequence's end its duration and shadow level: the penumbra's width in rows
        (:func:`shadowcam.outdoor.strips.edge_width`), across which the cut ramps lie.
    speed_change : bool, keyword-only
        Fit the ramps whose duration is free with an edge speed that changes linearly over
        the ramp (:func:`shadowcam.outdoor.penumbra.fit_ramps`).
    shadow_ratio : float, optional, keyword-only
        The capture's shadow-to-lit ratio (the first pass's). Given (with a buffer that keeps
        the luminance), the ramps the law was fitted to (not ``short``) that start on their
        lit plateau are timed by their half-level crossing instead
        (:mod:`shadowcam.outdoor.half_level`; state ``half_level``), when its standard
        error is at most `max_sigma` intervals.

    Returns
    -------
    dict of (H, W) ndarray
        ``ramp_centre_s`` (NaN unless state fitted / neighbours_duration / cut_centred / half_level),
        ``ramp_duration_s``,
        ``ramp_sigma_s`` (float32) and ``ramp_state`` (uint8, :data:`RAMP_STATES`).
    """
    crossing = np.asarray(crossing_s, dtype=np.float64)
    time_s = np.asarray(time_s, dtype=np.float64)
    if crossing.shape != buffer.count.shape:
        raise ValueError(f"crossing_s {crossing.shape} must have the buffer's shape {buffer.count.shape}")
    check_positive(max_sigma, "max_sigma")
    shape = crossing.shape
    centre = np.full(shape, np.nan)
    duration = np.full(shape, np.nan)
    sigma = np.full(shape, np.inf)
    state = np.zeros(shape, dtype=np.uint8)
    rows, cols = np.nonzero(np.isfinite(crossing) & (buffer.count > 0))
    interval = float(np.median(np.diff(time_s))) if time_s.size > 1 else 1.0
    out = {"ramp_centre_s": centre.astype(np.float32), "ramp_duration_s": duration.astype(np.float32),
           "ramp_sigma_s": np.full(shape, np.nan, np.float32), "ramp_state": state}
    if rows.size == 0:
        return out
    fit = _fit(buffer, rows, cols, time_s, crossing[rows, cols], interval, speed_change=speed_change)
    end = time_s[-1]
    limit = max_sigma * interval
    cut = fit["centre_s"] + 0.5 * fit["duration_s"] > end + 0.5 * interval
    short = ~fit["resolved"]
    confident = fit["resolved"] & ~cut & (fit["sigma_s"] <= limit)
    centre[rows, cols], duration[rows, cols], sigma[rows, cols] = fit["centre_s"], fit["duration_s"], fit["sigma_s"]
    state[rows, cols] = np.select([short, cut, confident], [STATE_CODE["short"], STATE_CODE["cut"],
                                                          STATE_CODE["fitted"]], STATE_CODE["ambiguous"])
    good = np.zeros(shape, dtype=bool)
    good[rows, cols] = confident
    first_duration = duration.copy()
    first_shadow = np.full(shape, np.nan)
    first_shadow[rows, cols] = fit["shadow"]
    neighbours = coherent_durations(duration, good, radius=radius)
    nbr = neighbours[rows, cols]
    # the neighbours' duration (the same sun behind the same skyline) steadies a noisy ramp, and
    # decides a ramp the sequence's end cut: if the neighbours' ramp would have ended by then the
    # fit with their duration stands, or, shorter than the sampling resolves, the crossing does
    redo = np.isfinite(nbr) & ~confident & ~short
    if redo.any():
        r, c = rows[redo], cols[redo]
        refit = _fit(buffer, r, c, time_s, crossing[r, c], interval, duration=nbr[redo])
        ended = refit["centre_s"] + 0.5 * nbr[redo] <= end + 0.5 * interval
        ok = refit["resolved"] & (refit["sigma_s"] <= limit) & ended
        too_short = ~refit["resolved"] & (crossing[r, c] + 0.5 * nbr[redo] <= end + 0.5 * interval)
        centre[r, c] = np.where(ok, refit["centre_s"], centre[r, c])
        duration[r, c] = nbr[redo]
        sigma[r, c] = np.where(ok, refit["sigma_s"], sigma[r, c])
        was_cut = state[r, c] == STATE_CODE["cut"]
        state[r, c] = np.select([ok, too_short, was_cut], [STATE_CODE["neighbours_duration"], STATE_CODE["short"],
                                                           STATE_CODE["cut"]], STATE_CODE["ambiguous"])
    # a ramp the sequence's end cut after its centre (the lit level and the descent's first half
    # seen): the duration and the shadow level are its confident neighbours' (the same sun behind
    # the same skyline, the same ground in shadow), and only the centre and the lit level are fitted
    cut = state[rows, cols] == STATE_CODE["cut"]
    if cut.any():
        r, c = rows[cut], cols[cut]
        window = (max(int(cut_rows), int(radius)), int(radius))
        nbr_duration = coherent_durations(first_duration, good, radius=window, at=(r, c))
        nbr_shadow = neighbour_median(first_shadow, good, radius=window, at=(r, c))
        known = np.isfinite(nbr_duration) & np.isfinite(nbr_shadow)
        if known.any():
            r, c = r[known], c[known]
            refit = _fit(buffer, r, c, time_s, crossing[r, c], interval, duration=nbr_duration[known],
                         shadow=nbr_shadow[known])
            seen = refit["centre_s"] <= end
            ok = refit["resolved"] & (refit["sigma_s"] <= limit) & seen
            centre[r[ok], c[ok]] = refit["centre_s"][ok]
            duration[r[ok], c[ok]] = nbr_duration[known][ok]
            sigma[r[ok], c[ok]] = refit["sigma_s"][ok]
            state[r[ok], c[ok]] = STATE_CODE["cut_centred"]
    # a ramp that starts on its lit plateau: the crossing of its half level needs no law
    begun = None
    if shadow_ratio is not None:
        begun = _half_level(buffer, time_s, centre, sigma, state, duration, shadow_ratio=shadow_ratio, limit=limit,
                            interval=interval, window=(max(int(cut_rows), int(radius)), int(radius)))
    # an uncertain fit that does not contradict the level crossing (within two standard
    # errors) leaves it standing; one that does, or a ramp under way at its record's start
    # (the crossing's lit level is then too low), gives no time
    with np.errstate(invalid="ignore"):
        agrees = (state == STATE_CODE["ambiguous"]) & (np.abs(centre - crossing) <= 2.0 * sigma)
    if begun is not None:
        agrees &= ~begun
    state[agrees] = STATE_CODE["short"]
    keep = np.isin(state, [STATE_CODE[name] for name in TIMED_STATES])
    out["ramp_centre_s"] = np.where(keep, centre, np.nan).astype(np.float32)
    out["ramp_duration_s"] = np.where(state > 0, duration, np.nan).astype(np.float32)
    out["ramp_sigma_s"] = np.where(state > 0, sigma, np.nan).astype(np.float32)
    out["ramp_state"] = state
    return out
