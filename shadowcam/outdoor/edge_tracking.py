"""Shadow-edge tracking: the edge curve of one frame, column by column, sub-pixel.

In a sunset time-lapse the cast shadow of a ridge climbs the view: lit above,
shadowed below. In each image column the edge is the lowest pair of
vertically adjacent valid pixels with the upper one lit (coverage >= 0.5)
and the lower one shadowed (the ground-truth convention of the dev data).
Its sub-pixel row comes from the area (moment) estimator: for a box-filtered
step, the sum of the lit fractions over a window of ``2 h`` rows straddling
the edge is the distance from the window's top to the edge, exactly, and for
a straight edge slanted across the column it is the edge's row at the column
centre. Coverage noise averages over the window instead of being amplified
by a gradient.

Rows are in pixel-edge coordinates: pixel row ``r`` spans ``[r, r + 1]``,
its centre is ``r + 0.5``; an edge at ``y`` means rows ``r < y - 0.5`` have their
centre lit.

Offers
------
column_edges : edge row, confidence and number of transitions per column.
"""

import numpy as np


def column_edges(cover, *, valid, band=None, previous=None, half_window=3, max_step=3.0):
    """Locate the shadow edge in every column of one frame.

    Parameters
    ----------
    cover : (H, W) ndarray
        Coverage (lit fraction) of the frame: 1 lit, 0 shadowed.
    valid : (H, W) bool ndarray
        Pixels that can hold the edge (not sky).
    band : (H, W) bool ndarray, optional
        Frame-differencing band (:func:`shadowcam.outdoor.frame_difference.difference_band`);
        transitions inside the band are preferred (the shadow edge moves; a
        static lit-above / shadowed-below pair, e.g. a pixel shadowed from the
        start but bright enough to be taken for lit, does not); without one,
        transitions within `max_step` rows of `previous`; other transitions
        are used only if there is neither.
    previous : (W,) ndarray, optional
        Edge rows of the previous frame (NaN where none).
    half_window : int, optional
        ``h``: the area estimator sums ``2 h`` rows around the transition.
    max_step : float, optional
        Rows the edge may move between frames and still count as tracked.

    Returns
    -------
    edge_row : (W,) float32 ndarray
        Sub-pixel edge row (pixel-edge coordinates); NaN where the column has
        no lit-above / shadowed-below transition.
    confidence : (W,) float32 ndarray
        ``1 - 4 * mean |coverage - ideal step|`` over the window, clipped to
        [0, 1], halved when the transition was not in the band nor near the
        previous edge; 0 where no edge.
    n_transitions : (W,) int16 ndarray
        Number of lit-above / shadowed-below pairs in the column.
    """
    cover = np.asarray(cover, dtype=np.float32)
    valid = np.asarray(valid, dtype=bool)
    if cover.ndim != 2 or valid.shape != cover.shape:
        raise ValueError(f"cover {cover.shape} and valid {valid.shape} must be the same (H, W) shape")
    if half_window < 1:
        raise ValueError(f"half_window must be >= 1; got {half_window}")
    height, width = cover.shape
    clipped = np.clip(cover, np.float32(0.0), np.float32(1.0))
    clipped[np.isnan(clipped)] = 0.0
    usable = valid & np.isfinite(cover)
    lit = (clipped >= 0.5) & usable
    pairs = lit[:-1] & ~lit[1:] & usable[1:]
    n_transitions = pairs.sum(axis=0).astype(np.int16)
    # the shadow edge moves: transitions in the frame-differencing band come first, then those
    # near the column's previous edge (a frame where the edge barely moved), then any
    in_band = np.zeros_like(pairs)
    if band is not None:
        band = np.asarray(band, dtype=bool)
        in_band = pairs & (band[:-1] | band[1:])
    near = np.zeros_like(pairs)
    if previous is not None:
        prev = np.asarray(previous, dtype=np.float64)
        boundary = np.arange(1, height, dtype=np.int32)[:, None]
        # |boundary - prev| <= max_step for integer boundaries, without an (H, W) float temporary
        with np.errstate(invalid="ignore"):
            low, high = np.ceil(prev - max_step)[None, :], np.floor(prev + max_step)[None, :]
            near = pairs & (boundary >= low) & (boundary <= high)
    use_band = in_band.any(axis=0)
    preferred = np.where(use_band[None, :], in_band, near)
    use_preferred = preferred.any(axis=0)
    chosen = np.where(use_preferred[None, :], preferred, pairs)
    has = chosen.any(axis=0)
    # lowest pair (rows r, r + 1) per column: a max over rows, fast along contiguous rows
    index_type = np.uint16 if height < 2**16 else np.uint32
    last = np.max(chosen * np.arange(1, height, dtype=index_type)[:, None], axis=0).astype(np.int64) - 1
    last = np.where(has, last, height - 2)
    offsets = np.arange(-half_window + 1, half_window + 1)  # rows of the window, relative to r
    rows = last[None, :] + offsets[:, None]
    inside = (rows >= 0) & (rows < height)
    rows_c = np.clip(rows, 0, height - 1)
    cols = np.broadcast_to(np.arange(width), rows.shape)
    ideal_default = (offsets <= 0).astype(np.float32)[:, None]
    ok = inside & usable[rows_c, cols]
    values = np.where(ok, clipped[rows_c, cols], ideal_default)
    top = last - half_window + 1
    edge = top + values.sum(axis=0)
    ideal = np.clip(edge[None, :] - rows, 0.0, 1.0)
    resid = np.abs(values - ideal).mean(axis=0)
    confidence = np.clip(1.0 - 4.0 * resid, 0.0, 1.0)
    if band is not None or previous is not None:
        confidence = np.where(use_preferred, confidence, 0.5 * confidence)
    edge_row = np.where(has, edge, np.nan).astype(np.float32)
    confidence = np.where(has, confidence, 0.0).astype(np.float32)
    return edge_row, confidence, n_transitions
