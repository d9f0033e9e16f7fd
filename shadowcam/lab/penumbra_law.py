"""The dip of a straight wire edge sweeping an extended source, and its fit to a pixel's dip.

A wire whose shadow edge sweeps the line of sight to an extended source at a constant
speed hides, at frame t, the part of the source within its strip: in frames along the
sweep, the source's points ``centre + x`` (x in ``[-extent, extent]``) are hidden while
``|t - centre - x| < width / 2``. With ``S`` the share of the source below a coordinate
(its brightness profile across the sweep direction integrated: a uniform disc or sphere
gives circular segments, a uniform line source a box), the hidden share is

    F(t) = S((t - centre + width / 2) / extent) - S((t - centre - width / 2) / extent)

and the pixel's signal ``lit - (lit - full) F(t)``. A pixel's footprint spreads its
points' times about the centre's by ``spread`` frames (standard deviation): the signal is
F averaged over the two times ``t -+ spread`` (the symmetric two-point kernel of that
variance; exact for two sub-samples along the sweep). The fit
(:func:`fit_penumbra_law`) finds centre, extent and width by damped Gauss-Newton on the
samples from the grid start's best points, with lit and full (>= 0) solved exactly (linear)
at each step, pixel by pixel in :mod:`shadowcam.lab.penumbra_kernels`: first contact
``centre - width/2 - extent`` and last release ``centre + width/2 + extent`` (the
source's extreme points seen through the wire's edges) and the half-hidden crossings
follow from the shape, and a dip without umbra gets its full-occlusion level.

Offers
------
PROFILES : source profiles -> share of the source below a normalised coordinate.
disc_share_below : share of the unit disc below a coordinate (circular segment).
hidden_share : F(t) of the law, with the footprint's two-point spread.
GRID_EXTENT_RATIOS, GRID_WIDTH_RATIOS : the fit's grid start, in units of the starting width.
fit_penumbra_law : per pixel, the law's parameters from the samples of its dip.
law_edges : first contact, last release and the half-hidden crossings of fitted laws.
dips_are_wide : whether a sweep's dips are wider than the tracker's window (the law applies).
choose_profile : the source profile (disc or box) whose law fits a sweep's dips best.
penumbra_edges : a sweep's outer edges and half-hidden crossings from the law (one read of
    the frames for its wide dips).
"""

import logging
from dataclasses import dataclass

import numpy as np

from shadowcam._shared.validation import check_in
from shadowcam.lab.dip_classification import OK
from shadowcam.lab.penumbra_kernels import fit_laws

log = logging.getLogger(__name__)


def disc_share_below(z):
    """Share of the unit disc's area whose first coordinate is below `z` (any shape array).

    ``1/2 + (z sqrt(1 - z^2) + asin z) / pi`` in [-1, 1], 0 below, 1 above.
    """
    z = np.clip(np.asarray(z, dtype=np.float64), -1.0, 1.0)
    return 0.5 + (z * np.sqrt(1.0 - z * z) + np.arcsin(z)) / np.pi


def _box_share_below(z):
    """Share of a uniform segment [-1, 1] below `z`."""
    return np.clip(0.5 * (np.asarray(z, dtype=np.float64) + 1.0), 0.0, 1.0)


#: source profile across the sweep -> share of the source below a coordinate in units of
#: its half extent (a disc or a sphere: circular segments; a tube: a box)
PROFILES = {"disc": disc_share_below, "box": _box_share_below}


def hidden_share(t, centre, extent, width, *, spread=0.0, profile="disc"):
    """Share of the source the wire hides at frames `t` (broadcast arrays).

    Parameters
    ----------
    t : array_like
        Frames.
    centre : array_like
        Frame the wire's middle passes the source's centre.
    extent : array_like
        Half extent of the source along the sweep, in frames (> 0).
    width : array_like
        The wire's shadow width, in frames (> 0).
    spread : array_like, optional
        Standard deviation of the footprint's times about its centre's (frames).
    profile : {"disc", "box"}, optional

    Returns
    -------
    ndarray
        In [0, 1], the broadcast shape.
    """
    check_in(profile, "profile", tuple(PROFILES))
    below = PROFILES[profile]
    t, centre, extent, width, spread = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64)
                                                             for a in (t, centre, extent, width, spread)))
    total = 0.0
    for side in (-1.0, 1.0):
        lag = t + side * spread - centre
        total = total + below((lag + 0.5 * width) / extent) - below((lag - 0.5 * width) / extent)
    return 0.5 * total


