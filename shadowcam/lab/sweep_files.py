"""Shadow times straight from a sweep's image files, decoding and tracking on every core.

The sweep is cut into ``workers`` time chunks: this process and ``workers - 1``
worker processes each decode the frames of a chunk (plus the tracker's
padding) and feed them to a :class:`~shadowcam.lab.dip_tracker.DipTracker` that
owns the chunk; this process then merges the partials (bit for bit the
single-pass result) and times the dips as the workflow times a frame store
(:func:`shadowcam.lab.shadow_time.measured_shadow_times`: dip interval, connected
dips, each RAW pixel's own mosaic site), reading the files again, in time chunks,
only for what the tracked windows do not hold (optionally the tracking pass keeps
the own site's window and lit sums: ``own_site_in_first_pass``).
Decode and tracking of different chunks overlap, and no frame store is
written.

Offers
------
track_files : DipSummary of a sweep from its files (parallel time chunks).
sweep_shadow_times_from_files : shadow times of a sweep from its files.
chunk_bounds : split ``n`` frames into contiguous owned chunks.
signal_blocks : a sweep's tracked signal read again from its files, in blocks.
mosaic_colour : a mosaic-tracked summary's channel sums from its chunks' per-site sums.
site_sums_from_files : the own-site sums of a chunk of RAW files, read again.
"""

import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor
from functools import partial

import numpy as np

from shadowcam.io.cfa import site_constants
from shadowcam.io.decode import read_frame
from shadowcam.io.raw_mosaic import is_raw, read_mosaic
from shadowcam.io.mosaic_reader import MosaicReader
from shadowcam.lab.dip_kernels import SUM_SCALE, quantise_sum
from shadowcam.lab.dip_tracker import DipTracker, IntervalTracker, merge_partials
from shadowcam.lab.mosaic_signal import bilinear_channels, mosaic_signal
from shadowcam.lab.shadow_time import measured_shadow_times
from shadowcam.lab.site_signal import mosaic_own_site, site_window_of_sums, site_window_sums, tracked_site_window

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


class _MosaicFrames:
    """A chunk's RAW frames as channel-sum planes straight from their mosaic.

    Feeds the tracker :func:`shadowcam.lab.mosaic_signal.mosaic_signal` planes
    and keeps, over the owned frames, what the sweep's colour needs, in sums
    that are exact whatever the chunking: the integer sum of each mosaic
    site over the frames with the sweep's first levels (black and white of
    its first frame) and their count, the fixed-point sum of the normalised
    values of frames with other levels, and whether any site the pixel
    interpolates from clipped (the plane is a sum of three channels, so the
    tracker does not judge clipping).
    """

    def __init__(self, paths, first, owned, saturation_level):
        self.reader = MosaicReader(paths[first])
        self.shape = self.frame_shape = self.reader.shape
        self.levels = self.reader.levels if first == 0 else read_mosaic(paths[0])[1]
        self.owned = owned
        self.saturation_level = saturation_level
        self.tracker_saturation_level = np.inf
        self.site_sum = np.zeros(self.shape, np.int64)
        self.n_site_sum = 0
        self.other_sum = np.zeros(self.shape, np.int64)
        self.saturated = np.zeros(self.shape, bool)

    def read_into(self, path, index, out, own=None):
        """The tracked signal of frame `index` into `out` ``(M, N)`` (and each site's own value into `own`)."""
        mosaic, levels = self.reader.read(path)
        owned = self.owned[0] <= index < self.owned[1]
        usual = all(np.array_equal(levels[k], self.levels[k]) for k in ("black_sites", "white_sites"))
        mosaic_signal(mosaic, pattern=levels["cfa_pattern"], black=levels["black_sites"],
                      white=levels["white_sites"], out=out, saturated=self.saturated,
                      saturation_level=self.saturation_level if owned else np.inf,
                      site_sum=self.site_sum if owned and usual else None)
        if own is not None:
            mosaic_own_site(mosaic, pattern=levels["cfa_pattern"], black=levels["black_sites"],
                            white=levels["white_sites"], out=own)
        if owned and usual:
            self.n_site_sum += 1
        elif owned:
            self.other_sum += quantise_sum(_normalised(mosaic, levels))

    def read_site(self, path, own, signal):
        """Each site's own value and the tracked signal of one frame, into `own` and `signal` ``(M, N)``."""
        mosaic, levels = self.reader.read(path)
        pattern, black, white = levels["cfa_pattern"], levels["black_sites"], levels["white_sites"]
        mosaic_own_site(mosaic, pattern=pattern, black=black, white=white, out=own)
        mosaic_signal(mosaic, pattern=pattern, black=black, white=white, out=signal, saturated=self.saturated,
                      saturation_level=np.inf)

    def sums(self):
        return self.site_sum, self.n_site_sum, self.other_sum, self.saturated, self.levels


