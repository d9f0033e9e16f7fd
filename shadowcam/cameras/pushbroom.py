"""Ridge pushbroom (paper section VII, Fig. 18): the image along the moving shadow edge.

For each frame, the intensities along the tracked edge curve are read out and
stacked over time: output row ``k`` is frame ``k`` (time ``time_s[k]``), output
column ``c`` is image column ``c``. The colour is taken from the **registered
first frame** (the reference), in which every pixel the shadow later reaches
is still sunlit, so the pushbroom shows the surface under one illumination
(the same convention as the dev data's ground-truth ``pb_front``); it is
sampled at the edge row, linearly between the two pixel centres that
straddle it (pixel-edge coordinates: row ``r`` has its centre at ``r + 0.5``).
Columns without an edge in a frame are NaN. :func:`resample_uniform_time`
puts the rows on a regular time grid for display (irregular intervals and
gaps in the capture would otherwise distort the time axis).

Offers
------
sample_along_edge : the colours at one edge curve.
assemble_pushbroom : the (time, col, channel) pushbroom from all edge curves.
resample_uniform_time : rows resampled to evenly spaced times.
"""

import numpy as np

from shadowcam._shared.validation import check_array, check_positive


def sample_along_edge(image, edge_row):
    """Return the colours of `image` at the edge curve.

    Parameters
    ----------
    image : (H, W, C) ndarray
    edge_row : (W,) ndarray
        Edge row per column, pixel-edge coordinates (NaN = none).

    Returns
    -------
    (W, C) ndarray
        Same float dtype as `image`; NaN where the edge is NaN.
    """
    image = np.asarray(image)
    edge = np.asarray(edge_row, dtype=np.float64)
    if image.ndim != 3 or edge.shape != (image.shape[1],):
        raise ValueError(f"image must be (H, W, C) and edge_row (W,); got {image.shape} and {edge.shape}")
    height, width = image.shape[:2]
    position = np.clip(np.nan_to_num(edge, nan=0.5) - 0.5, 0.0, height - 1.0)  # centre coordinates
    lower = np.minimum(np.floor(position).astype(int), height - 2) if height > 1 else np.zeros(width, int)
    frac = (position - lower)[:, None] if height > 1 else np.zeros((width, 1))
    cols = np.arange(width)
    upper = np.minimum(lower + 1, height - 1)
    out = (1 - frac) * image[lower, cols] + frac * image[upper, cols]
    out = out.astype(image.dtype if np.issubdtype(image.dtype, np.floating) else np.float32)
    out[~np.isfinite(edge)] = np.nan
    return out


def assemble_pushbroom(reference, edge_row):
    """Return the ridge pushbroom.

    Parameters
    ----------
    reference : (H, W, C) ndarray
        The registered first frame (colour source; see the module docstring).
    edge_row : (T, W) ndarray
        Edge rows per frame.

    Returns
    -------
    (T, W, C) ndarray
        Row k = colours along the edge of frame k.
    """
    edge = np.asarray(edge_row)
    check_array(edge, "edge_row", ndim=2)
    return np.stack([sample_along_edge(reference, row) for row in edge])


def resample_uniform_time(pushbroom, time_s, *, step_s):
    """Resample pushbroom rows to evenly spaced times (linear; NaN stays NaN).

    Parameters
    ----------
    pushbroom : (T, W, C) ndarray
    time_s : (T,) ndarray
        Increasing frame times.
    step_s : float
        Spacing of the output times (e.g. the median capture interval).

    Returns
    -------
    times : (T_out,) ndarray
        ``time_s[0], time_s[0] + step_s, ...`` up to ``time_s[-1]``.
    image : (T_out, W, C) ndarray
    """
    data = np.asarray(pushbroom, dtype=np.float64)
    times = np.asarray(time_s, dtype=np.float64)
    if data.ndim != 3 or times.shape != (data.shape[0],):
        raise ValueError(f"pushbroom must be (T, W, C) and time_s (T,); got {data.shape}, {times.shape}")
    check_positive(step_s, "step_s")
    grid = np.arange(times[0], times[-1] + 1e-9 * step_s, step_s)
    after = np.clip(np.searchsorted(times, grid, side="right"), 1, times.size - 1)
    before = after - 1
    frac = ((grid - times[before]) / (times[after] - times[before]))[:, None, None]
    out = (1 - frac) * data[before] + frac * data[after]
    return grid, out.astype(np.asarray(pushbroom).dtype)
