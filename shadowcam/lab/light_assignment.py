"""Assigning each pixel's minima to the lights that cast them (paper Fig. 11).

With ``L`` lights, the wire's shadows from each light pass a pixel in an order set
by where the lights sit along the sweep, and that order is the same at
neighbouring pixels: minimum k of a pixel with exactly ``L`` minima is light k's.
Spatial continuity checks it: light k's time map is smooth across a surface, so
a time further than `tolerance` from the median of its light's times at the
neighbouring pixels (a spurious dip, another light's shadow, or a depth edge
where the order cannot be checked) is ``ambiguous_order``.
Pixels with another number of minima (a light hidden from the point, two
shadows merged, a spurious dip) get ``minima_count``, except minima that match
exactly one light's neighbourhood within `tolerance`, which are kept. The order is
taken only from seeds the neighbourhood confirms light by light: a neighbour denies a
seed's time where its own seed puts that light elsewhere (its own time, or its nearest
light's shifted by the median gaps), or where it has no seed and sees no minimum at a
time inside the sweep (a shadow passing there would have been seen).

A dip is timed over a window around its minimum's place. Under the sweep's
Poisson-Gaussian noise (:mod:`shadowcam.lab.sensor_noise`) that window is the shadow's
only where no sample so far from the minimum that the window around it would miss the
dip could have been as deep by noise alone (:func:`place_noise_probability`): a long shallow shadow (a tube lying along
the wire: a few percent of the light over many frames) has a floor whose noise minima fall anywhere on
it. A time whose probability exceeds `false_alarm` is ``unresolved_dip`` (over any continuity
flag: its place is not measured, so neither is its agreement). A light whose
resolved dips in a sweep are no more than noise alone gives at `false_alarm` (the
binomial upper `false_alarm` quantile over the pixels its shadow crosses) is not shown by
that sweep: ``shown`` is False and its times that passed are ``unresolved_dip`` too.

Offers
------
LIGHT_REASONS : reason code -> meaning, per light and pixel.
assign_minima : :class:`~shadowcam.lab.minima.Minima` -> per-light time maps, contrast,
    confidence and reasons.
light_summary : per-light contrast, coverage and reason counts.
place_noise_probability : probability that noise alone makes a sample far from a dip's minimum as deep.
"""

import warnings

import numpy as np
from scipy.special import ndtr, ndtri
from scipy.stats import binom

from shadowcam._shared.validation import check_in_interval, check_positive
from shadowcam.lab import minima as _m

#: reason code -> meaning, per light and pixel (0 = a reliable time)
LIGHT_REASONS = {
    0: "ok",
    1: "minima_count",
    2: "low_contrast",
    3: "ambiguous_order",
    4: "overlapping",
    5: "dip_at_sweep_end",
    6: "invalid_input",
    7: "wide_dip",
    8: "unresolved_dip",
}
OK, MINIMA_COUNT, LOW_CONTRAST, AMBIGUOUS_ORDER, OVERLAPPING, AT_END, INVALID, WIDE, UNRESOLVED = range(9)
_FROM_MINIMUM = {_m.OK: OK, _m.MISSING: MINIMA_COUNT, _m.LOW_CONTRAST: LOW_CONTRAST,
                 _m.OVERLAPPING: OVERLAPPING, _m.AT_END: AT_END, _m.INVALID: INVALID, _m.WIDE: WIDE}


def _neighbour_median(time, radius):
    """Median of the finite times within `radius` pixels (the pixel itself excluded), (L, H, W);
    in row bands with a `radius`-row halo (bounding the neighbours' stack)."""
    out = np.empty(time.shape)
    height = time.shape[1]
    for rows in _m.row_bands(*time.shape[1:]):
        top, bottom = max(rows.start - radius, 0), min(rows.stop + radius, height)
        out[:, rows] = _band_neighbour_median(time[:, top:bottom], radius)[:, rows.start - top:rows.stop - top]
    return out


