"""Per-pixel shadow-arrival time (seconds, sub-frame) from tracked edges.

Two estimators, combined:

* **edge crossing** (:func:`arrival_from_edges`): the tracked edge row of each
  column is a function of time; a pixel's arrival is when the edge passes its
  centre ``r + 0.5``, linear in time between the two frames whose edges
  straddle it. The sub-frame part comes from where the edge sits *spatially*
  (sub-pixel) in each frame.
* **coverage crossing** (:class:`shadowcam.outdoor.episodes.ShadowEpisodes`, streamed
  frame by frame): the start of the pixel's final dark episode (its lit fraction
  drops through 0.5 and never relights for good after), linear in time between
  the two frames around it. It covers what a single edge per column cannot
  represent (a second transition in a column, a sunlit tongue that sweeps
  sideways) and is not fooled by a shadow that passes (a cloud).

* **penumbra fit** (:mod:`shadowcam.outdoor.descent`): the centre of the final descent's
  ramp, the circular-segment law of a disc sun behind a straight edge fitted to the
  pixel's coverage over the whole ramp. Where the ramp spans several frames (the real
  sun behind a far ridge at a photographer's cadence) it replaces both crossings, which
  assume an edge sharper than one interval; a ramp shorter than the sampling resolves
  keeps them. A ramp still under way at the last frame, or whose centre is uncertain, gets
  no time but a reason (:func:`apply_ramps`).

Earlier dark episodes of a pixel are resolved by :func:`resolve_episodes`: one
whose start agrees with the ridge edge's crossing of the pixel is the ridge
shadow's arrival, relit later by the geometry (a sunlit tongue through a
saddle); the others are transient shadows (a cloud). A pixel whose episodes
none of this explains gets no time but a reason. :func:`combine_arrivals` takes
the edge crossing where it agrees with the coverage crossing within a tolerance
and the coverage crossing elsewhere, and gives each pixel a reason; every
episode of a pixel with more than one is listed as an event (:func:`event_table`).

Offers
------
ARRIVAL_REASONS : reason code -> name (CF flag meanings).
arrival_from_edges : arrival time of every pixel from the per-frame edge rows.
EVENT_KINDS : event kind code -> name (CF flag meanings).
resolve_episodes : which dark episode of each pixel is the ridge shadow's arrival.
combine_arrivals : the final arrival map and its reasons.
apply_ramps : the penumbra fit's centres and reasons where the final descent was fitted.
arrivals : arrival map, reasons and events from tracked edges and pixel episodes (arrays).
event_table : the dark episodes of pixels with more than one, as a table.
arrival_dataset : the arrival-time map over (row, col) with reasons.
arrival_map : the arrival dataset of a capture from its photometry and edges datasets.
"""

import numpy as np
import xarray as xr

from shadowcam._shared.validation import check_positive, check_same_shape
from shadowcam.io.frame_times import median_interval, time_to_frame
from shadowcam.outdoor.descent import STATE_CODE, TIMED_STATES

#: reason code -> meaning (stored as CF flag_values / flag_meanings)
ARRIVAL_REASONS = {
    0: "edge_crossing",
    1: "coverage_crossing",
    2: "never_shadowed",
    3: "shadowed_at_start",
    4: "sky",
    5: "relit_after_arrival",
    6: "ambiguous_history",
    7: "penumbra_fit",
    8: "ramp_cut",
    9: "ambiguous_ramp",
    10: "no_lit_level",
    11: "lit_ratio_spread",
    12: "arrival_before_record",
    13: "clipped_crossing",
}
REASON_CODE = {name: code for code, name in ARRIVAL_REASONS.items()}
#: event kind code -> meaning: the ridge shadow's arrival (end = relit time, NaN if it lasts),
#: the ridge shadow again after the pixel was relit, a transient (passing) shadow, an
#: episode of a pixel whose history is ambiguous
EVENT_KINDS = {0: "arrival", 1: "shadowed_again", 2: "transient", 3: "ambiguous"}


