"""Keyframes of the tracked edge, and interpolation of the edge between them.

A frame whose edge is not found reliably (a cloud, heavy noise, a badly
exposed frame) would put a wrong edge into the arrival map. Frames whose
typical edge confidence is high are keyframes; the edge of every other frame,
and every low-confidence column of a keyframe, is replaced by linear
interpolation *in seconds* between the nearest reliable edges of the same
column before and after, and marked as interpolated. Time gaps (dropped
frames) are handled because the interpolation uses the frame times.

Offers
------
select_keyframes : frames whose edge is reliable.
interpolate_edges : fill unreliable edges from the neighbouring reliable ones.
"""

import numpy as np


def select_keyframes(confidence, edge_row, *, min_confidence=0.6, min_found_fraction=0.5):
    """Return which frames are keyframes.

    Parameters
    ----------
    confidence : (T, W) ndarray
        Per-frame, per-column edge confidence (0 where no edge).
    edge_row : (T, W) ndarray
        Edge rows (NaN where no edge).
    min_confidence : float, optional
        A keyframe's median confidence over the columns with an edge.
    min_found_fraction : float, optional
        A keyframe finds an edge in at least this fraction of the median
        (over frames) number of columns with an edge.

    Returns
    -------
    (T,) bool ndarray
    """
    confidence = np.asarray(confidence, dtype=np.float64)
    edge_row = np.asarray(edge_row, dtype=np.float64)
    if confidence.shape != edge_row.shape or confidence.ndim != 2:
        raise ValueError(f"confidence {confidence.shape} and edge_row {edge_row.shape} must be the same (T, W) shape")
    found = np.isfinite(edge_row)
    counts = found.sum(axis=1)
    typical = np.median(counts) if counts.size else 0
    with np.errstate(invalid="ignore"):
        median_conf = np.array([np.median(c[f]) if f.any() else 0.0 for c, f in zip(confidence, found)])
    enough = counts >= min_found_fraction * typical
    return (median_conf >= min_confidence) & enough | (counts == 0) & (typical == 0)


def interpolate_edges(edge_row, confidence, time_s, *, is_keyframe, min_confidence=0.6):
    """Replace unreliable edges by interpolation in time between reliable ones.

    Parameters
    ----------
    edge_row : (T, W) ndarray
        Edge rows (NaN where no edge).
    confidence : (T, W) ndarray
    time_s : (T,) ndarray
        Frame times in seconds (increasing; irregular intervals allowed).
    is_keyframe : (T,) bool ndarray
    min_confidence : float, optional
        Edges of keyframes with lower confidence are interpolated too.

    Returns
    -------
    edge_row : (T, W) float32 ndarray
        Reliable edges kept, the others linearly interpolated in `time_s`
        between the nearest reliable edges of the column (NaN when either
        neighbour is missing or has no edge).
    interpolated : (T, W) bool ndarray
        True where the value was interpolated (or set to NaN) here.
    """
    edge = np.asarray(edge_row, dtype=np.float64)
    conf = np.asarray(confidence, dtype=np.float64)
    times = np.asarray(time_s, dtype=np.float64)
    key = np.asarray(is_keyframe, dtype=bool)
    if edge.ndim != 2 or conf.shape != edge.shape or times.shape != (edge.shape[0],) or key.shape != times.shape:
        raise ValueError(
            f"edge_row {edge.shape}, confidence {conf.shape} must be (T, W); time_s {times.shape} and "
            f"is_keyframe {key.shape} must be (T,)"
        )
    if np.any(np.diff(times) <= 0):
        raise ValueError("time_s must increase strictly (sort the frames by time)")
    # reliable = keyframe and (confident edge, or no edge at all: a fully lit / shadowed column)
    reliable = key[:, None] & ((conf >= min_confidence) | ~np.isfinite(edge))
    out = edge.copy()
    n_frames, width = edge.shape
    index = np.arange(n_frames)
    for col in range(width):
        good = reliable[:, col]
        bad = ~good
        if not bad.any():
            continue
        if not good.any():
            out[:, col] = np.nan
            continue
        good_idx = index[good]
        after = np.searchsorted(good_idx, index[bad])
        before = after - 1
        has_both = (before >= 0) & (after < good_idx.size)
        b_idx = good_idx[np.clip(before, 0, good_idx.size - 1)]
        a_idx = good_idx[np.clip(after, 0, good_idx.size - 1)]
        t, tb, ta = times[bad], times[b_idx], times[a_idx]
        yb, ya = edge[b_idx, col], edge[a_idx, col]
        frac = np.where(ta > tb, (t - tb) / np.where(ta > tb, ta - tb, 1.0), 0.0)
        out[bad, col] = np.where(has_both, yb + frac * (ya - yb), np.nan)
    return out.astype(np.float32), ~reliable
