"""The arrival as the crossing of a pixel's half level: half the sun's disc hidden.

A pixel's exposure-normalised luminance is ``S + (L - S) v``: the sky light ``S`` (the level
with the sun fully hidden) plus the direct sun ``L - S`` (``L`` the level with it unhidden)
times the disc's visible fraction ``v``. The arrival, half the disc hidden, is when the
luminance is at the half level ``(L + S) / 2``: no law of the ramp's shape is needed (the
sun's clearance over a sloping, curved skyline changes rate over the ramp; a pixel's footprint
may be reached in two steps), only the two levels. The photometry's normalisation holds the
lit level steady over the sequence (the sun's fading and the exposure are divided out), so
both are constants of the pixel.

* :func:`end_level`: the level at an end of a pixel's final descent, the mean of its first
  (or last) samples, and whether it is a plateau: their line's slope is within ``z`` standard
  errors of zero. A ramp already under way at the start of the record descends there.
* :func:`half_levels`: the half level of the pixels whose lit level is a plateau; the shadow
  level is the pixel's own where its descent ends on a plateau below the lit level, else the
  lit level times the capture's shadow-to-lit ratio (sky over sun irradiance; the albedo
  cancels in it), whose error moves the half level by only half its share of ``L``.
* :func:`half_level_crossings`: the last downward crossing of the half level, refined by a
  line over ``+-k`` samples around it (the caller's ``k``: an eighth of the ramp's duration,
  over which the disc's law keeps its centre rate to 3 %, ``sqrt(1 - u^2) >= 0.968`` for
  ``|u| <= 1/4``, while the ramp's speed may differ between its halves), with its standard
  error from the line's residual.

Offers
------
end_level : the level and the plateau test at the start or the end of descents.
half_levels : half level of each descent whose lit level was seen.
half_level_crossings : crossing time of a half level and its standard error.
"""

import numpy as np

from shadowcam._shared.validation import check_array, check_in, check_in_interval, check_positive
from shadowcam.outdoor.ramp_kernels import end_level_pixels, half_level_pixels

#: samples at an end of a descent whose mean and slope give its level and the plateau test
END_SAMPLES = 10
#: standard errors of the end samples' slope within which they are a plateau
PLATEAU_Z = 2.0


def _contiguous(values, time_s):
    """`values` and `time_s` (broadcast to its shape) as C-contiguous float64 (N, K) arrays."""
    y = np.ascontiguousarray(check_array(values, "values", ndim=2), dtype=np.float64)
    t = np.broadcast_to(np.asarray(time_s, dtype=np.float64), y.shape)
    if t.shape != y.shape:
        raise ValueError(f"time_s must have shape {y.shape} or ({y.shape[1]},); got {np.shape(time_s)}")
    return y, np.ascontiguousarray(t)


def _series(values, time_s):
    y, t = _contiguous(values, time_s)
    return np.where(np.isfinite(t), y, np.nan), t


def _check_end(side, samples, z):
    check_in(side, "side", ("start", "end"))
    if int(samples) < 3:
        raise ValueError(f"samples must be >= 3; got {samples}")
    check_positive(z, "z", finite=True)


def _end_levels(y, t, side, samples, z):
    """(level, plateau, slope, lowest sample) at one end of each row of `y` (times `t`; both contiguous)."""
    level, slope, low, plateau = end_level_pixels(t, y, int(samples), float(z) ** 2, side == "end")
    return level, plateau, slope, low


def end_level(values, time_s, *, side, samples=END_SAMPLES, z=PLATEAU_Z):
    """The level at one end of each pixel's descent and whether it is a plateau.

    Parameters
    ----------
    values : (N, K) ndarray
        Exposure-normalised luminance of N pixels' final descents; NaN where unknown.
    time_s : (N, K) or (K,) ndarray
        Times of the samples (s).
    side : {"start", "end"}, keyword-only
        The first or the last `samples` finite samples.
    samples : int, keyword-only
        Samples averaged (at least 3; fewer held: no level).
    z : float, keyword-only
        A plateau's line slope is within `z` standard errors of zero.

    Returns
    -------
    level : (N,) float64 ndarray
        Mean of the samples (NaN with fewer than `samples`).
    plateau : (N,) bool ndarray
    slope : (N,) float64 ndarray
        Their line's slope (per s).
    """
    _check_end(side, samples, z)
    return _end_levels(*_contiguous(values, time_s), side, samples, z)[:3]