def _normalised(site_values, levels, count=1):
    """``(values - count * black) / (white - black)`` per mosaic site, float64."""
    black = site_constants(levels["black_sites"], site_values.shape)
    return (site_values - count * black) / (site_constants(levels["white_sites"], site_values.shape) - black)


class _DecodedFrames:
    """A chunk's frames decoded to RGB by :func:`shadowcam.io.decode.read_frame` (non-RAW files)."""

    def __init__(self, paths, first, owned, saturation_level):
        self._first = (paths[first], read_frame(paths[first]))
        self.frame_shape = self._first[1].shape
        self.shape = self.frame_shape[:2]
        self.tracker_saturation_level = saturation_level

    def read_into(self, path, index, out, own=None):
        out[...] = self._first[1] if path == self._first[0] else read_frame(path)

    def sums(self):
        return None


def _in_threads(threads, function, *args):
    """``function(*args)`` with `threads` numba threads meanwhile (None: unchanged)."""
    if threads is None:
        return function(*args)
    import numba

    previous = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        return function(*args)
    finally:
        numba.set_num_threads(previous)


def _in_chunks(function, paths, workers, *args):
    """``function(paths, owned, *args)`` for each time chunk, one per process.

    This process takes the first chunk itself (one process fewer to start,
    one result fewer to send back); each uses one numba thread.
    """
    chunks = chunk_bounds(len(paths), int(workers))
    if len(chunks) == 1:
        return [function(paths, chunks[0], *args)]
    with ProcessPoolExecutor(len(chunks) - 1, mp_context=_CONTEXT) as pool:
        futures = [pool.submit(_in_threads, 1, function, paths, owned, *args) for owned in chunks[1:]]
        return [_in_threads(1, function, paths, chunks[0], *args)] + [f.result() for f in futures]


def _track_owned(paths, owned, half_window, block_frames, saturation_level, own_site=False):
    """Decode the padded frames of one owned chunk; return its DipPartial (and RAW sums).

    RAW files are tracked from their mosaic (one signal plane per frame, see
    :mod:`shadowcam.lab.mosaic_signal`); the partial then comes with the chunk's
    per-site sums and clipped-pixel mask, else with None. With `own_site` (RAW only)
    the tracker also keeps each site's own value (``DipTracker(own_site=True)``).
    """
    start, stop = owned
    pad = DipTracker.padding(half_window)
    first, last = max(0, start - pad), min(len(paths), stop + pad)
    raw = is_raw(paths[first])
    frames = (_MosaicFrames if raw else _DecodedFrames)(paths, first, owned, saturation_level)
    own_site = bool(own_site) and raw
    tracker = DipTracker(frames.shape, half_window=half_window, owned=owned,
                         saturation_level=frames.tracker_saturation_level, own_site=own_site)
    buffer = np.empty((block_frames,) + frames.frame_shape, np.float32)
    own = np.empty((block_frames,) + frames.shape, np.float32) if own_site else None
    block = []
    for index in range(first, last):
        frames.read_into(paths[index], index, buffer[len(block)], None if own is None else own[len(block)])
        block.append(index)
        if len(block) == block_frames or index == last - 1:
            tracker.update(buffer[:len(block)], first_index=block[0], own=None if own is None else own[:len(block)])
            block = []
    return tracker.partial(), frames.sums()


