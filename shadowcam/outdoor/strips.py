"""The outdoor edge-tracking pass in column strips, merged exactly.

The second outdoor pass (:mod:`shadowcam.outdoor.tracking`) cannot be split
in time (its per-pixel lit level, the column's last edge and a pending
coverage crossing reach arbitrarily far back), but it can be split in space.
Its spatial dependencies across columns are:

* the registration shift: cubic resampling reads columns ``floor(c + shift_col) - 1
  .. + 2``, so ``ceil(max |shift_col|) + 2`` columns (bits independent of the cut:
  :func:`shadowcam.outdoor.translation.translate`, ``"cubic_Keys1981"``);
* the frame-differencing band: the coverage drop is widened by ``margin``
  columns (:func:`shadowcam.outdoor.frame_difference.difference_band`);
* ``band_fraction``, a whole-frame mean: reassembled exactly from per-strip
  integer counts (band pixels and valid pixels of the strip's own columns).

* the penumbra fit's neighbours' duration (:func:`shadowcam.outdoor.descent.fit_descents`):
  :data:`~shadowcam.outdoor.descent.NEIGHBOUR_RADIUS` pixels each side.

Everything else is per pixel (luminance, coverage, lit-level update, coverage
crossing, the fit of the final descent) or per column (the edge search, its tracking prior and the area
estimator, which sums rows). A strip of columns ``[c0, c1)`` therefore streams
every frame over the window ``[c0 - halo, c1 + halo)`` and keeps only its own
columns. The band of a halo column next to the window's cut can be wrong; that
changes the halo column's edge and lit level and, through the next frames'
band, can creep inward by up to ``margin`` columns a frame where columns have
several transitions; a soft edge (the penumbra of the real sun behind a far ridge, many rows
wide) spreads those band errors over its whole width, so the halo grows by the edge's
measured width in rows (:func:`edge_width`). The default halo adds :data:`GUARD_COLUMNS`, and
each strip also keeps the column on either side of its own, which the
neighbouring strip owns: :func:`merge_strips` refuses to merge strips that do
not agree there (then raise the halo). On the seeded synthetic scene and on
dev_ridge the strips equal the single job bit for bit already with a guard of 0.

Offers
------
strip_bounds : column ranges of n equal strips.
edge_width : the first frame's shadow-edge width in rows (penumbra), measured.
strip_halo : halo columns needed for a photometry's shifts, edge width and the tracking options.
strip_window : the columns a strip reads (its own plus the halo, clipped to the frame).
track_strip : run the tracking pass on one strip.
merge_strips : join strips into the single job's result.
save_strip : write a strip to ``.npz`` atomically.
load_strip : read it back.
"""

import math

import numpy as np

from shadowcam._shared.atomic import atomic_path
from shadowcam.outdoor.descent import NEIGHBOUR_RADIUS
from shadowcam.outdoor.tracking import PIXEL_KEYS, EdgeTracker

#: extra halo columns against the band errors creeping in from the window's cut
GUARD_COLUMNS = 8
#: per-frame (time, col) results of the pass
COLUMN_KEYS = ("edge_row", "confidence", "n_transitions")
#: arrays of a strip file (:func:`save_strip`)
STRIP_KEYS = ("cols", "kept", "width", "edge_row", "confidence", "n_transitions", *PIXEL_KEYS,
              "band_count", "valid_count")


def strip_bounds(width, n_strips):
    """Return ``[(c0, c1), ...]``: `n_strips` contiguous column ranges covering ``[0, width)``."""
    if not 1 <= int(n_strips) <= int(width):
        raise ValueError(f"n_strips must be between 1 and the frame width {width}; got {n_strips}")
    edges = np.linspace(0, int(width), int(n_strips) + 1).round().astype(int)
    return [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]


def edge_width(reference_luma, *, lit_level, shadow_level, lit_at_start, sky):
    """Width in rows of the shadow edge in the first frame, measured from its partly lit pixels.

    The pixels shadowed in the first frame have a measured shadow level (the sequence's
    minimum) and a lit level (the shadow level over the shadow ratio), so their lit fraction
    in the first frame is known; those strictly between 0.1 and 0.9 lie in the penumbra's
    shadow-side half (the lit side is taken for lit and has no level below it yet).

    Parameters
    ----------
    reference_luma : (H, W) ndarray
        Luminance of the first frame.
    lit_level, shadow_level : (H, W) ndarray
        The first pass's levels (:func:`shadowcam.outdoor.normalise.normalise_frames`).
    lit_at_start, sky : (H, W) bool ndarray

    Returns
    -------
    float
        Twice the median count of such pixels per column, over the columns that have a
        lit / shadowed boundary; 0 where none has one.
    """
    ref = np.asarray(reference_luma, dtype=np.float64)
    lit_level = np.asarray(lit_level, dtype=np.float64)
    shadow_level = np.asarray(shadow_level, dtype=np.float64)
    lit = np.asarray(lit_at_start, dtype=bool)
    sky = np.asarray(sky, dtype=bool)
    if ref.ndim != 2 or not (ref.shape == lit_level.shape == shadow_level.shape == lit.shape == sky.shape):
        raise ValueError(f"reference_luma {ref.shape}, lit_level {lit_level.shape}, shadow_level {shadow_level.shape}, "
                         f"lit_at_start {lit.shape} and sky {sky.shape} must be the same (H, W) shape")
    shadowed = ~lit & ~sky & (lit_level > shadow_level)
    with np.errstate(divide="ignore", invalid="ignore"):
        cover = (ref - shadow_level) / (lit_level - shadow_level)
    partial = shadowed & (cover > 0.1) & (cover < 0.9)
    boundary = shadowed.any(axis=0) & (lit & ~sky).any(axis=0)
    if not boundary.any():
        return 0.0
    return 2.0 * float(np.median(partial.sum(axis=0)[boundary]))