def arrival_from_edges(edge_row, time_s, *, eligible):
    """Arrival time of each pixel from the per-frame edge rows.

    Parameters
    ----------
    edge_row : (T, W) ndarray
        Edge row per frame and column (pixel-edge coordinates; lit above);
        NaN where there is none.
    time_s : (T,) ndarray
        Frame times in seconds.
    eligible : (H, W) bool ndarray
        Pixels that may receive an arrival (lit in the first frame, not sky).

    Returns
    -------
    (H, W) float64 ndarray
        Seconds; NaN where the edge never passed the pixel centre.
    """
    edge = np.asarray(edge_row, dtype=np.float64)
    times = np.asarray(time_s, dtype=np.float64)
    eligible = np.asarray(eligible, dtype=bool)
    if edge.ndim != 2 or times.shape != (edge.shape[0],) or eligible.ndim != 2 or eligible.shape[1] != edge.shape[1]:
        raise ValueError(f"edge_row {edge.shape} must be (T, W), time_s {times.shape} (T,), eligible {eligible.shape} (H, W)")
    height = eligible.shape[0]
    centre = np.arange(height, dtype=np.float64)[:, None] + 0.5
    arrival = np.full(eligible.shape, np.nan)
    for k in range(1, edge.shape[0]):
        y0, y1 = edge[k - 1][None, :], edge[k][None, :]
        with np.errstate(invalid="ignore"):
            cross = (y0 > centre) & (y1 <= centre) & eligible & np.isnan(arrival)
        if not cross.any():
            continue
        frac = (y0 - centre) / np.where(y0 > y1, y0 - y1, 1.0)
        value = times[k - 1] + np.clip(frac, 0.0, 1.0) * (times[k] - times[k - 1])
        arrival[cross] = np.broadcast_to(value, arrival.shape)[cross]
    return arrival


def _at_the_edge(starts, edge_row, time_s, *, tolerance_rows):
    """Whether the tracked edge of the pixel's column is within `tolerance_rows` of its centre
    in the first frame at or after each start (one episode slot at a time)."""
    height, width = starts.shape[:2]
    edge = np.asarray(edge_row, dtype=np.float32)
    times = np.asarray(time_s, dtype=np.float64)
    centre = np.arange(height, dtype=np.float32)[:, None] + np.float32(0.5)
    col = np.arange(width, dtype=np.int32)[None, :]
    near = np.zeros(starts.shape, dtype=bool)
    for slot in range(starts.shape[-1]):
        start = starts[..., slot]
        known = np.isfinite(start)
        k = np.searchsorted(times, np.where(known, start, times[0])).astype(np.int32)
        np.minimum(k, times.size - 1, out=k)
        with np.errstate(invalid="ignore"):
            near[..., slot] = known & (np.abs(edge[k, col] - centre) <= tolerance_rows)
    return near