@dataclass(frozen=True)
class LawFit:
    """Fitted laws of N pixels' dips.

    Attributes
    ----------
    centre, extent, width : (N,) float64 ndarray
        Frames (see :func:`hidden_share`); NaN where not fitted.
    lit, full : (N,) float64 ndarray
        The signal with nothing hidden and with the whole source hidden.
    rms : (N,) float64 ndarray
        Root mean square residual of the fit.
    covariance : (N, 3, 3) float64 ndarray
        Of (centre, extent, width), from the residual's variance and the fit's Jacobian.
    profile : str
    """

    centre: np.ndarray
    extent: np.ndarray
    width: np.ndarray
    lit: np.ndarray
    full: np.ndarray
    rms: np.ndarray
    covariance: np.ndarray
    profile: str = "disc"


#: the fit's grid start: extents and widths in proportion to the starting (half-depth) width
GRID_EXTENT_RATIOS = np.geomspace(0.03, 1.2, 12)
GRID_WIDTH_RATIOS = np.linspace(0.2, 1.3, 12)


def fit_penumbra_law(times, samples, *, centre, width, spread=0.0, profile="disc", iterations=40, converged=1e-10,
                     starts=2):
    """Fit the law of :func:`hidden_share` to each pixel's dip samples.

    Parameters
    ----------
    times : (N, K) array_like
        Frames of the samples (NaN: no sample).
    samples : (N, K) array_like
        The pixels' signal at `times`, covering the dip and some lit frames either side.
    centre, width : (N,) array_like
        Starting centre and width (e.g. the half-depth interval's middle and length).
    spread : float or (N,) array_like, optional
        Footprint spread in frames (:func:`hidden_share`).
    profile : {"disc", "box"}, optional
    iterations : int, optional
        Most damped Gauss-Newton steps after a coarse grid of extents and widths.
    converged : float, optional
        The steps stop once one moves every parameter by less than this, relative to
        ``max(1, |parameter|)`` (0: all `iterations`).
    starts : int, optional
        The grid's best points refined, the lowest residual reached kept.

    Returns
    -------
    LawFit
    """
    check_in(profile, "profile", tuple(PROFILES))
    times = np.asarray(times, dtype=np.float64)
    samples = np.asarray(samples, dtype=np.float64)
    valid = np.isfinite(times) & np.isfinite(samples)
    n = len(times)
    spread = np.broadcast_to(np.asarray(spread, dtype=np.float64), (n,))
    params, lit, full, sum_squares, normal = fit_laws(
        np.ascontiguousarray(times), np.ascontiguousarray(samples), np.ascontiguousarray(valid),
        np.ascontiguousarray(centre, dtype=np.float64),
        np.maximum(np.asarray(width, dtype=np.float64), 0.5), np.ascontiguousarray(spread),
        profile == "box", GRID_EXTENT_RATIOS, GRID_WIDTH_RATIOS, int(iterations), 1e-3, float(converged), int(starts))
    count = valid.sum(1)
    rms = np.sqrt(sum_squares / np.maximum(count, 1))
    # five parameters (lit and full solved inside): the residual's variance per sample
    variance = sum_squares / np.maximum(count - 5, 1)
    covariance = np.linalg.pinv(normal) * variance[:, None, None]
    fitted = count >= 6
    nan = np.where(fitted, 1.0, np.nan)
    return LawFit(centre=params[:, 0] * nan, extent=params[:, 1] * nan, width=params[:, 2] * nan,
                  lit=lit * nan, full=full * nan, rms=rms * nan, covariance=covariance * nan[:, None, None],
                  profile=profile)


