"""A passing cloud's shade at the ridge shadow's edge, measured just above it and divided out.

Under a cloud the sun term of a point is dimmed by the cloud's transmittance ``T``; its lit
fraction (coverage) reads ``T`` where it is sunlit and stays near 0 where the ridge shadows
it. A cloud is large and smooth next to the ridge edge's pixel-sharp front, so in each
column the coverage of the pixels a few rows above the edge (sunlit as far as the ridge is
concerned) measures ``T`` there, and dividing the coverage of the rows below by it gives
back the ridge shadow alone: the edge and the pixels' arrival are found where the ridge
puts them even while a cloud is over them.

A column is corrected only when its reference rows are clearly dimmed: their median below
the "fully lit" coverage of the tracker (0.9) and below 1 by more than three times its own
standard error (from the rows' spread), so noise alone never triggers it.

Offers
------
shade_above_edge : the cloud transmittance just above each column's edge.
remove_shade : divide it out of the coverage of the rows at and below the reference rows.
"""

import numpy as np

#: coverage of a fully lit pixel (the tracker updates its lit level above it)
FULLY_LIT = 0.9


def shade_above_edge(cover, edge_row, *, valid, gap=4, rows=8):
    """Transmittance of a passing shade just above each column's edge.

    Parameters
    ----------
    cover : (H, W) ndarray
        Coverage of the frame.
    edge_row : (W,) ndarray
        The columns' edge rows (pixel-edge coordinates; NaN: none, no correction).
    valid : (H, W) bool ndarray
        Pixels that may serve as reference: sunlit as far as the ridge is concerned (the
        tracker: lit at start, not sky, and lit in the previous frame once its shade was divided
        out; rows the ridge's shadow has reached read near 0, which no division should take for
        a cloud's shade).
    gap, rows : int, keyword-only
        The reference rows are the `rows` rows ending `gap` rows above the edge.

    Returns
    -------
    (W,) float32 ndarray
        Median coverage of the reference rows where they are clearly dimmed, else 1.
    """
    cover = np.asarray(cover, dtype=np.float32)
    valid = np.asarray(valid, dtype=bool)
    edge = np.asarray(edge_row, dtype=np.float64)
    height, width = cover.shape
    if valid.shape != cover.shape or edge.shape != (width,):
        raise ValueError(f"cover {cover.shape}, valid {valid.shape} must be (H, W) and edge_row {edge.shape} (W,)")
    if int(gap) < 0 or int(rows) < 3:
        raise ValueError(f"gap must be >= 0 and rows >= 3; got {gap}, {rows}")
    shade = np.ones(width, dtype=np.float32)
    has = np.isfinite(edge)
    if not has.any():
        return shade
    bottom = np.floor(np.where(has, edge, 0.0)).astype(np.int64) - int(gap)
    index = bottom[None, :] - np.arange(1, int(rows) + 1)[:, None]
    inside = (index >= 0) & has[None, :]
    cols = np.broadcast_to(np.arange(width), index.shape)
    clipped = np.clip(index, 0, height - 1)
    use = inside & valid[clipped, cols] & np.isfinite(cover[clipped, cols])
    values = np.where(use, cover[clipped, cols], np.nan)
    count = use.sum(axis=0)
    enough = count >= 3
    if not enough.any():
        return shade
    with np.errstate(invalid="ignore"):
        median = np.nanmedian(values[:, enough], axis=0)
        spread = 1.4826 * np.nanmedian(np.abs(values[:, enough] - median), axis=0)
    error = 1.2533 * spread / np.sqrt(count[enough])
    dimmed = (median < FULLY_LIT) & (1.0 - median > 3.0 * error) & (median > 0)
    shade[np.flatnonzero(enough)[dimmed]] = median[dimmed]
    return shade


def remove_shade(cover, shade, edge_row, *, gap=4, rows=8):
    """Divide the shade out of the coverage of the reference rows and everything below them.

    Parameters
    ----------
    cover : (H, W) ndarray
    shade : (W,) ndarray
        :func:`shade_above_edge`.
    edge_row : (W,) ndarray
    gap, rows : int, keyword-only
        As :func:`shade_above_edge`.

    Returns
    -------
    (H, W) float32 ndarray
        A copy of `cover`, divided by `shade` from the top reference row down.
    """
    cover = np.array(cover, dtype=np.float32)
    shade = np.asarray(shade, dtype=np.float32)
    edge = np.asarray(edge_row, dtype=np.float64)
    dimmed = np.flatnonzero((shade < 1) & np.isfinite(edge))
    if not dimmed.size:
        return cover
    top = np.maximum(np.floor(edge[dimmed]).astype(np.int64) - int(gap) - int(rows), 0)
    below = np.arange(cover.shape[0])[:, None] >= top[None, :]
    block = cover[:, dimmed]  # only the dimmed columns: (H, n) temporaries
    np.divide(block, shade[dimmed][None, :], out=block, where=below)
    cover[:, dimmed] = block
    return cover