def strip_halo(shift, *, margin=2, guard=GUARD_COLUMNS, edge_width_rows=0.0):
    """Return the halo (columns each side of a strip) for the tracking pass.

    Parameters
    ----------
    shift : (T, 2) ndarray
        Per-frame ``(shift_row, shift_col)`` of the photometry (pixels).
    margin : int, optional
        Frame-differencing widening (the tracking option of the same name).
    guard : int, optional
        Extra columns (see the module notes).
    edge_width_rows : float, optional
        Measured width of the shadow edge (:func:`edge_width`).

    Returns
    -------
    int
        ``ceil(max |shift_col|) + 2 + margin + NEIGHBOUR_RADIUS + guard + ceil(edge_width_rows)``.
    """
    shift = np.asarray(shift, dtype=np.float64)
    if shift.ndim != 2 or shift.shape[1] != 2 or not np.all(np.isfinite(shift)):
        raise ValueError(f"shift must be a finite (T, 2) array; got shape {shift.shape}")
    if margin < 0 or guard < 0 or not edge_width_rows >= 0:
        raise ValueError(f"margin, guard and edge_width_rows must be >= 0; got {margin}, {guard}, {edge_width_rows}")
    largest = float(np.abs(shift[:, 1]).max()) if shift.size else 0.0
    return (int(math.ceil(largest)) + 2 + int(margin) + NEIGHBOUR_RADIUS + int(guard)
            + int(math.ceil(edge_width_rows)))


def strip_window(cols, halo, width):
    """Return ``(a, b)``: the columns strip `cols` ``(c0, c1)`` reads, ``[c0 - halo, c1 + halo)`` clipped."""
    c0, c1 = (int(c) for c in cols)
    if not 0 <= c0 < c1 <= width:
        raise ValueError(f"cols must be (c0, c1) with 0 <= c0 < c1 <= {width}; got {cols}")
    if halo < 0:
        raise ValueError(f"halo must be >= 0; got {halo}")
    return max(0, c0 - int(halo)), min(int(width), c1 + int(halo))


def _window_photometry(photometry, window):
    a, b = window
    cut = {key: (value[:, a:b] if np.ndim(value) == 2 and key not in ("shift",) else value)
           for key, value in photometry.items()}
    if cut.get("shade_cols") is not None:  # the shade field's block centres in the window's columns
        cut["shade_cols"] = np.asarray(cut["shade_cols"], dtype=np.float64) - a
    return cut


def track_strip(frames, photometry, time_s, *, cols, halo=None, **options):
    """Run the tracking pass on the columns `cols` of the frames.

    Parameters
    ----------
    frames : iterable of (H, W, C) or (H, b - a, C) ndarray
        In time order: whole frames, or only the strip's window ``(a, b)``
        (:func:`strip_window`; reading only those columns is what saves memory).
    photometry : mapping
        Whole-frame photometry (:class:`shadowcam.outdoor.tracking.EdgeTracker`).
    time_s : (T,) ndarray
    cols : (2,) tuple of int
        The strip's own columns ``[c0, c1)``.
    halo : int, optional
        Columns read each side; default :func:`strip_halo` of the photometry's shifts.
    **options
        Keyword options of :class:`~shadowcam.outdoor.tracking.EdgeTracker`.

    Returns
    -------
    dict
        ``cols (c0, c1)``, ``kept (k0, k1)`` (the strip's columns plus one each side,
        clipped: the columns of the arrays), ``width``; ``edge_row``, ``confidence``,
        ``n_transitions`` ``(T, k1 - k0)``; :data:`~shadowcam.outdoor.tracking.PIXEL_KEYS` ``(H, k1 - k0, ...)``;
        ``band_count (T,)`` int64 and ``valid_count`` (band and valid pixels of the
        strip's own columns).
    """
    height, width = np.shape(photometry["sky"])
    if halo is None:
        halo = strip_halo(photometry["shift"], margin=options.get("margin", 2))
    window = strip_window(cols, halo, width)
    (c0, c1), (a, b) = cols, window
    kept = (max(0, c0 - 1), min(width, c1 + 1))
    tracker = EdgeTracker(_window_photometry(photometry, window), time_s, count_cols=(c0 - a, c1 - a), **options)
    for frame in frames:
        if frame.shape[1] == width and width != b - a:
            frame = frame[:, a:b]
        elif frame.shape[1] != b - a:
            raise ValueError(f"frames must be {width} columns wide or the strip's window {window}; "
                             f"got shape {frame.shape}")
        tracker.update(frame)
    result = tracker.result()
    local = np.s_[:, kept[0] - a:kept[1] - a]
    strip = {key: result[key][local] for key in (*COLUMN_KEYS, *PIXEL_KEYS)}
    strip.update(cols=(int(c0), int(c1)), kept=kept, width=int(width), band_count=tracker.band_count,
                 valid_count=tracker.valid_count)
    return strip