def law_edges(fit, *, share=0.5, iterations=50):
    """First contact, last release and the crossings of a hidden `share` of fitted laws.

    Parameters
    ----------
    fit : LawFit
    share : float, optional
        Hidden share of the crossings (0.5: half the source hidden), at the pixel's centre
        (no footprint spread).
    iterations : int, optional
        Bisection steps of the crossings.

    Returns
    -------
    dict of (N,) float64 ndarray
        ``first`` (centre - width/2 - extent), ``last`` (centre + width/2 + extent),
        ``entry``, ``exit`` (the law at the pixel's centre crossing `share`; NaN where it
        never hides that much), ``first_std``, ``last_std`` (from the fit's covariance).
    """
    reach = 0.5 * fit.width + fit.extent
    peak = hidden_share(fit.centre, fit.centre, fit.extent, fit.width, profile=fit.profile)
    crossings = []
    for side in (-1.0, 1.0):
        inside, outside = fit.centre.copy(), fit.centre + side * reach
        for _ in range(iterations):
            middle = 0.5 * (inside + outside)
            above = hidden_share(middle, fit.centre, fit.extent, fit.width, profile=fit.profile) > share
            inside, outside = np.where(above, middle, inside), np.where(above, outside, middle)
        crossings.append(np.where(peak > share, 0.5 * (inside + outside), np.nan))
    outer = np.array([1.0, 1.0, 0.5])  # d(last)/d(centre, extent, width); first: (1, -1, -1/2)
    first_std = np.sqrt(np.einsum("i,nij,j->n", outer * [1, -1, -1], fit.covariance, outer * [1, -1, -1]))
    last_std = np.sqrt(np.einsum("i,nij,j->n", outer, fit.covariance, outer))
    return {"first": fit.centre - reach, "last": fit.centre + reach, "entry": crossings[0], "exit": crossings[1],
            "first_std": first_std, "last_std": last_std}


def dips_are_wide(entry, exit_, timed, half_window):
    """True when the sweep's median half-depth dip width exceeds `half_window` frames.

    A planar sweep gives every point it shadows the same width, so the median says
    whether the dips (with their penumbrae, about as wide again) outgrow the tracker's
    ``2 half_window + 1``-frame window: a thin wire under a point light (about 2 frames)
    does not, a wire under an extended source or a slow sweep does.
    """
    width = (exit_ - entry)[timed & np.isfinite(entry) & np.isfinite(exit_)]
    return width.size > 0 and float(np.median(width)) > half_window


def _dip_samples(blocks, rows, cols, first, count):
    """(N, K) signal (channels summed) of the pixels at frames ``first + k``, k < count
    (NaN beyond a pixel's count or the sweep), and their frames, from one pass."""
    size = int(count.max(initial=0))
    samples = np.full((len(rows), size), np.nan, dtype=np.float32)
    start = 0
    for block in blocks:
        block = np.asarray(block)
        signal = block[:, rows, cols] if block.ndim == 3 else block[:, rows, cols].sum(axis=-1)
        for k in range(len(block)):
            offset = start + k - first
            inside = np.flatnonzero((offset >= 0) & (offset < count))
            samples[inside, offset[inside]] = signal[k, inside]
        start += len(block)
    frames = first[:, None] + np.arange(size)[None]
    return np.where(np.isfinite(samples), frames, np.nan), samples


def choose_profile(times, samples, *, centre, width, spread, max_pixels=256):
    """The source profile whose law fits a sweep's dips best: the least median residual
    over up to `max_pixels` of them, evenly spread (every point of a sweep sees the same
    source, so one profile serves the sweep).

    Parameters
    ----------
    times, samples : (N, K) ndarray
    centre, width, spread : (N,) ndarray
        As :func:`fit_penumbra_law`.
    max_pixels : int, optional

    Returns
    -------
    str
        A key of :data:`PROFILES`.
    """
    pick = np.unique(np.linspace(0, len(times) - 1, min(len(times), max_pixels)).round().astype(np.intp))
    scores = {name: np.nanmedian(fit_penumbra_law(times[pick], samples[pick], centre=centre[pick],
                                                  width=width[pick], spread=spread[pick], profile=name).rms)
              for name in PROFILES}
    return min(scores, key=lambda name: (not np.isfinite(scores[name]), scores[name]))


