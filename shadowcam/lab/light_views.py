"""One shadow camera per light from a capture lit by several lights (paper Fig. 11).

Each sweep's minima are found (:func:`shadowcam.lab.minima.find_minima`) and assigned to
the lights (:func:`shadowcam.lab.light_assignment.assign_minima`) in the order the lights
sit along the wire's motion (the capture's ``light_along_*``: a light further along the
motion needs the wire further along to shadow a point, so later), checked against the
lights' positions measured from the median gaps between their shadows; which u light is
which v light is measured from the lights' contrast maps (:func:`match_sweep_lights`; the
description, when given, is checked against it); light k's shadow
times of the u and v sweeps are its dual coordinates (uniform wire motion: the frame is
the dual coordinate), and the reference image resampled there is the dual view from
light k.

Offers
------
light_positions : the lights' positions along a sweep from the gaps between their shadows.
match_sweep_lights : which u-sweep light is which v-sweep light, from their contrast maps.
pair_sweep_lights : the v sweep's lights put in the u sweep's order (measured, or checked).
check_light_order : those positions against the capture's ``light_along_<sweep>``.
sweep_light_times : one sweep's frames -> its minima assigned to the lights, their positions.
light_views_dataset : per-light shadow times of both sweeps -> the dataset with the dual views.
light_set_views : a several-lights capture in memory -> per-light shadow times, reasons,
    contrast, confidence and dual views.
view_attrs : the options of the views as the dataset's attrs.
light_set_errors : per-light, per-sweep absolute time errors on the scored pixels.
light_set_accuracy : per-light, per-sweep error and coverage against the renderer.
"""

import itertools
import warnings
from dataclasses import fields, replace

import numpy as np
import xarray as xr
from scipy.special import ndtri

from shadowcam._shared.validation import check_array, check_positive
from shadowcam.cameras.dual_view import resample_dual_view
from shadowcam.lab.light_assignment import LIGHT_REASONS, OK, assign_minima
from shadowcam.lab.shadow_time_methods import SHADOW_TIME_METHODS
from shadowcam.lab.site_signal import cfa_site_colours
from shadowcam.lab.minima import find_minima

SWEEPS = ("u", "v")


def light_positions(time, *, min_pixels=20):
    """The lights' positions along a sweep, in frames, measured from their shadows.

    Parameters
    ----------
    time : (L, H, W) array_like
        Per-light shadow times in the order of the shadows along the sweep (NaN = untimed),
        as :func:`shadowcam.lab.light_assignment.assign_minima` gives them.
    min_pixels : int
        Pixels with both lights timed below which a gap is not measured.

    Returns
    -------
    position : (L,) float64 ndarray
        0 for the first light, then the running sum of the median gaps between
        consecutive lights (NaN after a gap that is not measured).
    spread : (L - 1,) float64 ndarray
        Median absolute deviation of each gap over the pixels (frames).
    """
    time = np.asarray(time, dtype=np.float64)
    gaps, spread = [], []
    for k in range(time.shape[0] - 1):
        gap = (time[k + 1] - time[k])[np.isfinite(time[k + 1]) & np.isfinite(time[k])]
        enough = gap.size >= int(min_pixels)
        gaps.append(float(np.median(gap)) if enough else np.nan)
        spread.append(float(np.median(np.abs(gap - np.median(gap)))) if enough else np.nan)
    return np.concatenate([[0.0], np.cumsum(gaps)]), np.array(spread)