def _same(x, y):
    return np.array_equal(x, y, equal_nan=np.issubdtype(np.asarray(x).dtype, np.floating))


def merge_strips(strips):
    """Join column strips (:func:`track_strip`) into the single job's result.

    Parameters
    ----------
    strips : sequence of dict
        Strips covering the frame's columns without gaps or overlap (any order).

    Returns
    -------
    dict
        As :func:`shadowcam.outdoor.tracking.track_frames`: ``edge_row``,
        ``confidence``, ``n_transitions`` ``(T, W)``, ``band_fraction (T,)``
        (float32 of the summed band count over the summed valid count, which is
        how the single job's mean rounds), :data:`~shadowcam.outdoor.tracking.PIXEL_KEYS` ``(H, W, ...)``.

    Raises
    ------
    ValueError
        When the strips do not tile the frame, or two neighbours disagree on the
        columns next to their boundary (the halo was too narrow for the sequence).
    """
    strips = sorted(strips, key=lambda s: s["cols"][0])
    if not strips:
        raise ValueError("strips is empty; give the results of track_strip")
    width = strips[0]["width"]
    starts = [s["cols"][0] for s in strips]
    stops = [s["cols"][1] for s in strips]
    if starts[0] != 0 or stops[-1] != width or starts[1:] != stops[:-1] or {s["width"] for s in strips} != {width}:
        raise ValueError(f"strips must tile columns [0, {width}) without gaps or overlap; got {list(zip(starts, stops))}")
    for left, right in zip(strips[:-1], strips[1:]):
        boundary = left["cols"][1]
        for key in (*COLUMN_KEYS, *PIXEL_KEYS):
            mine = left[key][:, boundary - 1 - left["kept"][0]:boundary + 1 - left["kept"][0]]
            theirs = right[key][:, boundary - 1 - right["kept"][0]:boundary + 1 - right["kept"][0]]
            if not _same(mine, theirs):
                raise ValueError(
                    f"strips {left['cols']} and {right['cols']} disagree on {key} at columns "
                    f"{boundary - 1}-{boundary}: the halo is too narrow for this sequence; raise it")
    merged = {key: np.concatenate([s[key][:, s["cols"][0] - s["kept"][0]:s["cols"][1] - s["kept"][0]]
                                   for s in strips], axis=1)
              for key in (*COLUMN_KEYS, *PIXEL_KEYS)}
    band = np.sum([s["band_count"] for s in strips], axis=0).astype(np.float64)
    valid = float(sum(s["valid_count"] for s in strips))
    merged["band_fraction"] = (band / valid if valid else np.zeros_like(band)).astype(np.float32)
    return {key: merged[key] for key in ("edge_row", "confidence", "n_transitions", "band_fraction",
                                         *PIXEL_KEYS)}


def save_strip(strip, path):
    """Write `strip` (:func:`track_strip`) to `path` (``.npz``) atomically."""
    if not str(path).endswith(".npz"):
        raise ValueError(f"path must end with .npz; got {path}")
    with atomic_path(path) as tmp:
        np.savez(tmp, **{key: np.asarray(strip[key]) for key in STRIP_KEYS})


def load_strip(path):
    """Read a strip written by :func:`save_strip` (dict as :func:`track_strip` returns)."""
    with np.load(path) as data:
        missing = set(STRIP_KEYS) - set(data.files)
        if missing:
            raise ValueError(f"{path} is not an edge-tracking strip: missing {sorted(missing)}; "
                             "rerun track-edges-strip")
        strip = {key: data[key] for key in STRIP_KEYS}
    for key in ("cols", "kept"):
        strip[key] = tuple(int(v) for v in strip[key])
    for key in ("width", "valid_count"):
        strip[key] = int(strip[key])
    return strip
