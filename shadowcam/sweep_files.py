"""Shadow times straight from a sweep's image files, decoding and tracking on every core.

RAW decoding costs far more per pixel than the streaming dip tracker, so the
sweep is cut into ``workers`` time chunks: each worker process decodes the
frames of its chunk (plus the tracker's padding) and feeds them to a
:class:`~shadowcam.dip_tracker.DipTracker` that owns the chunk; the parent
merges the partials (bit for bit the single-pass result) and times the dips.
Decode and tracking of different chunks overlap, and no frame store is
written.

Offers
------
track_files : DipSummary of a sweep from its files (parallel time chunks).
sweep_shadow_times_from_files : shadow times of a sweep from its files.
chunk_bounds : split ``n`` frames into contiguous owned chunks.
"""

import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from shadowcam.decode import read_frame
from shadowcam.dip_tracker import DipTracker, merge_partials
from shadowcam.shadow_time import summary_shadow_times

#: worker start method: rawpy (OpenMP) may deadlock in forked processes
_CONTEXT = multiprocessing.get_context("forkserver")


def chunk_bounds(n_frames, n_chunks):
    """Owned ``(start, stop)`` of `n_chunks` near-equal contiguous chunks of `n_frames`.

    Parameters
    ----------
    n_frames : int
    n_chunks : int

    Returns
    -------
    list of (int, int)
        Empty chunks are dropped (fewer frames than chunks).
    """
    if int(n_frames) < 1 or int(n_chunks) < 1:
        raise ValueError(f"n_frames and n_chunks must be >= 1, got {n_frames!r}, {n_chunks!r}")
    edges = np.linspace(0, int(n_frames), int(n_chunks) + 1).round().astype(int)
    return [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:]) if b > a]


def _track_chunk(paths, owned, half_window, block_frames, saturation_level, threads):
    """Worker: decode the padded frames of one owned chunk and return its DipPartial."""
    if threads is not None:
        import numba

        numba.set_num_threads(threads)
    start, stop = owned
    pad = DipTracker.padding(half_window)
    first, last = max(0, start - pad), min(len(paths), stop + pad)
    tracker = None
    block = []
    for index in range(first, last):
        image = read_frame(paths[index])
        if tracker is None:
            tracker = DipTracker(image.shape[:2], half_window=half_window, owned=owned,
                                 saturation_level=saturation_level)
            buffer = np.empty((block_frames,) + image.shape, np.float32)
        buffer[len(block)] = image
        block.append(index)
        if len(block) == block_frames or index == last - 1:
            tracker.update(buffer[:len(block)], first_index=block[0])
            block = []
    return tracker.partial()


def track_files(paths, *, half_window=4, workers=2, block_frames=8, saturation_level=0.999):
    """Track a sweep's dips from its image files, one time chunk per worker process.

    Parameters
    ----------
    paths : sequence of str or Path
        Frame files in time order (anything :func:`shadowcam.decode.read_frame` reads).
    half_window : int, optional
        See :class:`~shadowcam.dip_tracker.DipTracker`.
    workers : int, optional
        Processes (and time chunks); 1 runs in this process.
    block_frames : int, optional
        Frames decoded before each tracker update (memory: ``block_frames`` frames).
    saturation_level : float, optional

    Returns
    -------
    DipSummary
        With channel sums and saturation; equal to a single pass over the frames.
    """
    paths = [os.fspath(p) for p in paths]
    if not paths:
        raise ValueError("paths is empty: give the frame files of the sweep")
    if int(workers) < 1 or int(block_frames) < 1:
        raise ValueError(f"workers and block_frames must be >= 1, got {workers!r}, {block_frames!r}")
    chunks = chunk_bounds(len(paths), int(workers))
    args = (half_window, int(block_frames), saturation_level)
    if len(chunks) == 1:
        partials = [_track_chunk(paths, chunks[0], *args, None)]
    else:
        with ProcessPoolExecutor(len(chunks), mp_context=_CONTEXT) as pool:
            futures = [pool.submit(_track_chunk, paths, owned, *args, 1) for owned in chunks]
            partials = [f.result() for f in futures]
    return merge_partials(partials, n_frames=len(paths))


def sweep_shadow_times_from_files(paths, *, method="edge_fit", half_window=4, workers=2,
                                  block_frames=8, method_params=None, classify_params=None):
    """Shadow times of one sweep from its image files (RAW, TIFF, PNG, EXR ...).

    Parameters
    ----------
    paths : sequence of str or Path
        Frame files in time order.
    method, half_window, method_params, classify_params
        As :func:`shadowcam.shadow_time.sweep_shadow_times`.
    workers, block_frames
        As :func:`track_files`.

    Returns
    -------
    dict
        As :func:`shadowcam.shadow_time.sweep_shadow_times`; the CFA pattern of
        RAW frames is read from the first file.
    """
    summary = track_files(paths, half_window=half_window, workers=workers,
                          block_frames=block_frames)
    _, info = read_frame(paths[0], return_info=True)
    return summary_shadow_times(summary, method=method, cfa_pattern=info["cfa_pattern"],
                                method_params=method_params, classify_params=classify_params)