def check_light_order(position, spread, light_along, *, sweep, tolerance=2.0, seen=None):
    """Check the lights' positions along a sweep from the data against the capture description.

    Shadows of lights at one height move with the wire in proportion to the lights'
    offsets along the sweep, so the measured gaps between consecutive lights (frames) are
    a scaled copy of the described ones (metres, sorted along the sweep). The scale is
    the least-squares fit over the gaps measured consistently (spread across the pixels
    within `tolerance`, between two lights each `seen` in most pixels its shadow crosses: a
    gap from noise minima is not); a gap further than `tolerance`
    frames from its scaled description means the description's positions (or their order)
    are not the capture's. Needs three lights or more (two give one gap, which any scale
    fits); lights swapped between equally spaced positions are not seen.

    Parameters
    ----------
    position : (L,) array_like
        From :func:`light_positions`.
    spread : (L - 1,) array_like
        From :func:`light_positions`.
    light_along : (L,) array_like
        The capture's ``light_along_<sweep>``, per light.
    sweep : str
        ``"u"`` or ``"v"`` (for the message).
    tolerance : float
        Frames.
    seen : (L,) array_like, optional
        Per light in the order along the sweep, the fraction of its pixels where it is
        timed (``assign_minima``'s ``seen``); a gap counts only between lights above 1/2.

    Returns
    -------
    (L,) float64 ndarray
        The described positions scaled to frames, in the order along the sweep (all NaN
        where no gap is measured consistently).

    Raises
    ------
    ValueError
        Naming ``light_along_<sweep>`` when they disagree.
    """
    gaps = np.diff(np.asarray(position, dtype=np.float64))
    along = np.sort(np.asarray(light_along, dtype=np.float64))
    if along.size != gaps.size + 1:
        raise ValueError(f"light_along_{sweep}: {along.size} lights described, {gaps.size + 1} measured")
    described = np.diff(along)
    use = np.isfinite(gaps) & (np.asarray(spread, dtype=np.float64) <= tolerance)
    if seen is not None:
        seen = np.asarray(seen, dtype=np.float64) > 0.5
        use &= seen[:-1] & seen[1:]
    norm = float(np.sum(described[use] ** 2))
    if not use.any() or norm == 0:
        return np.full(along.size, np.nan)
    scale = float(np.sum(described[use] * gaps[use]) / norm)
    off = np.abs(gaps - scale * described)[use]
    if off.max() > tolerance:
        expected = np.concatenate([[0.0], np.cumsum(scale * described)])
        raise ValueError(
            f"light_along_{sweep}: the capture description puts the lights' shadows at "
            f"{np.round(expected, 1).tolist()} frames along the {sweep} sweep, the data at "
            f"{np.round(position, 1).tolist()} (median gaps between the minima; off by "
            f"{off.max():.1f} > tolerance {tolerance}): check the lights' offsets (synthetic.lights "
            "in the manifest) against the capture; lights at different heights break the "
            "proportion this check assumes (light-views --skip-order-check)")
    return np.concatenate([[0.0], np.cumsum(scale * described)])