def penumbra_edges(read, results, *, n_frames, half_window, footprint_variance=None, profile=None):
    """Outer edges and half-hidden crossings of a sweep's wide dips from the law.

    Each timed pixel's samples from its half-depth entry less half the width (and 2
    frames) to its exit plus as much (within the sweep) are read once and fitted
    (:func:`fit_penumbra_law`, starting from the half-depth interval); the footprint
    spread is ``sqrt(footprint_variance) |grad shadow_time|`` (0 when undeclared), the
    profile the one that fits the sweep best unless given. Only
    where the sweep's dips are wide (:func:`dips_are_wide`), on the pixels timed ``ok``
    (a dip cut by the sweep has no law fit); a pixel whose fit fails (non-finite, full not
    below lit, centre outside its samples) keeps no edges and its crossings.

    Parameters
    ----------
    read : callable
        ``read()`` -> the sweep's ``(T, H, W[, C])`` blocks in time order from frame 0.
    results : dict of (H, W) ndarray
        A sweep's shadow times with the interval (:func:`shadowcam.lab.shadow_time.shadow_times`).
    n_frames, half_window : int
    footprint_variance : float or (H, W) array_like, optional
        Per-axis second moment of a pixel's footprint, px^2 (per pixel: a RAW sweep's
        channel sum adds its demosaic taps').
    profile : {"disc", "box"}, optional
        Default: the one that fits the sweep best (:func:`choose_profile`).

    Returns
    -------
    dict of (H, W) float32 ndarray
        Empty when the dips are not wide; else ``penumbra_first``, ``penumbra_last`` and
        their ``*_std``, and ``interval_entry``, ``interval_exit`` with the law's
        half-hidden crossings where it was fitted.
    """
    entry, exit_ = results["interval_entry"].astype(np.float64), results["interval_exit"].astype(np.float64)
    timed = results["reason"] == OK
    if not dips_are_wide(entry, exit_, timed, half_window):
        return {}
    width = exit_ - entry
    chosen = timed & np.isfinite(width)
    first = np.clip(np.floor(np.where(chosen, entry - 0.5 * width - 2.0, 0.0)), 0, n_frames - 1)
    last = np.clip(np.ceil(np.where(chosen, exit_ + 0.5 * width + 2.0, 0.0)), 0, n_frames - 1)
    rows, cols = np.nonzero(chosen)
    first_frame = first[rows, cols].astype(np.int64)
    times, samples = _dip_samples(read(), rows, cols, first_frame, (last[rows, cols] - first_frame + 1).astype(np.int64))
    gradient = np.hypot(*np.gradient(results["shadow_time"].astype(np.float64)))
    gradient = np.where(np.isfinite(gradient), gradient, np.nanmedian(gradient) if np.isfinite(gradient).any() else 0.0)
    variance = np.broadcast_to(np.asarray(0.0 if footprint_variance is None else footprint_variance, np.float64),
                               entry.shape)
    spread = np.sqrt(variance[rows, cols]) * gradient[rows, cols]
    centre, width = 0.5 * (entry + exit_)[rows, cols], width[rows, cols]
    if profile is None and len(rows):
        profile = choose_profile(times, samples, centre=centre, width=width, spread=spread)
    fit = fit_penumbra_law(times, samples, centre=centre, width=width, spread=spread, profile=profile or "disc")
    log.info("penumbra law (%s profile) fitted to %d wide dips", fit.profile, len(rows))
    edges = law_edges(fit)
    good = (np.isfinite(edges["first"]) & np.isfinite(edges["last"]) & (fit.full < fit.lit)
            & (fit.centre > first_frame) & (fit.centre < last[rows, cols]))
    out = {key: np.full(entry.shape, np.nan) for key in ("penumbra_first", "penumbra_last",
                                                         "penumbra_first_std", "penumbra_last_std")}
    for key, value in (("penumbra_first", edges["first"]), ("penumbra_last", edges["last"]),
                       ("penumbra_first_std", edges["first_std"]), ("penumbra_last_std", edges["last_std"])):
        out[key][rows[good], cols[good]] = value[good]
    crossing = good & np.isfinite(edges["entry"]) & np.isfinite(edges["exit"])
    out["interval_entry"], out["interval_exit"] = entry.copy(), exit_.copy()
    out["interval_entry"][rows[crossing], cols[crossing]] = edges["entry"][crossing]
    out["interval_exit"][rows[crossing], cols[crossing]] = edges["exit"][crossing]
    return {key: value.astype(np.float32) for key, value in out.items()}