def _band_neighbour_median(time, radius):
    """:func:`_neighbour_median` of one block of rows (its outside NaN)."""
    stack = np.stack([other for _, _, other in _neighbour_views(time, radius, np.nan)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmedian(stack, axis=0)


def _neighbour_views(values, radius, fill):
    """Each neighbour offset within `radius` pixels (the pixel itself excluded) and `values`
    (..., H, W) at that neighbour of every pixel (`fill` beyond the image): (dy, dx, (..., H, W))."""
    lead = ((0, 0),) * (values.ndim - 2)
    pad = np.pad(values, lead + ((radius, radius), (radius, radius)), constant_values=fill)
    rows, cols = values.shape[-2:]
    for dy in range(-radius, radius + 1):
        for dx in range(-radius, radius + 1):
            if dy or dx:
                yield dy, dx, pad[..., radius + dy:radius + dy + rows, radius + dx:radius + dx + cols]


def _local_slopes(time, radius):
    """Each light's time step per pixel along x and y: the median differences of adjacent
    pixels within `radius` (0 where none), two (L, H, W)."""
    step_x = np.concatenate([np.diff(time, axis=2), np.full(time[:, :, :1].shape, np.nan)], axis=2)
    step_y = np.concatenate([np.diff(time, axis=1), np.full(time[:, :1].shape, np.nan)], axis=1)
    return tuple(np.nan_to_num(_neighbour_median(d, radius)) for d in (step_x, step_y))


def _agreement(time, tolerance, radius):
    """Neighbours with a time for the same light, and those within `tolerance` of the pixel's
    time carried to them along the local slope (:func:`_local_slopes`), (L, H, W)."""
    slope_x, slope_y = _local_slopes(time, radius)
    total = np.zeros(time.shape)
    agree = np.zeros(time.shape)
    with np.errstate(invalid="ignore"):
        for dy, dx, other in _neighbour_views(time, radius, np.nan):
            total += np.isfinite(other)
            agree += np.abs(other - time - slope_x * dx - slope_y * dy) <= tolerance
    return total, agree


def _gaps(time, measured=None):
    """Median time from light k to light k + 1 over the pixels with both, (L - 1,); where no
    pixel has both, `measured` ((L - 1,), the gaps of the seeds before their confirmation),
    else NaN."""
    out = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        for k in range(time.shape[0] - 1):
            out.append(float(np.nanmedian(time[k + 1] - time[k])))
    out = np.array(out)
    return out if measured is None else np.where(np.isfinite(out), out, measured)


def _from_nearest_light(time, gaps):
    """Each light's time where it has one, else the nearest light's (fewest gaps away; the
    earlier at a tie) shifted by the median `gaps` between them; and the number of gaps
    crossed (0 = its own, -1 = none), (L, H, W) each."""
    offset = np.concatenate([[0.0], np.cumsum(gaps)])
    out = time.copy()
    crossed = np.where(np.isfinite(time), 0, -1)
    n = time.shape[0]
    for k in range(n):
        for distance in range(1, n):
            for j in (k - distance, k + distance):
                if 0 <= j < n and np.isfinite(offset[k] - offset[j]):
                    fill = ~np.isfinite(out[k]) & np.isfinite(time[j])
                    out[k][fill] = time[j][fill] + offset[k] - offset[j]
                    crossed[k][fill] = distance
    return out, crossed


def _predict(time, radius, gaps):
    """Each light's expected time at each pixel: its neighbours' median, else the nearest
    light's neighbours' median shifted by the median gaps between them, (L, H, W)."""
    return _from_nearest_light(_neighbour_median(time, radius), gaps)[0]


def _match(estimate, predicted, tolerance, gaps, timed):
    """Each light's minimum: the significant minimum nearest its prediction within
    `tolerance`, taken by no nearer light; two matched `timed` minima ((K, H, W) bool) of
    lights k < j must differ by the median gaps between them (`gaps`, (L - 1,)) within
    ``(j - k) tolerance``, else the one further from its prediction is dropped; -1 where
    none. `estimate` (K, H, W), NaN = not significant; `predicted` (L, H, W)."""
    with np.errstate(invalid="ignore"):
        distance = np.abs(estimate[None] - predicted[:, None])  # (L, K, H, W)
    distance = np.where(np.isfinite(distance) & (distance <= tolerance), distance, np.inf)
    best = np.argmin(distance, axis=1)  # (L, H, W)
    best_distance = np.min(distance, axis=1)
    pick = np.where(np.isfinite(best_distance), best, -1)
    # a minimum claimed by two lights goes to the nearer one (lights are more than
    # 2 tolerance apart wherever both predictions hold, so this is rare)
    for k in range(pick.shape[0]):
        for j in range(pick.shape[0]):
            if j != k:
                lose = (pick[k] >= 0) & (pick[k] == pick[j]) & (best_distance[j] < best_distance[k])
                pick[k][lose] = -1
    if np.all(np.isfinite(gaps)):
        offset = np.concatenate([[0.0], np.cumsum(gaps)])
        time = np.where(_gather(timed, pick) == 1, _gather(estimate, pick), np.nan)
        with np.errstate(invalid="ignore"):
            for k in range(pick.shape[0]):
                for j in range(k + 1, pick.shape[0]):
                    off = np.abs(time[j] - time[k] - (offset[j] - offset[k])) > (j - k) * tolerance
                    drop_k = off & (best_distance[k] >= best_distance[j])
                    pick[k][drop_k], time[k][drop_k] = -1, np.nan
                    pick[j][off & ~drop_k], time[j][off & ~drop_k] = -1, np.nan
    return pick


def _gather(values, pick):
    """``values[pick[k], y, x]`` per light, NaN where ``pick < 0``; (L, H, W)."""
    index = np.maximum(pick, 0)
    out = np.take_along_axis(values, index, 0).astype(np.float64)
    return np.where(pick >= 0, out, np.nan)


def _spaced(seed, estimate, gaps, tolerance):
    """Seeds whose consecutive lights' times lie the median `gaps` ((L - 1,)) apart within
    `tolerance`: the shadows of lights k and k + 1 pass a point one light spacing apart, so a
    seed that gives them two minima further off (a spurious dip beside a real one) is dropped."""
    time = _gather(estimate, seed)
    with np.errstate(invalid="ignore"):
        off = np.abs(np.diff(time, axis=0) - np.asarray(gaps)[:, None, None]) > tolerance
    return np.where(off.any(axis=0)[None], -1, seed)


def _confirmed(seed, estimate, timed, gaps, n_frames, tolerance, radius):
    """Per light, the seeds their neighbours confirm; a seed a neighbourhood denies in one
    light is dropped whole.

    A seed gives light k the time t of a `timed` minimum at a pixel; carried to a neighbour
    within `radius` along the local slope of light k's seed times (:func:`_local_slopes`) it
    is t'. A seeded neighbour holds a time for light k too: its own, or its nearest seeded
    light's shifted by the median `gaps` (outside the sweep where its seed leaves light k
    out). It confirms where that time lies within ``tolerance (1 + gaps crossed)`` of t' and
    denies otherwise: the seeds' assignments of minima to lights must agree. A neighbour
    without a seed denies where t' lies inside the sweep and none of its significant minima
    lies within `tolerance` of t' (a shadow passing there would have been seen; one cut by
    the sweep's first or last frame is still a significant minimum), else says nothing.
    More denials than confirmations: that minimum is no light's (a spurious dip one gap
    from a real one, spurious dips side by side where no shadow falls), so the pixel's
    minima are not its lights in order and its whole seed goes. As many: that light's part
    goes, the others stand. A minimum that is not `timed` (wide,
    overlapping, cut by the sweep) has no time to judge: its part goes, the others stand,
    and the propagation may give it back.

    Parameters
    ----------
    seed : (L, H, W) int ndarray
        Index of each light's minimum, -1 = none.
    estimate : (K, H, W) float ndarray
        The minima's times, NaN = not significant.
    timed : (K, H, W) bool ndarray
        Minima whose time is the dip's (``reason`` ok).
    gaps : (L - 1,) float ndarray
    n_frames : int
    tolerance : float
    radius : int

    Returns
    -------
    (L, H, W) int ndarray
        `seed` with the parts not confirmed set to -1, and the pixels with a denied part all -1.
    """
    time = np.where(_gather(timed, seed) == 1, _gather(estimate, seed), np.nan)
    held, crossed = _from_nearest_light(time, gaps)
    unseeded = ~np.isfinite(time).any(axis=0)
    held = np.where(unseeded[None], np.nan, held)
    allowed = np.where(crossed >= 0, tolerance * (1.0 + crossed), np.nan)
    slope_x, slope_y = _local_slopes(time, radius)
    views = zip(_neighbour_views(held, radius, np.nan), _neighbour_views(allowed, radius, np.nan),
                _neighbour_views(unseeded, radius, False), _neighbour_views(estimate, radius, np.nan))
    confirm = np.zeros(time.shape)
    deny = np.zeros(time.shape)
    with np.errstate(invalid="ignore"):
        for (dy, dx, other), (_, _, other_allowed), (_, _, other_unseeded), (_, _, other_minima) in views:
            carried = time + slope_x * dx + slope_y * dy
            miss = np.abs(other - carried)
            confirm += miss <= other_allowed
            deny += miss > other_allowed
            seen = np.zeros(time.shape, bool)
            for minimum in other_minima:
                seen |= np.abs(minimum[None] - carried) <= tolerance
            inside = (carried >= 0) & (carried <= n_frames - 1)
            deny += other_unseeded[None] & inside & ~seen
    denied = (deny > confirm).any(axis=0)
    return np.where((confirm > deny) & ~denied[None], seed, -1)


def _propagate(seed, estimate, timed, radius, tolerance, iterations, measured):
    """Seeds grown by continuity: per light, the prediction from the neighbours and the
    matching of each pixel's minima to it (:func:`_match`), repeated until nothing
    changes; a light no seed kept is predicted from the others by the `measured` gaps
    ((L - 1,)); (L, H, W)."""
    pick = seed
    for _ in range(int(iterations)):
        time = _gather(estimate, pick)
        gaps = _gaps(time, measured)
        predicted = _predict(time, radius, gaps)
        matched = _match(estimate, predicted, tolerance, gaps, timed)
        # a seed stands unless its neighbours give one of its minima to another light;
        # a pixel with no prediction at all (isolated) keeps its seed's order
        moved = ((matched >= 0) & (matched != seed)).any(axis=0)
        keep = (seed >= 0).all(axis=0) & ~moved | ~np.isfinite(predicted).any(axis=0)
        new = np.where(keep[None], seed, matched)
        if np.array_equal(new, pick):
            break
        pick = new
    return pick


def _seed_partial(seed, estimate, gaps, n_frames, tolerance, *, informative):
    """Seeds also where fewer than L significant minima lie in order and exactly one way of
    giving them to consecutive lights puts every other light's shadow outside the sweep.

    With ``m < L`` minima, shift ``s`` gives minimum ``i`` (along the sweep) to light
    ``s + i``; the missing lights' times follow from the nearest of the minima by the
    median gaps. A
    shift is excluded when a missing light whose absence is `informative` ((L,) bool: the
    light is seen in most pixels its shadow crosses) has its time inside the sweep by more
    than `tolerance` (its shadow would have been seen there). A light hidden from the
    point (a missing minimum between two others) leaves no shift or several: no seed.
    """
    n_lights = seed.shape[0]
    if n_lights < 2 or not np.all(np.isfinite(gaps)):
        return seed
    offset = np.concatenate([[0.0], np.cumsum(gaps)])
    order = np.argsort(np.where(np.isfinite(estimate), estimate, np.inf), axis=0, kind="stable")
    times = np.take_along_axis(estimate, order, 0)  # finite first, along the sweep
    m = np.isfinite(times).sum(axis=0)
    out = seed.copy()
    for count in range(1, n_lights):
        at = (m == count) & (seed < 0).all(axis=0)
        if not at.any():
            continue
        first, last = times[0], times[count - 1]  # the earliest and latest minima
        feasible = []
        for shift in range(n_lights - count + 1):
            inside = np.zeros(at.shape, bool)
            for k in list(range(shift)) + list(range(shift + count, n_lights)):
                if not informative[k]:
                    continue
                with np.errstate(invalid="ignore"):
                    # from the nearest assigned minimum: the shortest extrapolation
                    if k < shift:
                        t = first - (offset[shift] - offset[k])
                    else:
                        t = last + offset[k] - offset[shift + count - 1]
                    inside |= (t > tolerance) & (t < n_frames - 1 - tolerance)
            feasible.append(~inside)
        feasible = np.stack(feasible)
        unique = at & (feasible.sum(axis=0) == 1)
        shift = np.argmax(feasible, axis=0)
        for k in range(n_lights):
            i = k - shift
            take = unique & (i >= 0) & (i < count)
            out[k][take] = np.take_along_axis(order, np.clip(i, 0, count - 1)[None], 0)[0][take]
    return out


def place_noise_probability(window, noise, *, tolerance, width=None):
    """Probability that noise alone makes a sample far from a dip's minimum as deep as it:
    that the minimum's place, and the window timed around it, are noise's.

    The minimum sits at the window's centre slot (``S // 2`` samples each side). Had noise
    put it ``r`` frames away, the window around it would still hold the dip's half-depth
    span (`width`) while ``r <= S // 2 - width / 2``: those samples, and all within
    `tolerance` frames, are near; its depth is their deepest. A far sample ``d`` above that
    depth (the difference's noise standard deviation ``sqrt(2) noise``) reaches it by
    noise with probability ``Q(d / (sqrt(2) noise))``; the probability that any far
    sample does is ``1 - prod(1 - Q)``. A sharp dip's far samples lie at the lit level,
    many noise deviations up (about 0); a shadow whose floor is longer than the window
    allows has far floor samples within the noise of its minimum (near 1).

    Parameters
    ----------
    window : (S, ...) array_like
        Samples around each minimum (S odd, the minimum at ``S // 2``), in the units of
        `noise` (e.g. normalised by the lit level); NaN = not the dip's (cut, outside).
    noise : (...) array_like
        Standard deviation of one sample (0 = noise-free: a far sample as deep counts 1/2).
    tolerance : float
        Frames within which the minimum's place is its own.
    width : (...) array_like, optional
        The dip's half-depth width in frames (NaN or None: only `tolerance`).

    Returns
    -------
    (...) float64 ndarray
        In [0, 1]; NaN where the minimum's slot is not finite.
    """
    window = np.asarray(window, np.float64)
    check_positive(tolerance, "tolerance", finite=True)
    if window.ndim < 1 or window.shape[0] % 2 != 1:
        raise ValueError(f"window must have an odd number of samples along axis 0; got shape {window.shape}")
    noise = np.broadcast_to(np.asarray(noise, np.float64), window.shape[1:])
    offset = np.abs(np.arange(window.shape[0]) - window.shape[0] // 2).reshape((-1,) + (1,) * (window.ndim - 1))
    half = window.shape[0] // 2
    own = np.full(window.shape[1:], float(tolerance))
    if width is not None:
        spare = half - 0.5 * np.broadcast_to(np.asarray(width, np.float64), window.shape[1:])
        own = np.fmax(own, np.where(np.isfinite(spare), spare, -np.inf))
    far = offset > own[None]
    near = np.where(~far & np.isfinite(window), window, np.inf)
    bottom = np.min(near, axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        above = window - bottom[None]
        exact = np.where(above > 0, np.inf, np.where(above < 0, -np.inf, 0.0))  # noise-free
        z = np.where(noise[None] > 0, above / (np.sqrt(2.0) * noise[None]), exact)
    # a far sample reaches the minimum's depth by noise with Q(z); none does with prod(1 - Q)
    reached = np.where(far & np.isfinite(window), ndtr(-z), 0.0)
    out = -np.expm1(np.sum(np.log1p(-np.minimum(reached, 1.0 - 1e-16)), axis=0))
    return np.where(np.isfinite(window[window.shape[0] // 2]), out, np.nan)


def _place(window, noise, pick, contrast, width, *, tolerance, false_alarm):
    """:func:`place_noise_probability` of each light's minimum `pick` (L, h, W) from the minima's
    normalised windows (S, K, h, W) and noise (K, h, W); 1 where it cannot be judged."""
    index = np.maximum(pick, 0)
    window = np.take_along_axis(window, index[None], 1)
    noise = np.take_along_axis(np.asarray(noise, np.float64), index, 0)
    # the half-depth span is the dip's own only where no sample of the window reaches
    # half the depth by noise (at false_alarm); else it is noise's and not used
    with np.errstate(invalid="ignore", divide="ignore"):
        crossings_own = contrast / (2.0 * noise) > -ndtri(false_alarm / window.shape[0])
    width = np.where(crossings_own, width, np.nan)
    return np.nan_to_num(place_noise_probability(window, noise, tolerance=tolerance, width=width), nan=1.0)


def _shown(resolved, crossed, false_alarm):
    """Per light: its resolved dips are more than noise alone gives, (L,) bool.

    `resolved` (L, H, W): pixels with a resolved timed dip; `crossed` (L, H, W): the pixels
    the light's shadow crosses inside the sweep. Noise alone resolves a share of at most
    `false_alarm` of them; more than its binomial upper `false_alarm` quantile is the light.
    """
    n = crossed.sum(axis=(1, 2))
    limit = binom.isf(false_alarm, np.maximum(n, 1), false_alarm)
    return resolved.sum(axis=(1, 2)) > limit


def assign_minima(minima, n_lights, *, radius=2, tolerance=2.0, iterations=None, false_alarm=1e-3):
    """Per-light shadow times from each pixel's minima, checked by spatial continuity.

    Seeds are the pixels with exactly `n_lights` significant minima whose gaps agree with
    the image's median gaps between the lights (within `tolerance`): minimum k is light
    k's; a light's part of a seed stands where its neighbours confirm it more than they deny
    it, and a part they deny drops the pixel's whole seed (:func:`_confirmed`). Then,
    `iterations` times, each light's time is predicted at every pixel from its
    neighbours (median within `radius`; where light k has no neighbours, another light's
    median shifted by the median gap between them) and each pixel's significant minima
    go to the light whose prediction lies within `tolerance` (the nearest): a minimum
    that disagrees with its neighbours by whole inter-light gaps is re-assigned to the
    light the neighbours make unambiguous, or left unassigned. A light with no minimum
    is ``minima_count``; a pixel with no neighbours keeps its seed's order; a time further
    than `tolerance` from its light's neighbourhood, or that at most half of the
    neighbours with a time for that light confirm (within `tolerance` along the local
    slope; an isolated time included), is ``ambiguous_order``.

    Parameters
    ----------
    minima : Minima
        From :func:`shadowcam.lab.minima.find_minima` with ``count >= n_lights``.
    n_lights : int
    radius : int
        Neighbourhood (pixels) of the continuity check.
    tolerance : float
        Frames a time may differ from its light's neighbourhood median.
    iterations : int, optional
        Most passes of the prediction and matching (each grows the assigned regions by
        about `radius` pixels); default until nothing changes, at most ``max(H, W)``.
    false_alarm : float
        Probability, per pixel and light, that noise alone places a timed dip's minimum
        (``unresolved_dip`` above it, :func:`place_noise_probability`), and that a light
        whose dips the sweep cannot resolve is taken as shown. The rate of
        :func:`~shadowcam.lab.minima.find_minima`'s detection: one rate for every test.

    Returns
    -------
    dict of str to ndarray
        ``time`` (L, H, W): NaN where the reason is not ok; ``contrast`` (L, H, W): the
        minimum's depth over the lit level; ``time_std`` (L, H, W); ``reason`` (L, H, W)
        int8 (:data:`LIGHT_REASONS`); ``minimum`` (L, H, W) int64: the index of the
        light's minimum in `minima` (-1 where none); ``seen`` (L,): the fraction of the
        pixels where the light's shadow is predicted inside the sweep in which its minimum
        is timed (before the partial seeds); ``confidence`` (L, H, W) in [0, 1], 0 where
        flagged: the probability that the time is light k's shadow, as the product of
        ``(1 - Q(depth_snr)) ** n_frames`` (noise alone makes no minimum this deep anywhere
        in the sweep), ``1 -`` :func:`place_noise_probability` (no sample far from it
        reaches its depth by noise) and ``(a + 1) / (n + 2)`` (the neighbours
        agree: ``a`` of the ``n`` neighbours with a time for light k lie within
        `tolerance` of it; the posterior mean under a uniform prior); ``shown`` (L,) bool:
        the sweep shows the light's dip (its resolved dips are more than noise alone gives).
    """
    if int(n_lights) != n_lights or n_lights < 1:
        raise ValueError(f"n_lights must be an integer >= 1; got {n_lights!r}")
    n_lights = int(n_lights)
    if minima.time.shape[0] < n_lights:
        raise ValueError(f"minima: found with count={minima.time.shape[0]} < n_lights={n_lights}; "
                         "find at least one minimum per light")
    check_positive(tolerance, "tolerance", finite=True)
    check_in_interval(false_alarm, "false_alarm", 0, 1, closed="neither")
    radius = int(radius)
    iterations = max(minima.count.shape) if iterations is None else int(iterations)
    significant = (minima.reason != _m.MISSING) & (minima.reason != _m.LOW_CONTRAST)
    estimate = np.where(significant, minima.estimate, np.nan)
    ordered = (minima.count == n_lights) & (minima.extra_contrast == 0)
    # seeds: the k-th significant minimum along the sweep is light k's
    rank = np.argsort(~significant, axis=0, kind="stable")[:n_lights]
    seed = np.where(ordered[None], rank, -1)
    gaps = _gaps(_gather(estimate, seed))
    timed_minima = minima.reason == _m.OK
    seed = _confirmed(_spaced(seed, estimate, gaps, tolerance), estimate, timed_minima, gaps, minima.n_frames,
                      tolerance, radius)
    pick = _propagate(seed, estimate, timed_minima, radius, tolerance, iterations, gaps)
    # a light seen in most pixels where its shadow falls inside the sweep: its absence
    # there is evidence, and seeds pixels with fewer minima (:func:`_seed_partial`)
    time = _gather(estimate, pick)
    predicted = _predict(time, radius, _gaps(time, gaps))
    with np.errstate(invalid="ignore"):
        inside = (predicted > tolerance) & (predicted < minima.n_frames - 1 - tolerance)
    timed = (pick >= 0) & (np.take_along_axis(minima.reason, np.maximum(pick, 0), 0) == _m.OK)
    seen = (inside & timed).sum(axis=(1, 2)) / np.maximum(inside.sum(axis=(1, 2)), 1)
    partial = _spaced(_seed_partial(seed, estimate, gaps, minima.n_frames, tolerance, informative=seen > 0.5),
                      estimate, gaps, tolerance)
    # the confirmed seeds stand; the partial ones are put to the same vote, among all
    seed = np.where(seed >= 0, seed,
                    _confirmed(partial, estimate, timed_minima, gaps, minima.n_frames, tolerance, radius))
    pick = _propagate(seed, estimate, timed_minima, radius, tolerance, iterations, gaps)
    time = _gather(estimate, pick)
    total, agree = _agreement(time, tolerance, radius)
    median = _neighbour_median(time, radius)
    to_light = np.vectorize(_FROM_MINIMUM.get, otypes=[np.int8])
    own = np.take_along_axis(minima.reason, np.maximum(pick, 0), 0)
    reason = np.where(pick >= 0, to_light(own), MINIMA_COUNT).astype(np.int8)
    with np.errstate(invalid="ignore"):
        jump = (pick >= 0) & (np.abs(time - median) > tolerance)
    # a time most of its light's neighbours do not confirm is not checked by continuity
    # (an isolated time included): flagged, not guessed
    reason[jump | ((reason == OK) & (2 * agree <= total))] = AMBIGUOUS_ORDER
    contrast, std, snr = (_gather(a, pick) for a in (minima.contrast, minima.time_std, minima.depth_snr))
    place = np.zeros(pick.shape)
    if minima.summary is not None:
        width = _gather(minima.width, pick)
        for rows in _m.row_bands(*pick.shape[1:]):  # per pixel: in row bands, bounding the temporaries
            place[:, rows] = _place(minima.summary.window[:, :, rows], minima.summary.noise[:, rows], pick[:, rows],
                                    contrast[:, rows], width[:, rows], tolerance=tolerance, false_alarm=false_alarm)
    # a minimum whose place noise could have set is not a measured time, whatever its
    # neighbours say: unresolved before (and over) any continuity flag
    reason[(pick >= 0) & (own == _m.OK) & (place > false_alarm)] = UNRESOLVED
    shown = _shown(reason == OK, inside | (pick >= 0), false_alarm)
    reason[~shown[:, None, None] & (reason == OK)] = UNRESOLVED
    ok = reason == OK
    with np.errstate(invalid="ignore", over="ignore"):
        # no minimum this deep from noise anywhere in the sweep: (1 - Q(snr)) ** n_frames
        real = np.exp(minima.n_frames * np.log1p(-ndtr(-np.where(np.isfinite(snr), snr, np.inf))))
    confidence = real * (1.0 - place) * (agree + 1.0) / (total + 2.0)
    return {"time": np.where(ok, time, np.nan), "contrast": contrast, "time_std": std,
            "confidence": np.where(ok, confidence, 0.0), "reason": reason, "minimum": pick,
            "seen": seen, "shown": shown}


def light_summary(assigned, *, valid=None):
    """Per-light median contrast, coverage and reason counts.

    Parameters
    ----------
    assigned : dict
        From :func:`assign_minima`.
    valid : (H, W) bool ndarray, optional
        Pixels to count (default all).

    Returns
    -------
    list of dict
        One per light: ``contrast`` (median over its found minima), ``coverage`` (fraction
        of `valid` pixels timed), ``reasons`` (name -> pixel count).
    """
    reason = assigned["reason"]
    valid = np.ones(reason.shape[1:], bool) if valid is None else np.asarray(valid, bool)
    out = []
    for k in range(reason.shape[0]):
        c = assigned["contrast"][k][valid]
        out.append({"contrast": float(np.nanmedian(c)) if np.isfinite(c).any() else float("nan"),
                    "coverage": float(np.mean(reason[k][valid] == OK)) if valid.any() else 0.0,
                    "reasons": {name: int(np.sum(reason[k][valid] == code))
                                for code, name in LIGHT_REASONS.items()}})
    return out