def resolve_episodes(final_s, event_start_s, edge_s, *, tolerance_s, edge_row=None, time_s=None, tolerance_rows=1.0):
    """Which dark episode of each pixel is the ridge shadow's arrival.

    Parameters
    ----------
    final_s : (H, W) ndarray
        Start of the final dark episode (NaN: none).
    event_start_s : (H, W, E) ndarray
        Starts of the earlier (relit) dark episodes, in time order (NaN: none).
    edge_s : (H, W) ndarray
        When the tracked ridge edge crossed the pixel centre (NaN: never).
    tolerance_s : float
        An episode is the ridge shadow's when its start is within this many seconds of `edge_s`, ...
    edge_row : (T, W) ndarray, optional
        ... or when the tracked edge of its column (pixel-edge rows) is within
        `tolerance_rows` of the pixel's centre in the first frame at or after its start
        (the edge passes the pixel as it darkens: a relit tongue along the edge, not a
        cloud drifting over the lit cliff).
    time_s : (T,) ndarray, optional
        Frame times of `edge_row`.
    tolerance_rows : float, optional

    Returns
    -------
    coverage_s : (H, W) float64 ndarray
        The start of the first earlier episode that agrees with the edge crossing (the
        pixel was relit after the arrival), else the start of the final episode; NaN for
        ambiguous pixels.
    chosen : (H, W) int ndarray
        Slot of the earlier episode that is the arrival (the pixel was relit after it);
        ``E`` where the arrival is the final episode.
    ambiguous : (H, W) bool ndarray
        Pixels with earlier episodes where the edge crossed the pixel at a time that none
        of its episodes, final or earlier, agrees with: the edge or the episodes are wrong
        there, and no time is given.
    """
    final = np.asarray(final_s, dtype=np.float64)
    starts = np.asarray(event_start_s)
    edge = np.asarray(edge_s, dtype=np.float64)
    check_same_shape({"final_s": final, "edge_s": edge, "event_start_s[..., 0]": starts[..., 0]})
    with np.errstate(invalid="ignore"):
        agree = np.abs(starts - edge[..., None]) <= tolerance_s
        final_agrees = np.abs(final - edge) <= tolerance_s
    if edge_row is not None:
        agree |= _at_the_edge(starts, edge_row, time_s, tolerance_rows=tolerance_rows)
    relit = agree.any(axis=-1)
    chosen = np.where(relit, np.argmax(agree, axis=-1), starts.shape[-1])
    first = np.take_along_axis(starts, np.minimum(chosen, starts.shape[-1] - 1)[..., None], axis=-1)[..., 0]
    earlier = np.isfinite(starts).any(axis=-1)
    ambiguous = earlier & np.isfinite(edge) & ~relit & ~final_agrees
    coverage = np.where(relit, first, final)
    coverage[ambiguous] = np.nan
    return coverage, chosen, ambiguous


def combine_arrivals(edge_s, coverage_s, *, tolerance_s, sky, lit_at_start, relit=None, ambiguous=None):
    """Final arrival map and per-pixel reason.

    Parameters
    ----------
    edge_s, coverage_s : (H, W) ndarray
        Arrival from edge crossing and from coverage crossing (NaN = none).
    tolerance_s : float
        The edge crossing is kept where the two agree within this many seconds
        (or where only it exists); elsewhere the coverage crossing is used.
    sky, lit_at_start : (H, W) bool ndarray
    relit, ambiguous : (H, W) bool ndarray, optional
        :func:`resolve_episodes` results: reasons ``relit_after_arrival`` and
        ``ambiguous_history`` (no time).

    Returns
    -------
    arrival_s : (H, W) float64 ndarray
    reason : (H, W) uint8 ndarray
        Codes of :data:`ARRIVAL_REASONS`.
    """
    edge_s = np.asarray(edge_s, dtype=np.float64)
    coverage_s = np.asarray(coverage_s, dtype=np.float64)
    check_same_shape({"edge_s": edge_s, "coverage_s": coverage_s})
    with np.errstate(invalid="ignore"):
        agree = np.abs(edge_s - coverage_s) <= tolerance_s
    use_edge = np.isfinite(edge_s) & (agree | np.isnan(coverage_s))
    arrival = np.where(use_edge, edge_s, coverage_s)
    reason = np.full(edge_s.shape, REASON_CODE["coverage_crossing"], dtype=np.uint8)
    reason[use_edge] = REASON_CODE["edge_crossing"]
    if relit is not None:
        reason[np.asarray(relit, dtype=bool) & np.isfinite(arrival)] = REASON_CODE["relit_after_arrival"]
    reason[np.isnan(arrival)] = REASON_CODE["never_shadowed"]
    if ambiguous is not None:
        ambiguous = np.asarray(ambiguous, dtype=bool)
        arrival[ambiguous] = np.nan
        reason[ambiguous] = REASON_CODE["ambiguous_history"]
    reason[~np.asarray(lit_at_start, dtype=bool)] = REASON_CODE["shadowed_at_start"]
    sky = np.asarray(sky, dtype=bool)
    reason[sky] = REASON_CODE["sky"]
    arrival[sky | ~np.asarray(lit_at_start, dtype=bool)] = np.nan
    return arrival, reason