def signal_blocks(paths, block_frames, first=0, last=None):
    """Frames ``first .. last - 1`` of the sweep's tracked signal read again, in blocks of `block_frames`.

    A generator: nothing is read unless it is iterated.
    """
    last = len(paths) if last is None else last
    frames = (_MosaicFrames if is_raw(paths[first]) else _DecodedFrames)(paths, first, (0, 0), np.inf)
    buffer = np.empty((block_frames,) + frames.frame_shape, np.float32)
    for start in range(first, last, block_frames):
        stop = min(start + block_frames, last)
        for index in range(start, stop):
            frames.read_into(paths[index], index, buffer[index - start])
        yield buffer[:stop - start]


def _interval_owned(paths, owned, centre_frame, threshold, half_window, block_frames):
    """The IntervalPartial of one owned chunk, its padded frames read again."""
    tracker = IntervalTracker(centre_frame, threshold, half_window=half_window, n_frames=len(paths), owned=owned)
    first = max(0, owned[0] - IntervalTracker.PAD)
    for block in signal_blocks(paths, block_frames, first, min(len(paths), owned[1] + IntervalTracker.PAD)):
        tracker.update(block)
    return tracker.partial()


def site_sums_from_files(paths, owned, window_start, k, block_frames):
    """The :class:`~shadowcam.lab.site_signal.SiteSums` of one owned chunk of RAW files, read again.

    Each frame's own-site values come straight from its mosaic (no demosaic) and its
    signal as the tracker's (:func:`shadowcam.lab.mosaic_signal.mosaic_signal`).
    """
    start, stop = owned
    frames = _MosaicFrames(paths, start, (0, 0), np.inf)
    own = np.empty((block_frames,) + frames.shape, np.float32)
    signal = np.empty_like(own)

    def samples():
        for first in range(start, stop, block_frames):
            n = min(block_frames, stop - first)
            for i in range(n):
                frames.read_site(paths[first + i], own[i], signal[i])
            yield own[:n], signal[:n]

    return site_window_sums(samples(), window_start, k, first=start)


def mosaic_colour(summary, chunk_sums):
    """Give a mosaic-tracked summary its per-channel sums and clipped pixels (in place).

    `chunk_sums`: :meth:`_MosaicFrames.sums` of every chunk (per-site integer DN sums
    over the frames with the first levels, their count, fixed-point sums of the
    normalised other frames, clipped pixels, the first levels); integer sums
    are added before anything is rounded, so the result does not depend on
    the chunking.
    """
    site_sum, count, other_sum = (sum(part[i] for part in chunk_sums) for i in range(3))
    levels = chunk_sums[0][4]
    normalised = _normalised(site_sum, levels, count) + other_sum / SUM_SCALE
    summary.channel_sum = bilinear_channels(normalised, pattern=levels["cfa_pattern"])
    summary.saturated = np.logical_or.reduce([summary.saturated] + [part[3] for part in chunk_sums])
    return summary


