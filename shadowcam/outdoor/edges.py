"""The shadow edge of every outdoor frame: tracking, keyframes and the edges dataset.

The second outdoor pass streams the registered frames through the edge tracker
(:mod:`shadowcam.outdoor.tracking`), in one job or in column strips merged
exactly (:mod:`shadowcam.outdoor.strips`); then keyframes are chosen and the
edges of unreliable frames interpolated in seconds (:mod:`shadowcam.outdoor.keyframes`).

Offers
------
TRACK_OPTIONS : options of the tracking pass.
KEYFRAME_OPTIONS : options of the keyframe selection and interpolation.
track_edges : frame store + photometry dataset -> edges dataset (one job).
edges_from_strips : column strips of :func:`track_column_strip` + photometry -> the same edges dataset.
track_column_strip : the tracking pass on one column strip of a frame store.
"""

import json
import logging

from shadowcam.io.frame_store import iter_store_frames
from shadowcam.io.frame_times import find_gaps, median_interval
from shadowcam.outdoor.clipping import store_white_level
from shadowcam.outdoor.datasets import edges_dataset, photometry_arrays
from shadowcam.outdoor.keyframes import interpolate_edges, select_keyframes
from shadowcam.outdoor.photometric import luminance
from shadowcam.outdoor.strips import edge_width, merge_strips, strip_bounds, strip_halo, strip_window, track_strip
from shadowcam.outdoor.tracking import track_frames

log = logging.getLogger(__name__)

TRACK_OPTIONS = frozenset({"clipping", "half_window", "min_drop", "margin", "max_step", "lit_update",
                           "update_distance", "descent_frames", "max_sigma"})
KEYFRAME_OPTIONS = frozenset({"min_confidence", "min_found_fraction"})


def _check_options(options, allowed, name):
    unknown = set(options) - set(allowed)
    if unknown:
        raise ValueError(f"{name}: unknown option(s) {sorted(unknown)}; allowed {sorted(allowed)}")


def _white_level(frames, options):
    """The store's white level where the ``clipping`` option (popped from `options`) asks for it."""
    return store_white_level(frames) if options.pop("clipping", True) else None


def _edges(tracked, arrays, time_s, options):
    key_options = {k: v for k, v in options.items() if k in KEYFRAME_OPTIONS}
    is_keyframe = select_keyframes(tracked["confidence"], tracked["edge_row"], **key_options)
    edge_row, interpolated = interpolate_edges(
        tracked["edge_row"], tracked["confidence"], time_s, is_keyframe=is_keyframe,
        min_confidence=key_options.get("min_confidence", 0.6))
    dataset = edges_dataset(tracked, arrays, time_s, edge_row=edge_row, is_keyframe=is_keyframe,
                            interpolated=interpolated)
    dataset.attrs.update(median_interval_s=median_interval(time_s), gaps=json.dumps(find_gaps(time_s)))
    return dataset


def _edge_width(photometry, arrays):
    """The first frame's measured edge width in rows (:func:`shadowcam.outdoor.strips.edge_width`)."""
    return edge_width(luminance(photometry["reference"].values), lit_level=arrays["lit_level"],
                      shadow_level=arrays["shadow_level"], lit_at_start=arrays["lit_at_start"], sky=arrays["sky"])


def track_edges(frames, photometry, **options):
    """Track the shadow edge of every frame and interpolate unreliable frames.

    Parameters
    ----------
    frames : xarray.Dataset
        Frame store of the time-lapse (``image (time, row, col, channel)``, coord ``time_s``).
    photometry : xarray.Dataset
        Result of the first pass (``photometry.nc``).
    **options
        :data:`TRACK_OPTIONS` and :data:`KEYFRAME_OPTIONS`; ``clipping`` (default True): the frame
        store's white level (:func:`shadowcam.outdoor.clipping.store_white_level`) marks clipped
        samples (:class:`shadowcam.outdoor.tracking.EdgeTracker` ``white_level``).

    Returns
    -------
    xarray.Dataset
        :func:`shadowcam.outdoor.datasets.edges_dataset` with attrs ``median_interval_s``, ``gaps``.
    """
    _check_options(options, TRACK_OPTIONS | KEYFRAME_OPTIONS, "options")
    arrays = photometry_arrays(photometry)
    time_s = frames["time_s"].values
    width_rows = _edge_width(photometry, arrays)
    log.info("edge tracking: measured edge width %.1f rows", width_rows)
    track_options = {k: v for k, v in options.items() if k in TRACK_OPTIONS}
    tracked = track_frames(iter_store_frames(frames, what="edge tracking"), arrays, time_s, edge_width_rows=width_rows,
                           white_level=_white_level(frames, track_options), **track_options)
    return _edges(tracked, arrays, time_s, options)


def edges_from_strips(strips, photometry, time_s, *, width, **options):
    """The :func:`track_edges` dataset from the column strips of the same frames.

    Parameters
    ----------
    strips : sequence of dict
        :func:`track_column_strip` results covering every column once.
    photometry : xarray.Dataset
    time_s : (T,) ndarray
        Frame times of the frame store.
    width : int
        Columns of the frames.
    **options
        :data:`KEYFRAME_OPTIONS` (tracking options were used by the strips).

    Returns
    -------
    xarray.Dataset
    """
    _check_options(options, TRACK_OPTIONS | KEYFRAME_OPTIONS, "options")
    tracked = merge_strips(strips)
    if tracked["edge_row"].shape != (len(time_s), width):
        raise ValueError(f"strips: merged shape {tracked['edge_row'].shape} does not match the frames "
                         f"({len(time_s)} times x {width} columns); rerun track-edges-strip")
    return _edges(tracked, photometry_arrays(photometry), time_s, options)


def track_column_strip(frames, photometry, *, index, count, **options):
    """Run the tracking pass on strip `index` of `count` equal column strips.

    Reads only the strip's window (its columns plus a halo for the registration
    shift, the frame-differencing widening and the measured edge width) of every frame.

    Parameters
    ----------
    frames : xarray.Dataset
        Frame store of the time-lapse.
    photometry : xarray.Dataset
    index, count : int
        Strip `index` (from 0) of `count`.
    **options
        :data:`TRACK_OPTIONS` (:data:`KEYFRAME_OPTIONS` are accepted and ignored).

    Returns
    -------
    dict
        :func:`shadowcam.outdoor.strips.track_strip` result.
    """
    _check_options(options, TRACK_OPTIONS | KEYFRAME_OPTIONS, "options")
    if not 0 <= index < count:
        raise ValueError(f"index: must be in [0, count={count}); got {index}")
    options = {k: v for k, v in options.items() if k in TRACK_OPTIONS}
    arrays = photometry_arrays(photometry)
    width = frames.sizes["col"]
    cols = strip_bounds(width, count)[index]
    width_rows = _edge_width(photometry, arrays)
    halo = strip_halo(arrays["shift"], margin=options.get("margin", 2), edge_width_rows=width_rows)
    a, b = strip_window(cols, halo, width)
    log.info("strip %d/%d: columns %d:%d, reading %d:%d (halo %d, edge width %.1f rows)", index, count, *cols, a,
             b, halo, width_rows)
    white_level = _white_level(frames, options)
    stream = iter_store_frames(frames.isel(col=slice(a, b)), what=f"edge tracking, strip {index}/{count}")
    return track_strip(stream, arrays, frames["time_s"].values, cols=cols, halo=halo, edge_width_rows=width_rows,
                       white_level=white_level, **options)