def apply_ramps(arrival_s, reason, ramp_centre_s, ramp_state):
    """Take the fitted penumbra centres where the final descent's ramp spans several frames.

    Parameters
    ----------
    arrival_s : (H, W) ndarray
        :func:`combine_arrivals` result.
    reason : (H, W) uint8 ndarray
        Its reasons; only pixels whose arrival is the final episode's (``edge_crossing``,
        ``coverage_crossing``) are changed.
    ramp_centre_s : (H, W) ndarray
    ramp_state : (H, W) uint8 ndarray
        :func:`shadowcam.outdoor.descent.fit_descents` results.

    Returns
    -------
    arrival_s : (H, W) float64 ndarray
        The ramp centre where the state is one of
        :data:`shadowcam.outdoor.descent.TIMED_STATES`; NaN where it is ``cut`` (reason
        ``ramp_cut``), ``ambiguous`` (reason ``ambiguous_ramp``), ``no_lit_level``,
        ``lit_ratio_spread``, ``clipped_crossing`` (reasons of the same names) or ``before_record`` (reason
        ``arrival_before_record``).
    reason : (H, W) uint8 ndarray
    """
    arrival = np.array(arrival_s, dtype=np.float64)
    reason = np.array(reason, dtype=np.uint8)
    state = np.asarray(ramp_state, dtype=np.uint8)
    check_same_shape({"arrival_s": arrival, "reason": reason, "ramp_centre_s": np.asarray(ramp_centre_s),
                      "ramp_state": state})
    final = (reason == REASON_CODE["edge_crossing"]) | (reason == REASON_CODE["coverage_crossing"])
    fitted = final & np.isin(state, [STATE_CODE[name] for name in TIMED_STATES])
    arrival[fitted] = np.asarray(ramp_centre_s, dtype=np.float64)[fitted]
    reason[fitted] = REASON_CODE["penumbra_fit"]
    for name, code in (("cut", "ramp_cut"), ("ambiguous", "ambiguous_ramp"), ("no_lit_level", "no_lit_level"),
                       ("lit_ratio_spread", "lit_ratio_spread"), ("before_record", "arrival_before_record"),
                       ("clipped_crossing", "clipped_crossing")):
        where = final & (state == STATE_CODE[name])
        arrival[where] = np.nan
        reason[where] = REASON_CODE[code]
    return arrival, reason


def event_table(final_s, final_depth, event_start_s, event_end_s, event_depth, *, chosen, ambiguous, eligible):
    """The dark episodes of every pixel that had more than one, with their kind.

    Parameters
    ----------
    final_s, final_depth : (H, W) ndarray
        Start and depth of the final dark episode (NaN: none).
    event_start_s, event_end_s, event_depth : (H, W, E) ndarray
        The earlier (relit) episodes in time order (NaN: none).
    chosen, ambiguous : (H, W) ndarray
        :func:`resolve_episodes` results.
    eligible : (H, W) bool ndarray
        Pixels that may have an arrival (lit at start, not sky).

    Returns
    -------
    dict of (N,) ndarray
        ``row``, ``col``, ``start_s``, ``end_s`` (NaN: lasts to the last frame),
        ``depth`` (1 - the mean lit fraction) and ``kind`` (codes of :data:`EVENT_KINDS`),
        pixel by pixel in time order.
    """
    starts = np.asarray(event_start_s)
    # only the pixels with an earlier episode: (N, E) arrays
    pixel = np.isfinite(starts).any(axis=-1) & np.asarray(eligible, dtype=bool)
    row, col = np.nonzero(pixel)
    starts = starts[pixel].astype(np.float64)
    ends = np.asarray(event_end_s)[pixel].astype(np.float64)
    depths = np.asarray(event_depth)[pixel].astype(np.float32)
    final = np.asarray(final_s, dtype=np.float64)[pixel]
    chosen = np.asarray(chosen)[pixel]
    ambiguous = np.asarray(ambiguous, dtype=bool)[pixel]
    relit = chosen < starts.shape[-1]
    slot = np.arange(starts.shape[-1])
    kind = np.where(slot < chosen[:, None], 2, np.where(slot == chosen[:, None], 0, 1))
    final_kind = np.where(relit, 1, 0)
    kind = np.where(ambiguous[:, None], 3, kind)
    final_kind = np.where(ambiguous, 3, final_kind)
    # all episodes of those pixels, the final one last
    start = np.concatenate([starts, final[:, None]], axis=-1)
    end = np.concatenate([ends, np.full((final.size, 1), np.nan)], axis=-1)
    depth = np.concatenate([depths, np.asarray(final_depth, dtype=np.float32)[pixel][:, None]], axis=-1)
    kinds = np.concatenate([kind, final_kind[:, None]], axis=-1).astype(np.uint8)
    listed = np.isfinite(start)
    index = np.broadcast_to(np.arange(final.size)[:, None], listed.shape)[listed]
    return {"row": row[index].astype(np.int32), "col": col[index].astype(np.int32), "start_s": start[listed],
            "end_s": end[listed], "depth": depth[listed], "kind": kinds[listed]}