def track_files(paths, *, half_window=4, workers=2, block_frames=16, saturation_level=0.999, own_site=False):
    """Track a sweep's dips from its image files, one time chunk per worker process.

    Parameters
    ----------
    paths : sequence of str or Path
        Frame files in time order (anything :func:`shadowcam.io.decode.read_frame`
        reads). RAW files are tracked from their Bayer mosaic without
        demosaicking each frame (:mod:`shadowcam.lab.mosaic_signal`): the same
        channel-sum signal as the demosaiced frames, up to float32 rounding.
    half_window : int, optional
        See :class:`~shadowcam.lab.dip_tracker.DipTracker`.
    workers : int, optional
        Processes (and time chunks); 1 runs in this process.
    block_frames : int, optional
        Frames decoded before each tracker update (memory: ``block_frames`` frames,
        4 bytes per pixel each for RAW, 12 for RGB, next to the tracker's ~220
        bytes per pixel). The tracker reads and writes its state once per
        update, so larger blocks cost less per frame (``docs/benchmarks.md``).
    saturation_level : float, optional
    own_site : bool, optional
        RAW: keep each site's own value beside the signal (the summary's
        ``tracked_site``, :class:`~shadowcam.lab.dip_tracker.DipTracker` ``own_site``:
        ``2 K * 4 + 64`` bytes per pixel more in the tracker, 4 per pixel and block frame
        for the block's own values); ignored for other files.

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
    results = _in_chunks(_track_owned, paths, workers, half_window, int(block_frames), saturation_level,
                         own_site)
    summary = merge_partials([partial for partial, _ in results], n_frames=len(paths))
    if results[0][1] is None:
        return summary
    return mosaic_colour(summary, [sums for _, sums in results])


def sweep_shadow_times_from_files(paths, *, method="edge_fit", half_window=4, workers=2,
                                  block_frames=16, method_params=None, classify_params=None,
                                  own_site_in_first_pass=False):
    """Shadow times of one sweep from its image files (RAW, TIFF, PNG, EXR ...).

    The same timing as the workflow's frame stores
    (:func:`shadowcam.lab.shadow_time.measured_shadow_times`, the one path of both):
    dip interval, connected dips, and for RAW with ``edge_fit`` each pixel's own
    mosaic site.

    Parameters
    ----------
    paths : sequence of str or Path
        Frame files in time order.
    method, half_window, method_params, classify_params
        As :func:`shadowcam.lab.shadow_time.sweep_shadow_times`.
    workers, block_frames
        As :func:`track_files`.
    own_site_in_first_pass : bool, optional
        RAW with ``edge_fit``: the tracking pass keeps each site's own value and its
        exact lit sums (:func:`track_files` ``own_site``) and the files are not decoded
        again for the own site. Off by default: its noise comes from exact sums, not
        from float64 sums block by block, which moves a few float32 outputs by one unit
        in the last place (``docs/benchmarks.md``).

    Returns
    -------
    dict
        As :func:`shadowcam.lab.shadow_time.sweep_shadow_times`; the CFA pattern of
        RAW frames is read from the first file.

    Notes
    -----
    The files are read a second time only for what the tracked windows do not hold,
    in time chunks as the tracking (one per worker): the dip interval of pixels whose
    crossings lie beyond their window (:func:`shadowcam.lab.dip_tracker.track_intervals`);
    for RAW with ``edge_fit`` every frame once more, each site's own value straight from
    its mosaic (:func:`shadowcam.lab.site_signal.mosaic_own_site`, no demosaic; the
    site's lit statistics take every frame outside its window), unless
    `own_site_in_first_pass`; and, in this process,
    the support of ``several_minima`` / ``wide_dip`` pixels
    (:func:`shadowcam.lab.connected_dips.support_intervals`) when there are any.
    """
    paths = [os.fspath(p) for p in paths]
    first_pass = bool(own_site_in_first_pass) and method == "edge_fit"
    summary = track_files(paths, half_window=half_window, workers=workers,
                          block_frames=block_frames, own_site=first_pass)
    block_frames = int(block_frames)

    def measure(centre, threshold):
        return _in_chunks(_interval_owned, paths, workers, centre, threshold, summary.half_window, block_frames)

    def site_window(tracked, site_colour):
        parts = _in_chunks(site_sums_from_files, paths, workers, tracked.window_start, tracked.window.shape[0],
                           block_frames)
        return site_window_of_sums(parts, tracked, site_colour=site_colour)

    cfa_pattern = read_mosaic(paths[0])[1]["cfa_pattern"] if is_raw(paths[0]) else None
    return measured_shadow_times(summary, read=partial(signal_blocks, paths, block_frames), method=method,
                                 cfa_pattern=cfa_pattern, measure=measure,
                                 site_window=tracked_site_window if first_pass else site_window,
                                 method_params=method_params, classify_params=classify_params)