def half_levels(values, time_s, *, shadow_ratio, samples=END_SAMPLES, z=PLATEAU_Z):
    """Half level ``(L + S) / 2`` of each descent whose lit level was seen as a plateau.

    Parameters
    ----------
    values : (N, K) ndarray
    time_s : (N, K) or (K,) ndarray
        As :func:`end_level`.
    shadow_ratio : float, keyword-only
        The capture's shadow-to-lit ratio ``S / L`` (in [0, 1)), for descents that do not end
        on a plateau below their lit level.
    samples, z : keyword-only
        As :func:`end_level`.

    Returns
    -------
    dict of (N,) ndarray
        ``half`` (NaN where the descent does not start on a plateau), ``lit`` (the start's level), ``contrast`` (``L - S``;
        where the start is no plateau, from its level, a lower bound), ``lit_seen`` (bool: the
        descent starts on a plateau), ``under_way`` (bool: it starts descending, every start
        sample above the half level of the start's mean and the shadow level: the ramp had
        begun) and ``own_shadow`` (bool: the shadow level is the pixel's own, its descent ends
        on a plateau), ``shadow`` (the end's level) with ``shadow_seen`` (bool: the descent
        ends on a plateau).
    """
    check_in_interval(shadow_ratio, "shadow_ratio", 0.0, 1.0, closed="left")
    _check_end("start", samples, z)
    y, t = _contiguous(values, time_s)
    lit, lit_seen, lit_slope, lowest = _end_levels(y, t, "start", samples, z)
    shadow, shadow_seen, _, _ = _end_levels(y, t, "end", samples, z)
    with np.errstate(invalid="ignore"):
        own = shadow_seen & lit_seen & (shadow < lit)
    level = np.where(own | (~lit_seen & shadow_seen), shadow, float(shadow_ratio) * lit)
    half = 0.5 * (lit + level)
    with np.errstate(invalid="ignore"):
        under_way = ~lit_seen & (lit_slope < 0) & (lowest > half)
    return {"half": np.where(lit_seen, half, np.nan), "lit": lit, "contrast": lit - level, "lit_seen": lit_seen,
            "under_way": under_way, "own_shadow": own, "shadow": shadow, "shadow_seen": shadow_seen}


def half_level_crossings(values, time_s, *, half_level, half_window):
    """The last downward crossing of each pixel's half level, refined by a local line.

    Parameters
    ----------
    values : (N, K) ndarray
    time_s : (N, K) or (K,) ndarray
        As :func:`end_level`.
    half_level : (N,) ndarray
        NaN: no crossing.
    half_window : int or (N,) int ndarray, keyword-only
        ``k``: the line runs over the ``k`` finite samples each side of the crossing (at least 1).

    Returns
    -------
    crossing_s : (N,) float64 ndarray
        NaN where the half level is unknown or never crossed downward.
    sigma_s : (N,) float64 ndarray
        Standard error of the crossing from the line's residual (inf where the line through
        the samples does not descend: the crossing between the two samples is given).
    step : (N,) float64 ndarray
        The drop between the two samples around the crossing (a ramp shorter than an
        interval drops by its whole contrast there).
    slope : (N,) float64 ndarray
        The line's slope (per s; the two samples' where it does not descend).
    """
    y, t = _series(values, time_s)
    n = y.shape[0]
    level = np.asarray(half_level, dtype=np.float64).reshape(-1)
    if level.shape != (n,):
        raise ValueError(f"half_level must have shape ({n},); got shape {np.shape(half_level)}")
    k = np.broadcast_to(np.asarray(half_window), (n,)).astype(np.int64)
    if np.any(k < 1):
        raise ValueError("half_window must be >= 1")
    return half_level_pixels(np.ascontiguousarray(t), y, np.ascontiguousarray(level), np.ascontiguousarray(k))