def arrival_dataset(arrival_s, arrival_frame, reason, *, edge_arrival_s, coverage_arrival_s, interval_s,
                    events=None):
    """Assemble the arrival map.

    Parameters
    ----------
    events : dict, optional
        :func:`event_table`.

    Returns
    -------
    xarray.Dataset
        ``arrival_time_s``, ``arrival_frame``, ``reason`` (CF flags),
        ``edge_arrival_s``, ``coverage_arrival_s`` over ``(row, col)``; with `events`,
        ``event_row``, ``event_col``, ``event_start_s``, ``event_end_s``, ``event_depth``,
        ``event_kind`` (CF flags) over ``event``; attr ``median_interval_s``.
    """
    cam = ("row", "col")
    codes = sorted(ARRIVAL_REASONS)
    data = {
        "arrival_time_s": (cam, np.asarray(arrival_s), {"units": "s", "long_name": "shadow arrival time since the first frame"}),
        "arrival_frame": (cam, np.asarray(arrival_frame), {"units": "frame", "long_name": "arrival as fractional frame (piecewise linear in time_s)"}),
        "reason": (cam, np.asarray(reason, np.uint8), {
            "long_name": "how the arrival was obtained, or why there is none",
            "flag_values": np.array(codes, np.uint8), "flag_meanings": " ".join(ARRIVAL_REASONS[c] for c in codes)}),
        "edge_arrival_s": (cam, np.asarray(edge_arrival_s), {"units": "s", "long_name": "arrival from the tracked edge crossing the pixel centre"}),
        "coverage_arrival_s": (cam, np.asarray(coverage_arrival_s), {"units": "s", "long_name": "arrival from the pixel's lit fraction crossing 0.5"}),
    }
    if events is not None:
        kinds = sorted(EVENT_KINDS)
        data.update({
            "event_row": ("event", events["row"], {"long_name": "row of the pixel of a dark episode"}),
            "event_col": ("event", events["col"], {"long_name": "column of the pixel of a dark episode"}),
            "event_start_s": ("event", events["start_s"], {"units": "s", "long_name": "start of the dark episode"}),
            "event_end_s": ("event", events["end_s"], {"units": "s", "long_name": "end (relighting); NaN: lasts to the last frame"}),
            "event_depth": ("event", events["depth"], {"units": "1", "long_name": "1 - mean lit fraction during the episode"}),
            "event_kind": ("event", events["kind"], {
                "long_name": "what the episode is", "flag_values": np.array(kinds, np.uint8),
                "flag_meanings": " ".join(EVENT_KINDS[c] for c in kinds)}),
        })
    dataset = xr.Dataset(data)
    dataset.attrs["median_interval_s"] = float(interval_s)
    return dataset


#: the tracker's per-pixel results the arrival step reads (the episodes are optional)
EPISODE_KEYS = ("coverage_arrival_s", "final_depth", "event_start_s", "event_end_s", "event_depth",
                "ramp_centre_s", "ramp_state")


