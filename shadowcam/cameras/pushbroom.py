"""Shadow pushbroom: the image along the moving shadow edge, for the outdoor ridge (paper
section VII, Fig. 18) and the lab's single sweep (Fig. 10 IV-V, Fig. 11) alike.

Outdoor: the edge row per (frame, column) comes from edge tracking. Lab: for a wire whose
shadow runs along the camera's columns (a vertical wire), the edge column per (frame, row)
is where the shadow-time map ``t(row, col)`` crosses the frame, found sub-pixel by
:func:`edge_from_time_map` (``along="row"``); for a horizontal wire the roles of rows and
columns swap. Both then read the colours along the edge with the same functions.

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
assemble_pushbroom : the (time, col, channel) pushbroom from all edge curves (or (time, row,
    channel) with ``along="row"``).
resample_uniform_time : rows resampled to evenly spaced times.
edge_from_time_map : the lab's edge per (frame, row) from a shadow-time map.
pushbroom_from_shadow_time : the lab pushbroom dataset of one sweep (front function).
shadow_line_axis : the camera axis a sweep's shadow line runs along.
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


def assemble_pushbroom(reference, edge_row, *, along="col"):
    """Return the pushbroom.

    Parameters
    ----------
    reference : (H, W, C) ndarray
        The registered first frame (colour source; see the module docstring).
    edge_row : (T, W) ndarray
        Edge rows per frame (pixel-edge coordinates); with ``along="row"`` a (T, H) array
        of edge columns per row.
    along : {"col", "row"}, keyword-only
        The camera axis the edge runs along: ``col`` (the outdoor ridge: one edge row per
        column) or ``row`` (a vertical wire's shadow: one edge column per row).

    Returns
    -------
    (T, W, C) ndarray, or (T, H, C) with ``along="row"``
        Row k = colours along the edge of frame k.
    """
    edge = np.asarray(edge_row)
    check_array(edge, "edge_row", ndim=2)
    if along not in ("col", "row"):
        raise ValueError(f"along must be one of 'col', 'row'; got {along!r}")
    if along == "row":
        reference = np.asarray(reference).transpose(1, 0, 2)
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


def edge_from_time_map(shadow_time, frames, *, along="row"):
    """Where the shadow edge is in each frame: the crossing of the shadow-time map.

    Along each camera row (``along="row"``: the edge runs along the rows' direction, one
    edge column per row) the edge at frame k lies between the first pair of neighbouring
    pixels whose times bracket k, linearly interpolated between their centres.

    Parameters
    ----------
    shadow_time : (H, W) ndarray
        Shadow times (frames); NaN = none (no crossing through a NaN pixel).
    frames : (T,) array_like
        Frame indices (fractional allowed).
    along : {"row", "col"}, keyword-only
        ``row``: edge column per (frame, row); ``col``: edge row per (frame, column).

    Returns
    -------
    (T, H) float64 ndarray, or (T, W) with ``along="col"``
        Edge positions in pixel-edge coordinates (pixel i has its centre at i + 0.5), NaN
        where the frame crosses no pair of timed neighbours.
    """
    t = check_array(np.asarray(shadow_time, dtype=np.float64), "shadow_time", ndim=2)
    if along not in ("col", "row"):
        raise ValueError(f"along must be one of 'col', 'row'; got {along!r}")
    frames = check_array(np.asarray(frames, dtype=np.float64), "frames", ndim=1)
    if along == "col":
        t = t.T
    left, right = t[:, :-1], t[:, 1:]
    out = np.full((frames.size, t.shape[0]), np.nan)
    cols = np.arange(left.shape[1])
    for k, frame in enumerate(frames):
        with np.errstate(invalid="ignore", divide="ignore"):
            lo, hi = np.minimum(left, right), np.maximum(left, right)
            bracket = (lo <= frame) & (frame <= hi) & (hi > lo)
            frac = (frame - left) / (right - left)
        first = np.where(bracket.any(axis=1), np.argmax(bracket, axis=1), -1)
        has = first >= 0
        rows = np.nonzero(has)[0]
        out[k, rows] = cols[first[has]] + 0.5 + frac[rows, first[has]]
    return out


def pushbroom_from_shadow_time(shadow_time, *, sweep, reference=None):
    """The lab shadow pushbroom of one sweep (Fig. 10 IV-V): shadow time x position along
    the shadow line.

    The colours come from the sweep's lit image (the scene lit by the light and seen by the
    camera, the paper's Fig. 10(V) look) or `reference`, read at the edge of each frame.

    Parameters
    ----------
    shadow_time : xarray.Dataset
        ``shadow_time (sweep, row, col)``, ``lit_image (sweep, row, col, channel)``; attrs
        ``n_frames_<sweep>``.
    sweep : str, keyword-only
        The sweep's name.
    reference : (H, W, C) ndarray or xarray.Dataset, optional
        Colour source instead of the lit image (a Dataset: a decoded reference frame store).

    Returns
    -------
    xarray.Dataset
        ``pushbroom (time, row, channel)`` float32 (linear, the colour source's units) and
        ``edge (time, row)`` (pixel-edge column of the edge) for a shadow line along the
        camera columns; ``(time, col, channel)`` and the edge row for one along the rows.
        ``time`` is the frame index of the sweep. Attrs ``along`` (``row`` or ``col``: the
        position dimension) and ``sweep``.
    """
    import xarray as xr

    from shadowcam.cameras.dual_view import reference_image

    names = [str(s) for s in shadow_time["sweep"].values]
    if sweep not in names:
        raise ValueError(f"sweep must be one of {names}; got {sweep!r}")
    t = shadow_time["shadow_time"].sel(sweep=sweep).transpose("row", "col").values
    n_frames = int(shadow_time.attrs.get(f"n_frames_{sweep}", 0))
    if n_frames < 2:
        raise ValueError(f"shadow_time: attr n_frames_{sweep} missing or < 2")
    if reference is None:
        reference = shadow_time["lit_image"].sel(sweep=sweep).transpose("row", "col", "channel").values
    elif hasattr(reference, "data_vars"):
        reference = reference_image(reference)
    reference = np.asarray(reference)
    if reference.ndim != 3 or reference.shape[:2] != t.shape:
        raise ValueError(f"reference must be {t.shape + ('C',)}; got shape {reference.shape}")
    along = shadow_line_axis(t)
    edge = edge_from_time_map(t, np.arange(n_frames), along=along)
    image = assemble_pushbroom(reference, edge, along=along)
    channels = shadow_time["channel"].values if "channel" in shadow_time.coords else None
    across = "col" if along == "row" else "row"
    return xr.Dataset(
        {"pushbroom": (("time", along, "channel"), image.astype(np.float32),
                       {"units": "linear intensity of the colour source",
                        "long_name": f"colours along the shadow edge of sweep {sweep}"}),
         "edge": (("time", along), edge.astype(np.float32),
                  {"units": "pixel", "long_name": f"edge {across} (pixel-edge coordinates)"})},
        coords={"time": ("time", np.arange(n_frames), {"units": "frame"}),
                along: (along, np.arange(edge.shape[1]), {"units": "pixel"}),
                **({"channel": channels} if channels is not None else {})},
        attrs={"sweep": sweep, "along": along, "projection": "pushbroom"})


def shadow_line_axis(shadow_time):
    """The camera axis the shadow line runs along, from a shadow-time map.

    Parameters
    ----------
    shadow_time : (H, W) ndarray
        Shadow times; NaN = none.

    Returns
    -------
    str
        ``row`` when the times change faster across columns (a vertical wire: one edge column
        per row), else ``col``.
    """
    t = check_array(np.asarray(shadow_time, dtype=np.float64), "shadow_time", ndim=2)
    with np.errstate(invalid="ignore"):
        d_col = np.nanmedian(np.abs(np.diff(t, axis=1)))
        d_row = np.nanmedian(np.abs(np.diff(t, axis=0)))
    return "col" if d_row > d_col else "row"
