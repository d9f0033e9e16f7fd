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
exactly one light's neighbourhood within `tolerance`, which are kept.

Offers
------
LIGHT_REASONS : reason code -> meaning, per light and pixel.
assign_minima : :class:`~shadowcam.lab.minima.Minima` -> per-light time maps, contrast,
    confidence and reasons.
light_summary : per-light contrast, coverage and reason counts.
"""

import warnings

import numpy as np

from shadowcam._shared.validation import check_positive
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
}
OK, MINIMA_COUNT, LOW_CONTRAST, AMBIGUOUS_ORDER, OVERLAPPING, AT_END, INVALID, WIDE = range(8)
_FROM_MINIMUM = {_m.OK: OK, _m.MISSING: MINIMA_COUNT, _m.LOW_CONTRAST: LOW_CONTRAST,
                 _m.OVERLAPPING: OVERLAPPING, _m.AT_END: AT_END, _m.INVALID: INVALID, _m.WIDE: WIDE}


def _neighbour_median(time, radius):
    """Median of the finite times within `radius` pixels (the pixel itself excluded), (L, H, W)."""
    pad = np.pad(time, ((0, 0), (radius, radius), (radius, radius)), constant_values=np.nan)
    rows, cols = time.shape[1:]
    stack = np.stack([pad[:, radius + dy:radius + dy + rows, radius + dx:radius + dx + cols]
                      for dy in range(-radius, radius + 1) for dx in range(-radius, radius + 1)
                      if dy or dx])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmedian(stack, axis=0)


def assign_minima(minima, n_lights, *, radius=2, tolerance=2.0):
    """Per-light shadow times from each pixel's minima.

    Parameters
    ----------
    minima : Minima
        From :func:`shadowcam.lab.minima.find_minima` with ``count >= n_lights``.
    n_lights : int
    radius : int
        Neighbourhood (pixels) of the continuity check.
    tolerance : float
        Frames a time may differ from its light's neighbourhood median.

    Returns
    -------
    dict of str to ndarray
        ``time`` (L, H, W): NaN where the reason is not ok; ``contrast`` (L, H, W): the
        minimum's depth over the lit level; ``time_std`` (L, H, W); ``confidence`` (L, H, W)
        in [0, 1]: how far the dip's depth exceeds the detection level (0 where flagged);
        ``reason`` (L, H, W) int8 (:data:`LIGHT_REASONS`).
    """
    if int(n_lights) != n_lights or n_lights < 1:
        raise ValueError(f"n_lights must be an integer >= 1; got {n_lights!r}")
    n_lights = int(n_lights)
    if minima.time.shape[0] < n_lights:
        raise ValueError(f"minima: found with count={minima.time.shape[0]} < n_lights={n_lights}; "
                         "find at least one minimum per light")
    check_positive(tolerance, "tolerance", finite=True)
    shape = minima.count.shape
    significant = (minima.reason != _m.MISSING) & (minima.reason != _m.LOW_CONTRAST)
    ordered = (minima.count == n_lights) & (minima.extra_contrast == 0)
    # the k-th significant minimum along the sweep is light k's
    rank = np.argsort(~significant, axis=0, kind="stable")
    time = np.full((n_lights, *shape), np.nan)
    reason = np.full((n_lights, *shape), MINIMA_COUNT, np.int8)
    pick = np.full((n_lights, *shape), -1, np.int64)
    to_light = np.vectorize(_FROM_MINIMUM.get, otypes=[np.int8])
    for k in range(n_lights):
        index = rank[k]
        own = np.take_along_axis(minima.reason, index[None], 0)[0]
        reason[k] = np.where(ordered, to_light(own), MINIMA_COUNT)
        pick[k] = np.where(ordered, index, -1)
        time[k] = np.where(ordered & (reason[k] == OK),
                           np.take_along_axis(minima.time, index[None], 0)[0], np.nan)
    median = _neighbour_median(time, int(radius))
    # continuity: a time further than `tolerance` from its light's neighbourhood
    with np.errstate(invalid="ignore"):
        jump = np.abs(time - median) > tolerance
    reason[jump] = AMBIGUOUS_ORDER
    time[jump] = np.nan
    # pixels with another number of minima: keep a minimum matching exactly one light's
    # neighbourhood, growing from the ordered pixels until nothing changes
    for _ in range(max(shape)):
        median = _neighbour_median(time, int(radius))
        changed = False
        with np.errstate(invalid="ignore"):
            for m in range(minima.time.shape[0]):
                t = minima.time[m]
                near = np.abs(t[None] - median) <= tolerance
                unique = (near.sum(axis=0) == 1) & ~ordered & np.isfinite(t)
                light = np.argmax(near, axis=0)
                for k in range(n_lights):
                    take = unique & (light == k) & (reason[k] == MINIMA_COUNT)
                    if take.any():
                        reason[k][take], pick[k][take], time[k][take] = OK, m, t[take]
                        changed = True
        if not changed:
            break
    rows, cols = np.indices(shape)

    def gather(values):
        out = np.full((n_lights, *shape), np.nan)
        for k in range(n_lights):
            has = pick[k] >= 0
            out[k][has] = values[pick[k][has], rows[has], cols[has]]
        return out

    est, contrast, std, depth = (gather(a) for a in (minima.time, minima.contrast, minima.time_std,
                                                       minima.depth))
    ok = reason == OK
    with np.errstate(invalid="ignore", divide="ignore"):
        snr = gather(minima.depth_snr)
        confidence = np.clip(snr / minima.significance - 1.0, 0.0, 1.0)
    return {"time": np.where(ok, est, np.nan), "contrast": contrast, "time_std": std,
            "confidence": np.where(ok, np.nan_to_num(confidence, nan=1.0), 0.0), "reason": reason}


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