def arrivals(edge_row, time_s, pixels, *, sky, lit_at_start, tolerance_s):
    """Arrival map of tracked edges and pixel episodes (the arrays behind :func:`arrival_map`).

    Parameters
    ----------
    edge_row : (T, W) ndarray
        Edge rows after keyframe interpolation.
    time_s : (T,) ndarray
    pixels : mapping
        ``coverage_arrival_s (H, W)`` and, optionally, ``final_depth``, ``event_start_s``,
        ``event_end_s``, ``event_depth`` and ``ramp_centre_s``, ``ramp_state``
        (:func:`shadowcam.outdoor.tracking.track_frames`).
    sky, lit_at_start : (H, W) bool ndarray
    tolerance_s : float
        Agreement of the edge crossing with an episode's start.

    Returns
    -------
    dict
        ``arrival_s``, ``reason``, ``edge_s``, ``coverage_s`` (the resolved coverage
        crossing) ``(H, W)`` and ``events`` (:func:`event_table`, None without episodes).
    """
    sky = np.asarray(sky, dtype=bool)
    lit = np.asarray(lit_at_start, dtype=bool)
    edge_s = arrival_from_edges(edge_row, time_s, eligible=lit & ~sky)
    final_s = np.asarray(pixels["coverage_arrival_s"], dtype=np.float64)
    coverage_s, relit, ambiguous, events = final_s, None, None, None
    if "event_start_s" in pixels:
        episodes = [np.asarray(pixels[name]) for name in ("event_start_s", "event_end_s", "event_depth")]
        coverage_s, chosen, ambiguous = resolve_episodes(final_s, episodes[0], edge_s, tolerance_s=tolerance_s,
                                                         edge_row=edge_row, time_s=time_s)
        relit = chosen < episodes[0].shape[-1]
        events = event_table(final_s, pixels["final_depth"], *episodes, chosen=chosen, ambiguous=ambiguous,
                             eligible=lit & ~sky)
    arrival, reason = combine_arrivals(edge_s, coverage_s, sky=sky, lit_at_start=lit, tolerance_s=tolerance_s,
                                       relit=relit, ambiguous=ambiguous)
    if "ramp_state" in pixels:
        arrival, reason = apply_ramps(arrival, reason, pixels["ramp_centre_s"], pixels["ramp_state"])
    return {"arrival_s": arrival, "reason": reason, "edge_s": edge_s, "coverage_s": coverage_s, "events": events}


def arrival_map(photometry, edges, *, tolerance_intervals=1.5):
    """The arrival-time map of a capture (edge crossing checked against coverage crossing).

    Parameters
    ----------
    photometry : xarray.Dataset
        First-pass result: ``sky`` and ``lit_at_start`` over ``(row, col)``.
    edges : xarray.Dataset
        Tracked edges: ``edge_row (time, col)``, ``coverage_arrival_s (row, col)``, coord ``time_s``;
        with the earlier dark episodes (``final_depth``, ``event_start_s``, ``event_end_s``,
        ``event_depth``) they are resolved (:func:`resolve_episodes`) and listed as events.
    tolerance_intervals : float, keyword-only
        Largest disagreement between the edge and coverage crossings, in median
        capture intervals, for the edge crossing to be kept.

    Returns
    -------
    xarray.Dataset
        As :func:`arrival_dataset`; ``arrival_frame`` clamped to the sequence.
    """
    check_positive(tolerance_intervals, "tolerance_intervals")
    time_s = edges["time_s"].values
    interval = median_interval(time_s)
    sky = photometry["sky"].values.astype(bool)
    lit = photometry["lit_at_start"].values.astype(bool)
    pixels = {name: edges[name].values for name in EPISODE_KEYS if name in edges}
    result = arrivals(edges["edge_row"].values, time_s, pixels, sky=sky, lit_at_start=lit,
                      tolerance_s=tolerance_intervals * interval)
    return arrival_dataset(result["arrival_s"], time_to_frame(result["arrival_s"], time_s, outside="clamp"),
                           result["reason"], edge_arrival_s=result["edge_s"], coverage_arrival_s=result["coverage_s"],
                           interval_s=interval, events=result["events"])