def match_sweep_lights(contrast_u, time_u, shown_u, contrast_v, time_v, shown_v, *, false_alarm=1e-3,
                       min_pixels=20):
    """Which u-sweep light is which v-sweep light, from their contrast maps.

    The same light lights the same scene in both sweeps, so a light's contrast (its dip's
    depth over the pixel's lit level: its share of the pixel's irradiance, shading and
    attached shadows included) is the same map in u and in v, while different lights'
    maps differ by their n.l / r^2 from different places. A sweep's dips are shallower than
    the share by the wire's blur, a factor of the pixel and sweep common to nearby lights,
    so the maps are compared normalised per pixel: the log contrasts centred over the
    lights compared there. A pairing (a permutation) compares the lights both sweeps show
    under it; its cost per pixel (where all of them are timed in both sweeps) is the sum of
    squared differences of the centred log contrasts, and the pairing is the one of least
    mean cost among those comparing the most lights. Its decisiveness is a sign test
    against the runner-up: each pixel timed for both favours the pairing of smaller cost
    there; with no preference either wins with probability 1/2, so ``z = (2 wins - n) /
    sqrt(n)`` (the best's wins among n pixels), and the pairing is decided when ``z``
    exceeds the one-sided ``false_alarm`` quantile (neighbouring pixels are treated as
    independent).

    Parameters
    ----------
    contrast_u, time_u : (L, H, W) array_like
        The u sweep's per-light contrast and time (NaN = untimed), light k at index k.
    shown_u : (L,) array_like of bool
        Whether the u sweep shows each light's dip.
    contrast_v, time_v, shown_v
        The same for the v sweep.
    false_alarm : float
        The test's false-alarm rate.
    min_pixels : int
        Pixels below which a pairing, or the test, has no evidence.

    Returns
    -------
    dict
        ``order`` (L,) int ndarray: v light ``order[k]`` is u light k; ``z`` (float; inf
        with one light or one pairing the evidence allows, 0 without evidence);
        ``decided`` (bool); ``reason`` (str, why it is not decided; empty when it is);
        ``cost`` (float, the pairing's mean cost; NaN without evidence).
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        log_u, log_v = (np.where(np.isfinite(np.asarray(t, np.float64)) & (np.asarray(c, np.float64) > 0),
                                 np.log(np.asarray(c, np.float64)), np.nan)
                        for c, t in ((contrast_u, time_u), (contrast_v, time_v)))
    n_lights = log_u.shape[0]
    shown_u, shown_v = np.asarray(shown_u, bool), np.asarray(shown_v, bool)
    critical = float(-ndtri(false_alarm))
    ranked = []
    for order in itertools.permutations(range(n_lights)):
        compared = [k for k in range(n_lights) if shown_u[k] and shown_v[order[k]]]
        if len(compared) < 2:
            continue
        u, v = log_u[compared], log_v[[order[k] for k in compared]]
        with np.errstate(invalid="ignore"):
            cost = np.sum(((u - u.mean(0)) - (v - v.mean(0))) ** 2, axis=0)  # (H, W), NaN where one is untimed
        valid = np.isfinite(cost)
        if valid.sum() >= min_pixels:
            ranked.append((-len(compared), float(cost[valid].mean()), order, cost))
    ranked.sort(key=lambda r: (r[0], r[1]))
    if n_lights == 1:
        return {"order": np.zeros(1, int), "cost": np.nan, "z": float("inf"), "decided": True, "reason": ""}
    if not ranked:
        return {"order": np.arange(n_lights), "cost": np.nan, "z": 0.0, "decided": False,
                "reason": "fewer than two lights are timed in both sweeps: no contrast maps to compare"}
    best = ranked[0]
    out = {"order": np.array(best[2]), "cost": best[1]}
    rivals = [r for r in ranked[1:] if r[0] == best[0]]
    if not rivals:
        return dict(out, z=float("inf"), decided=True, reason="")
    difference = rivals[0][3] - best[3]
    difference = difference[np.isfinite(difference)]
    wins, n = int(np.sum(difference > 0)), int(np.sum(difference != 0))
    z = (2.0 * wins - n) / np.sqrt(n) if n >= min_pixels else 0.0
    decided = bool(z > critical)
    reason = "" if decided else (
        f"the lights' contrast maps do not tell them apart (the runner-up pairing fits worse in "
        f"{wins} of {n} pixels, z = {z:.2f} <= {critical:.2f}): lights at nearly one place or of equal shading")
    return dict(out, z=float(z), decided=decided, reason=reason)


def pair_sweep_lights(per_sweep, positions, *, described, check=True, false_alarm=1e-3):
    """The v sweep's lights put in the u sweep's order, by their contrast maps.

    Without a description the lights are numbered in the order their shadows pass in the
    u sweep, and the v sweep's lights are matched to them by :func:`match_sweep_lights`;
    an undecided match keeps the v sweep's shadow order, with a warning. With a
    description (``light_along_*``, both sweeps already in its order) the measured
    pairing is checked against it.

    Parameters
    ----------
    per_sweep : mapping of str to dict
        ``u`` and ``v`` -> :func:`sweep_light_times`'s times.
    positions : mapping of str to (L,) ndarray
        ``u`` and ``v`` -> its positions.
    described : bool
        Both sweeps are in the order of the capture's ``light_along_*``.
    check : bool
        With a description: a decided measured pairing other than the described one is an
        error; False: only a warning.
    false_alarm : float
        Of :func:`match_sweep_lights`.

    Returns
    -------
    per_sweep, positions : dict
        As given, the v sweep's entries in the u sweep's light order.
    attrs : dict
        ``pairing`` (``described``, ``measured`` or ``shadow_order``: undecided, the k-th
        shadow of each sweep), ``pairing_z`` and ``pairing_decided`` (int).

    Raises
    ------
    ValueError
        Naming ``light_along_*`` when a decided measured pairing contradicts it (`check`).
    """
    u, v = per_sweep["u"], per_sweep["v"]
    match = match_sweep_lights(u["contrast"], u["time"], u["shown"], v["contrast"], v["time"], v["shown"],
                               false_alarm=false_alarm)
    attrs = {"pairing_z": float(match["z"]), "pairing_decided": int(match["decided"])}
    identity = np.arange(match["order"].size)
    if not match["decided"]:
        warnings.warn(f"pairing the u and v sweeps' lights: {match['reason']}; "
                      + ("the description's (light_along_*) pairing is kept unchecked" if described else
                         "light k is the k-th shadow to pass in each sweep, which may pair the wrong times "
                         "(give lights.light_along_*)"), stacklevel=2)
        return dict(per_sweep), dict(positions), dict(attrs, pairing="described" if described else "shadow_order")
    if described:
        if np.any(match["order"] != identity):
            message = (f"light_along_u / light_along_v: the described lights pair u light k with v light k, "
                       f"the contrast maps pair it with v light {match['order'].tolist()} (z = {match['z']:.1f}): "
                       "check the lights' offsets against the capture")
            if check:
                raise ValueError(message)
            warnings.warn(message, stacklevel=2)
        return dict(per_sweep), dict(positions), dict(attrs, pairing="described")
    order = match["order"]
    paired = {key: value[order] for key, value in v.items()}
    return ({"u": u, "v": paired}, {"u": positions["u"], "v": np.asarray(positions["v"])[order]},
            dict(attrs, pairing="measured"))


def _gather_light(record, index, ok):
    """One light's fields of a per-minimum record (window ``(W, K, H, W)``, others ``(K, H, W)``)
    at its minimum `index` ((1, H, W)); the window NaN where not `ok`."""
    gathered = {f.name: np.take_along_axis(getattr(record, f.name), index, 0)[0] for f in fields(record)
                if f.name not in ("window", "colour") and isinstance(getattr(record, f.name), np.ndarray)}
    window = np.take_along_axis(record.window, index[None], 1)[:, 0]
    return dict(gathered, window=np.where(ok[None], window, np.nan))


def _edge_fit_per_light(minima, assigned):
    """Each light's ok times re-timed by ``edge_fit`` over that light's own time map.

    ``edge_fit`` (:func:`shadowcam.lab.shadow_time_methods.time_edge_fit`) weighs each pixel's
    dip centroid against its neighbours' local plane by their variances; given the
    windows of one light's minima (:attr:`shadowcam.lab.minima.Minima.summary`, gathered
    at ``assigned["minimum"]``) its neighbours are that light's, never another light's.
    Flagged pixels neither get a time nor take part. With the minima's own-site samples
    (demosaiced RAW, ``summary.site``) each is timed from its own site where that dip is
    significant (:func:`shadowcam.lab.shadow_time_methods.time_edge_fit`).
    """
    summary = minima.summary
    out = dict(assigned)
    out["time"], out["time_std"] = assigned["time"].copy(), assigned["time_std"].copy()
    for k, pick in enumerate(assigned["minimum"]):
        ok = assigned["reason"][k] == OK
        index = np.maximum(pick, 0)[None]
        light = replace(summary, **_gather_light(summary, index, ok))
        if summary.site is not None:
            light.site = replace(summary.site, **_gather_light(summary.site, index, ok))
        with np.errstate(invalid="ignore", divide="ignore"):
            time, _, _, std = SHADOW_TIME_METHODS["edge_fit"](light)
        out["time"][k] = np.where(ok, time, np.nan)
        out["time_std"][k] = np.where(ok, std, assigned["time_std"][k])
    return out


def sweep_light_times(frames, n_lights, *, sweep, light_along=None, half_window=4, method="edge_fit", radius=2,
                      tolerance=2.0, check_order=True, cfa_pattern=None, shape=None):
    """One sweep's minima assigned to the lights, with the lights' positions along it.

    Parameters
    ----------
    frames : (T, H, W, C) array_like, or callable
        The sweep's frames (any linear scale: radiance, or decoded files with white 1), or
        a callable returning an iterable of consecutive ``(t, H, W, C)`` blocks of them
        (called twice, :func:`shadowcam.lab.minima.find_minima`; needs `shape`).
    n_lights : int
        Lights (>= 1).
    sweep : str
        ``"u"`` or ``"v"`` (for messages).
    light_along : (L,) array_like, optional
        Each light's described position along the sweep's wire motion, which orders its
        shadows (a light further along needs the wire further along to shadow a point, so
        later). None: light k is the k-th shadow to pass (nothing to check).
    half_window, method, radius, tolerance, check_order
        See :func:`light_set_views`.
    cfa_pattern : str, optional
        Demosaiced camera RAW frames: the CFA pattern of their mosaic (e.g. ``"RGGB"``,
        :func:`shadowcam.lab.site_signal.cfa_site_colours`). With ``edge_fit`` each assigned
        minimum is then timed from its own site where that dip is significant against its
        noise (:func:`shadowcam.lab.minima.find_minima`); which minima are found and assigned
        does not depend on it.
    shape : (int, int), optional
        ``(H, W)`` of callable `frames`.

    Returns
    -------
    times : dict of str to (L, H, W) ndarray
        ``time``, ``contrast``, ``confidence``, ``time_std``, ``reason``, ``minimum``
        (L, H, W) and ``shown`` (L,) (:func:`~shadowcam.lab.light_assignment.assign_minima`,
        re-timed by ``edge_fit``) with light k at index k.
    position : (L,) float64 ndarray
        Each light's position along the sweep measured from its shadows (frames from the
        first shadow's, :func:`light_positions`), light k at index k.

    Raises
    ------
    ValueError
        Naming the parameter, or ``light_along_<sweep>`` when the measured positions
        disagree with it (:func:`check_light_order`).
    """
    if callable(frames):
        if shape is None:
            raise ValueError("shape: give the frames' (H, W) with a callable of frame blocks")
        shape = tuple(int(n) for n in shape)
    else:
        frames = check_array(frames, "frames", ndim=4)
        shape = frames.shape[1:3]
    n_lights = int(check_positive(n_lights, "n_lights"))
    if light_along is not None:
        light_along = check_array(light_along, f"light_along_{sweep}", ndim=1, shape=(n_lights,))
    site_colour = cfa_site_colours(shape, cfa_pattern) if cfa_pattern and method == "edge_fit" else None
    minima = find_minima(frames, shape, count=n_lights, half_window=half_window,
                         method="dip_centroid" if method == "edge_fit" else method, site_colour=site_colour)
    in_order = assign_minima(minima, n_lights, radius=radius, tolerance=tolerance)
    if method == "edge_fit":
        in_order = _edge_fit_per_light(minima, in_order)
    position, spread = light_positions(in_order["time"])
    seen = in_order.pop("seen")
    if light_along is None:
        return in_order, position
    if check_order:
        check_light_order(position, spread, light_along, sweep=sweep, tolerance=tolerance, seen=seen)
    # the k-th shadow along the sweep is the light k-th along the wire's motion
    back = np.argsort(np.argsort(light_along, kind="stable"))
    return {key: value[back] for key, value in in_order.items()}, position[back]


def light_views_dataset(per_sweep, positions, reference, *, shape, lights, channels, attrs):
    """Per-light dual views from each light's u and v shadow times, as one dataset.

    Parameters
    ----------
    per_sweep : mapping of str to dict
        ``u`` and ``v`` -> :func:`sweep_light_times`'s times.
    positions : mapping of str to (L,) ndarray
        ``u`` and ``v`` -> its positions.
    reference : (H, W, C) ndarray
        The unshadowed image the views are coloured from.
    shape : (2,) tuple of int
        ``(frames of v, frames of u)``: the dual grid.
    lights, channels : sequence
        Coordinates ``light`` and ``channel``.
    attrs : mapping
        The options, stored as attrs.

    Returns
    -------
    xarray.Dataset
        As :func:`light_set_views`.
    """
    n_lights = len(lights)
    views = np.full((n_lights, *shape, reference.shape[2]), np.nan, np.float32)
    coverage = np.zeros((n_lights, *shape), bool)
    for k in range(n_lights):
        views[k], coverage[k] = resample_dual_view(reference, per_sweep["u"]["time"][k],
                                                   per_sweep["v"]["time"][k], shape=shape)
    dims = ("sweep", "light", "y", "x")

    def stacked(key, dtype):
        return (dims, np.stack([per_sweep[s][key] for s in SWEEPS]).astype(dtype))

    return xr.Dataset(
        {"time": stacked("time", np.float32), "contrast": stacked("contrast", np.float32),
         "confidence": stacked("confidence", np.float32), "time_std": stacked("time_std", np.float32),
         "reason": stacked("reason", np.int8),
         "shown": (("sweep", "light"), np.stack([per_sweep[s]["shown"] for s in SWEEPS]).astype(np.int8)),
         "dual_view": (("light", "v", "u", "channel"), views), "coverage": (("light", "v", "u"), coverage),
         "position": (("sweep", "light"), np.stack([positions[s] for s in SWEEPS]))},
        coords={"sweep": list(SWEEPS), "light": np.asarray(lights), "channel": np.asarray(channels)},
        attrs={"reasons": str(LIGHT_REASONS), **attrs})


def light_set_views(capture, *, half_window=4, method="edge_fit", radius=2, tolerance=2.0, check_order=True):
    """Per-light shadow times and dual views of a capture held in memory.

    Parameters
    ----------
    capture : xarray.Dataset
        ``frames_u``, ``frames_v`` (t, y, x, channel), ``reference`` (y, x, channel), a
        ``light`` coordinate and optionally ``light_along_u``, ``light_along_v`` (light,):
        each light's position along the sweep's wire motion, which orders its shadows
        (:func:`shadowcam.synthetic.lab.light_set_capture.render_light_set_capture`);
        without them light k is the k-th shadow to pass in the u sweep, and the v sweep's
        lights are paired with them by their contrast maps (:func:`pair_sweep_lights`); attr ``cfa_pattern``
        for demosaiced camera RAW frames (timed as :func:`sweep_light_times` times them). A
        capture's files: :func:`shadowcam.lab.light_files.light_set_views_of_plan`, or
        :func:`~shadowcam.lab.light_files.light_set_capture_of_plan` for this dataset.
    half_window : int
        Of :func:`~shadowcam.lab.minima.find_minima`: at least half the widest dip (a tube
        across the wire spreads its shadow over its projection).
    method : str
        Timing method of each minimum (:func:`~shadowcam.lab.minima.find_minima`), or
        ``edge_fit``: dip centroids refined over each light's own time map
        (:func:`_edge_fit_per_light`).
    radius, tolerance
        Of :func:`~shadowcam.lab.light_assignment.assign_minima`.
    check_order : bool
        Check the measured positions against ``light_along_<sweep>``
        (:func:`check_light_order`, which assumes the lights at one height) and the
        measured pairing of the sweeps' lights against theirs (:func:`pair_sweep_lights`);
        False: only measure them (a contradicting pairing is a warning).

    Returns
    -------
    xarray.Dataset
        ``time``, ``contrast``, ``confidence``, ``time_std`` (sweep, light, y, x) float32,
        ``reason`` (sweep, light, y, x) int8 (:data:`~shadowcam.lab.light_assignment.LIGHT_REASONS`),
        ``shown`` (sweep, light) int8 (1: the sweep shows the light's dip; 0: its dips are
        no more than noise alone places, every time ``unresolved_dip``), ``dual_view`` (light, v, u, channel), ``coverage`` (light, v, u) and ``position``
        (sweep, light): each light's position along the sweep measured from its shadows
        (frames from the first light's, :func:`light_positions`); attrs ``pairing``,
        ``pairing_z``, ``pairing_decided`` (:func:`pair_sweep_lights`).

    Raises
    ------
    ValueError
        When the measured positions disagree with ``light_along_<sweep>``
        (:func:`check_light_order`), or a decided pairing of the sweeps' lights with the
        description (:func:`pair_sweep_lights`; with `check_order`).
    """
    missing = {"frames_u", "frames_v", "reference"} - set(capture)
    if missing or "light" not in capture.coords:
        raise ValueError(f"capture: not a several-lights capture (missing {sorted(missing) or 'light'}); "
                         "render it with the render-lights step")
    n_lights = capture.sizes["light"]
    per_sweep, positions = {}, {}
    for name in SWEEPS:
        along = capture[f"light_along_{name}"].values if f"light_along_{name}" in capture else None
        per_sweep[name], positions[name] = sweep_light_times(
            capture[f"frames_{name}"].values, n_lights, sweep=name, light_along=along, half_window=half_window,
            method=method, radius=radius, tolerance=tolerance, check_order=check_order,
            cfa_pattern=capture.attrs.get("cfa_pattern"))
    per_sweep, positions, pairing = pair_sweep_lights(per_sweep, positions, described="light_along_u" in capture,
                                                      check=check_order)
    return light_views_dataset(
        per_sweep, positions, capture["reference"].values, shape=(capture.sizes["t_v"], capture.sizes["t_u"]),
        lights=capture["light"].values, channels=capture["channel"].values,
        attrs={**view_attrs(half_window=half_window, method=method, radius=radius, tolerance=tolerance,
                            check_order=check_order and "light_along_u" in capture), **pairing})


def view_attrs(*, half_window, method, radius, tolerance, check_order):
    """The options of :func:`light_set_views` as the dataset's attrs."""
    return {"half_window": int(half_window), "method": method, "radius": int(radius),
            "tolerance": float(tolerance), "order_checked": int(bool(check_order))}


def light_set_errors(views, capture, *, min_level=0.2):
    """Per-light, per-sweep absolute time errors on the pixels that can be scored.

    A pixel is scored for light k and a sweep when it is lit (reference level above
    `min_level` times its median) and light k's shadow lies entirely inside the sweep
    (more than two frames from either end).

    Parameters
    ----------
    views : xarray.Dataset
        From :func:`light_set_views`.
    capture : xarray.Dataset
        The truth: ``t_center_<sweep>``, ``t_first_<sweep>``, ``t_last_<sweep>`` (light, y,
        x) and ``reference`` (y, x, channel), as the capture's ``ground_truth.nc`` holds them.
    min_level : float

    Returns
    -------
    dict of (str, int) to ((y, x) float ndarray, (y, x) bool ndarray)
        (sweep, light) -> |estimate - truth| (frames; NaN where untimed or unscored) and
        the scored pixels.
    """
    level = capture["reference"].values.sum(-1)
    lit = level > min_level * np.median(level)
    out = {}
    for s, name in enumerate(SWEEPS):
        n = views.sizes[name]  # the sweep's frames: the dual grid's axis
        for k in range(capture.sizes["light"]):
            truth = capture[f"t_center_{name}"].values[k]
            scored = (lit & np.isfinite(truth) & (capture[f"t_first_{name}"].values[k] > 2)
                      & (capture[f"t_last_{name}"].values[k] < n - 3))
            error = np.where(scored, np.abs(views["time"].values[s, k] - truth), np.nan)
            out[name, k] = (error, scored)
    return out


def light_set_accuracy(views, capture, *, min_level=0.2, false_error=1.0):
    """Per-light, per-sweep accuracy against the renderer's per-light times.

    Parameters
    ----------
    views : xarray.Dataset
        From :func:`light_set_views`.
    capture : xarray.Dataset
        As for :func:`light_set_errors`.
    min_level : float
        Pixels darker than this fraction of the median reference are not scored.
    false_error : float
        Frames: a timed pixel further than this from the truth is a false time.

    Returns
    -------
    dict
        ``lights``: one entry per light with, per sweep, ``p95_error``, ``rmse`` and
        ``max_error`` (frames, over its timed scored pixels), ``coverage`` (timed fraction
        of the scored pixels: lit, the light's shadow entirely inside the sweep),
        ``n_scored``, ``contrast`` (median), ``false_rate`` (fraction of the timed scored
        pixels further than `false_error` from the truth), ``confidence_true`` and
        ``confidence_false`` (median confidence on the timed pixels within and beyond
        `false_error`; None where none), ``reasons`` (name -> count) and, from the views'
        ``shown``, ``dip_shown`` (bool) with a ``note`` where the sweep cannot show the
        light's dip; ``pairing`` (``how``, ``z``, ``decided``: how the v sweep's lights were
        paired with the u sweep's, :func:`pair_sweep_lights`) where the views record it.
    """
    errors = light_set_errors(views, capture, min_level=min_level)
    out = []
    for k in range(capture.sizes["light"]):
        entry = {}
        for s, name in enumerate(SWEEPS):
            error, scored = errors[name, k]
            err = error[scored]
            reason = views["reason"].values[s, k]
            timed = np.isfinite(err)
            contrast = views["contrast"].values[s, k][scored]
            confidence = views["confidence"].values[s, k][scored]
            false = timed & (np.nan_to_num(err, nan=0.0) > false_error)
            true = timed & ~false
            entry[name] = {
                "p95_error": float(np.percentile(err[timed], 95)) if timed.any() else None,
                "rmse": float(np.sqrt(np.mean(err[timed] ** 2))) if timed.any() else None,
                "max_error": float(err[timed].max()) if timed.any() else None,
                "coverage": float(timed.mean()) if scored.any() else 0.0,
                "n_scored": int(scored.sum()),
                "contrast": float(np.nanmedian(contrast)) if np.isfinite(contrast).any() else None,
                "false_rate": float(false.sum() / timed.sum()) if timed.any() else None,
                "confidence_true": float(np.median(confidence[true])) if true.any() else None,
                "confidence_false": float(np.median(confidence[false])) if false.any() else None,
                "reasons": {label: int(np.sum(reason[scored] == code)) for code, label in LIGHT_REASONS.items()},
            }
            if "shown" in views:
                entry[name]["dip_shown"] = bool(views["shown"].values[s, k])
                if not entry[name]["dip_shown"]:
                    entry[name]["note"] = (f"the {name} sweep cannot show this light's dip: its minima are no "
                                           "more than noise alone places (reason unresolved_dip)")
        out.append(entry)
    if "pairing" not in views.attrs:
        return {"lights": out}
    pairing = {"how": str(views.attrs["pairing"]), "z": float(views.attrs["pairing_z"]),
               "decided": bool(views.attrs["pairing_decided"])}
    return {"lights": out, "pairing": pairing}
