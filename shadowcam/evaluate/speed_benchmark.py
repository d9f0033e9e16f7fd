"""Speed benchmark of the shadow-time pipeline against its hardware floors (``make bench``).

A wire's shadow sweeps a textured plane; frames are rendered analytically
(exact shadow time at every pixel centre), mosaicked, given sensor noise and
written as 14-bit DNG files (lossless-JPEG compressed as cameras write them,
or uncompressed). The benchmark then measures, on this machine:

* end to end, DNG files -> shadow-time maps (:func:`shadowcam.lab.sweep_files.sweep_shadow_times_from_files`,
  both cores), against the decode floor: rawpy decoding the same files with
  the pipeline's settings (the mosaic, ``raw_image_visible``) in as many
  processes and doing nothing else; the pipeline's own mosaic reader and
  the demosaicing ``read_frame`` are timed alike for context;
* the shadow-time stage alone on in-memory frames (the channel-sum planes
  the file pipeline tracks, and the RGB frames of the workflow's store), in
  pixel-frames per second, against one numpy pass over the same bytes
  (memory-bandwidth floor);
* the peak memory of the end-to-end run for a short and a long sequence;
* the accuracy of the default configuration against the exact truth.

Timings on a shared machine are noisy; every figure is the best of `repeats`.

Offers
------
WireScene : analytic wire-shadow sweep (frames and exact shadow times).
write_sweep_dngs : render a scene to DNG files (cached by parameters).
decode_floor_seconds : wall time to decode files with nothing else, in parallel.
numpy_pass_seconds : wall time of one numpy pass over an array.
stage_seconds : wall time of the shadow-time stage on in-memory frames.
tracking_cpu_ns : CPU time per pixel-frame of the tracker on one core (robust to load).
stage_ns : CPU ns per pixel-frame of each stage of the DNG path on one thread.
end_to_end : run the file pipeline in a fresh process; wall time and peak memory.
run_benchmark : all of the above, as a dict of figures.
format_report : the figures as printable text.
"""

import json
import os
import subprocess
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path

import numba as nb
import numpy as np

from shadowcam.lab.accuracy import shadow_time_errors
from shadowcam.io.raw_writer import write_dng
from shadowcam.synthetic.sensor import SensorModel, simulate_raw
from shadowcam.lab.sweep_files import _CONTEXT


@dataclass(frozen=True)
class WireScene:
    """A thin wire's shadow sweeping a textured plane, seen by a linear camera.

    The shadow's centre line crosses image point (row y, col x) at time
    ``t0 + (x + tilt * y) / px_per_frame`` (pixel centres at integer + 0.5);
    the shadow is `width` frames wide and hard edged. Each pixel integrates
    the shadow exactly along columns and over `subrows` sub-rows.
    """

    height: int = 1200
    width_px: int = 1600
    n_frames: int = 1000
    px_per_frame: float = 2.1
    width: float = 2.0
    tilt: float = 0.3
    t0: float = 6.0
    seed: int = 0
    subrows: int = 4
    electrons: float = 2000.0

    def albedo(self):
        """Smooth random colour texture, ``(H, W, 3)`` float32 in 0.3..0.9."""
        rng = np.random.default_rng(self.seed)
        coarse = rng.random((self.height // 16 + 2, self.width_px // 16 + 2, 3))
        rows = np.arange(self.height) / 16
        cols = np.arange(self.width_px) / 16
        fine = coarse[rows.astype(int)][:, cols.astype(int)]
        return (0.3 + 0.6 * fine).astype(np.float32)

    def frame(self, k, albedo):
        """Radiance of frame `k`, ``(H, W, 3)`` float32.

        Only the few columns per row that the band can touch are computed.
        """
        centre = self.px_per_frame * (k - self.t0)  # band centre in x + tilt * y
        half = 0.5 * self.width * self.px_per_frame
        reach = int(np.ceil(half)) + 2
        rows = np.arange(self.height)
        first = np.floor(centre - self.tilt * (rows + 0.5)).astype(int)[:, None] - reach
        cols = first + np.arange(2 * reach + 1)[None, :]  # (H, m) candidate columns
        lit = np.zeros(cols.shape)
        for s in range(self.subrows):
            y = rows[:, None] + (s + 0.5) / self.subrows
            left = cols + self.tilt * y  # pixel spans [left, left + 1] in x + tilt * y
            covered = np.clip(np.minimum(left + 1, centre + half) - np.maximum(left, centre - half), 0, 1)
            lit += 1.0 - covered
        fraction = np.ones((self.height, self.width_px), np.float32)
        inside = (cols >= 0) & (cols < self.width_px)
        fraction[np.broadcast_to(rows[:, None], cols.shape)[inside], cols[inside]] = lit[inside] / self.subrows
        return albedo * fraction[..., None]

    def truth(self):
        """Exact shadow time at pixel centres, ``(H, W)`` float64 (NaN outside the sweep)."""
        rows = np.arange(self.height)[:, None] + 0.5
        cols = np.arange(self.width_px)[None, :] + 0.5
        t = self.t0 + (cols + self.tilt * rows) / self.px_per_frame
        return np.where((t >= 0) & (t <= self.n_frames - 1), t, np.nan)


_SENSOR = SensorModel(bit_depth=14, black_level=512, gain=1.0, read_noise=4.0)


def _write_frames(scene, directory, indices, compression):
    """Worker: render, add noise and write frames `indices` of `scene`."""
    albedo = scene.albedo()
    for k in indices:
        raw = simulate_raw(scene.frame(k, albedo), sensor=_SENSOR, scale=scene.electrons,
                           seed=[scene.seed, int(k)])
        write_dng(Path(directory) / f"frame_{k:05d}.dng", raw, bit_depth=14,
                  black_level=_SENSOR.black_level, compression=compression)


def write_sweep_dngs(scene, directory, *, workers=2, compression="none"):
    """Render `scene` to ``directory/frame_NNNNN.dng`` unless already there; return the paths.

    Parameters
    ----------
    scene : WireScene
    directory : str or Path
        Reused when its ``scene.json`` matches `scene`.
    workers : int, optional
        Rendering processes.
    compression : {"none", "ljpeg"}, optional
        DNG compression (see :func:`shadowcam.io.raw_writer.write_dng`).

    Returns
    -------
    list of Path
    """
    directory = Path(directory)
    stamp = directory / "scene.json"
    paths = [directory / f"frame_{k:05d}.dng" for k in range(scene.n_frames)]
    written = dict(asdict(scene), compression=compression)
    if stamp.is_file() and json.loads(stamp.read_text()) == written and all(p.is_file() for p in paths):
        return paths
    directory.mkdir(parents=True, exist_ok=True)
    stamp.unlink(missing_ok=True)
    parts = np.array_split(np.arange(scene.n_frames), workers)
    with ProcessPoolExecutor(workers, mp_context=_CONTEXT) as pool:
        list(pool.map(_write_frames, [scene] * workers, [directory] * workers, parts, [compression] * workers))
    stamp.write_text(json.dumps(written))
    return paths


def _decode_files(paths, reader):
    if reader == "rawpy":
        import rawpy

        for path in paths:
            with rawpy.imread(str(path)) as raw:
                raw.raw_image_visible.copy()
    elif reader == "direct":
        from shadowcam.io.mosaic_reader import MosaicReader

        mosaics = MosaicReader(paths[0])
        for path in paths:
            mosaics.read(path)
    else:
        from shadowcam.io.decode import read_frame

        for path in paths:
            read_frame(path)


def decode_floor_seconds(paths, *, workers=2, reader="rawpy"):
    """Wall time to decode `paths` in `workers` processes and do nothing else.

    Parameters
    ----------
    paths : sequence of Path
    workers : int, optional
    reader : {"rawpy", "direct", "read_frame"}, optional
        ``rawpy``: open and unpack the mosaic (``raw_image_visible``), the
        settings of the pipeline's RAW decode; ``direct``: the pipeline's
        :class:`~shadowcam.io.mosaic_reader.MosaicReader`; ``read_frame``:
        :func:`shadowcam.io.decode.read_frame` (rawpy, bilinear demosaic, linear
        float32: what the workflow's decode step stores).
    """
    parts = [list(p) for p in np.array_split(np.array(paths, dtype=object), workers)]
    with ProcessPoolExecutor(workers, mp_context=_CONTEXT) as pool:
        list(pool.map(_decode_files, [[p[0]] for p in parts], [reader] * workers))  # start the workers
        start = time.perf_counter()
        list(pool.map(_decode_files, parts, [reader] * workers))
        return time.perf_counter() - start


def numpy_pass_seconds(array, *, repeats=3):
    """Best wall time of one numpy pass (a float32 sum over time) over `array`."""
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        np.add.reduce(array, axis=0)
        best = min(best, time.perf_counter() - start)
    return best


def stage_seconds(frames, *, block_frames=16, method="edge_fit", repeats=2):
    """Best wall times of the shadow-time stage on in-memory frames.

    Parameters
    ----------
    frames : (T, H, W, C) float32 ndarray

    Returns
    -------
    tracking : float
        Streaming the frames through the tracker (the per-frame work).
    finishing : float
        Classifying and timing the dips (once per sweep).
    """
    from shadowcam.lab.shadow_time import summary_shadow_times, track_sweep

    shape = frames.shape[1:3]
    track_best = finish_best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        summary, _, _ = track_sweep((frames[i:i + block_frames] for i in range(0, len(frames), block_frames)),
                                    shape)
        middle = time.perf_counter()
        summary_shadow_times(summary, method=method)
        end = time.perf_counter()
        track_best = min(track_best, middle - start)
        finish_best = min(finish_best, end - middle)
    return track_best, finish_best


def tracking_cpu_ns(frames, *, block_frames=16, repeats=2):
    """CPU time per pixel-frame of the tracker on one thread, in ns (best of `repeats`).

    CPU time of this process, not wall time: other jobs on a shared machine
    change it much less (they still share caches and memory bandwidth).

    Parameters
    ----------
    frames : (T, H, W, C) float32 ndarray
    """
    import numba

    from shadowcam.lab.dip_tracker import DipTracker

    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        best = np.inf
        for _ in range(repeats):
            start = time.process_time()
            tracker = DipTracker(frames.shape[1:3])
            for i in range(0, len(frames), block_frames):
                tracker.update(frames[i:i + block_frames])
            tracker.partial()
            best = min(best, time.process_time() - start)
    finally:
        numba.set_num_threads(threads)
    return best / (frames.shape[0] * frames.shape[1] * frames.shape[2]) * 1e9


@nb.njit(cache=True, nogil=True)
def _minimal_tracker(block, ring, worst):
    """The least a streaming dip tracker does per pixel-frame: store, smooth, compare.

    `block` ``(T, P)`` float32; `ring` ``(3, P)`` the last three samples;
    `worst` ``(P,)`` the value a new minimum must beat. Returns the number of
    smoothed values below it (so the work is not optimised away).
    """
    hits = 0
    for t in range(block.shape[0]):
        a, b, c = ring[t % 3], ring[(t + 1) % 3], ring[(t + 2) % 3]
        for p in range(block.shape[1]):
            c[p] = block[t, p]
            s = np.float32(0.5) * b[p] + np.float32(0.25) * (a[p] + c[p])
            hits += s < worst[p]
    return hits


def stage_ns(paths, *, block_frames=16, repeats=2, own_site_in_first_pass=False):
    """CPU time of each stage of the DNG -> shadow-time path on one thread, ns per pixel-frame.

    Runs the path's own pieces in this process, one after the other, on
    `paths` (frames of one sweep), as :func:`~shadowcam.lab.sweep_files.sweep_shadow_times_from_files`
    runs them for RAW with ``edge_fit``: the direct mosaic read, the mosaic ->
    channel-sum signal, the tracker's update, its finish (partial, merge), the
    dip interval from the stored windows (and the count of pixels that would
    need a second read), the own site's second read of every file
    (:func:`~shadowcam.lab.sweep_files.site_sums_from_files`), and the
    classification and timing with the CFA pattern (each pixel from its own site,
    the connected dips' support read again from the files where the pipeline
    does); plus the least arithmetic a streaming tracker needs
    (:func:`_minimal_tracker`) and one numpy pass over the signal. With
    `own_site_in_first_pass` (the pipeline's option of that name) each site's own
    value is computed in the first pass and tracked instead of read again.

    Returns
    -------
    dict
        ``decode``, ``signal``, ``own``, ``track``, ``site_read``, ``minimal_track``,
        ``numpy_pass``: ns per pixel-frame (best of `repeats`; ``own`` 0 without
        `own_site_in_first_pass`, ``site_read`` 0 with it); ``finish_s``, ``interval_s``,
        ``timing_s``: seconds once per sweep; ``interval_unresolved``: pixels
        the interval pass must read the frames again for.
    """
    import numba

    from shadowcam.lab.dip_tracker import DipTracker, track_intervals, window_intervals, half_depth, \
        without_interval
    from shadowcam.io.mosaic_reader import MosaicReader
    from shadowcam.lab.mosaic_signal import mosaic_signal
    from shadowcam.lab.shadow_time import summary_shadow_times
    from shadowcam.lab.site_signal import mosaic_own_site, site_window_of_sums, tracked_site_window
    from shadowcam.lab.sweep_files import mosaic_colour, signal_blocks, site_sums_from_files

    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        reader = MosaicReader(paths[0])
        reader.read(paths[0])
        shape = reader.shape
        n = len(paths)
        pixel_frames = n * shape[0] * shape[1]
        pattern = reader.levels["cfa_pattern"]
        first_pass = bool(own_site_in_first_pass)
        best = dict.fromkeys(("decode", "signal", "own", "track", "site_read", "minimal_track", "numpy_pass",
                              "finish_s", "interval_s", "timing_s"), np.inf)
        for _ in range(repeats):
            clock = dict.fromkeys(best, 0.0)
            tracker = DipTracker(shape, own_site=first_pass, saturation_level=np.inf)  # as sweep_files tracks RAW
            block = np.empty((block_frames,) + shape, np.float32)
            own = np.empty_like(block)
            saturated = np.zeros(shape, bool)
            site_sum = np.zeros(shape, np.int64)
            for start in range(0, n, block_frames):
                stop = min(start + block_frames, n)
                for i in range(start, stop):
                    t0 = time.process_time()
                    mosaic, levels = reader.read(paths[i])
                    t1 = time.process_time()
                    mosaic_signal(mosaic, pattern=levels["cfa_pattern"], black=levels["black_sites"],
                                  white=levels["white_sites"], out=block[i - start], saturated=saturated,
                                  site_sum=site_sum)
                    t2 = time.process_time()
                    if first_pass:
                        mosaic_own_site(mosaic, pattern=levels["cfa_pattern"], black=levels["black_sites"],
                                        white=levels["white_sites"], out=own[i - start])
                    clock["decode"] += t1 - t0
                    clock["signal"] += t2 - t1
                    if first_pass:
                        clock["own"] += time.process_time() - t2
                t0 = time.process_time()
                tracker.update(block[:stop - start], first_index=start, own=own[:stop - start] if first_pass else None)
                t1 = time.process_time()
                ring, worst = np.zeros((3, shape[0] * shape[1]), np.float32), np.zeros(shape[0] * shape[1], np.float32)
                _minimal_tracker(block[:stop - start].reshape(stop - start, -1), ring, worst)
                t2 = time.process_time()
                np.add.reduce(block[:stop - start], axis=0)
                clock["track"] += t1 - t0
                clock["minimal_track"] += t2 - t1
                clock["numpy_pass"] += time.process_time() - t2
            t0 = time.process_time()
            summary = mosaic_colour(tracker.result(), [(site_sum, n, np.zeros(shape, np.int64), saturated,
                                                        reader.levels)])
            t1 = time.process_time()
            _, resolved = window_intervals(summary, half_depth(summary))
            t2 = time.process_time()
            interval = None
            if resolved.all():  # else the frames would be read again (not timed here)
                summary, interval = without_interval(summary, track_intervals(iter(()), summary))
            site_window = tracked_site_window
            t_site = time.process_time()
            if not first_pass:  # the pipeline's second read of every file for the own site
                parts = [site_sums_from_files(paths, (0, n), summary.window_start, summary.window.shape[0],
                                              block_frames)]

                def site_window(tracked, colour):
                    return site_window_of_sums(parts, tracked, site_colour=colour)
            t3 = time.process_time()
            summary_shadow_times(summary, interval=interval, cfa_pattern=pattern, own_site=True,
                                 read=lambda: signal_blocks(paths, block_frames), site_window=site_window)
            t4 = time.process_time()
            clock.update(finish_s=t1 - t0, interval_s=t2 - t1, site_read=0.0 if first_pass else t3 - t_site,
                         timing_s=t4 - t3 + t_site - t2)
            for key in ("decode", "signal", "own", "track", "site_read", "minimal_track", "numpy_pass"):
                clock[key] *= 1e9 / pixel_frames
            best = {key: min(best[key], clock[key]) for key in best}
        best["interval_unresolved"] = int((~resolved).sum())
        best["frames"], best["pixels"] = n, shape[0] * shape[1]
        return best
    finally:
        numba.set_num_threads(threads)


_END_TO_END = """
import json, resource, sys, time
import numpy as np
from shadowcam.lab.sweep_files import sweep_shadow_times_from_files
paths, workers, out = json.loads(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
start = time.perf_counter()
result = sweep_shadow_times_from_files(paths, workers=workers)
seconds = time.perf_counter() - start
np.save(out, result["shadow_time"])
own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
child = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
print(json.dumps({"seconds": seconds, "peak_rss_mib": (own + (workers - 1) * child) / 1024}))
"""


def end_to_end(paths, *, workers=2, out=None):
    """Run :func:`~shadowcam.lab.sweep_files.sweep_shadow_times_from_files` in a fresh process.

    Returns
    -------
    seconds : float
        Wall time of the call (decode, tracking, merge, timing).
    peak_rss_mib : float
        Peak resident memory of the parent (which tracks one chunk itself)
        plus ``workers - 1`` times the largest worker's (an upper bound of the
        simultaneous total).
    shadow_time : (H, W) float32 ndarray
    """
    out = Path(out or f"/tmp/shadowcam-bench-{os.getpid()}.npy")
    proc = subprocess.run([sys.executable, "-c", _END_TO_END, json.dumps([str(p) for p in paths]),
                           str(workers), str(out)], capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"end-to-end run failed:\n{proc.stderr[-2000:]}")
    figures = json.loads(proc.stdout.strip().splitlines()[-1])
    shadow_time = np.load(out)
    out.unlink()
    return figures["seconds"], figures["peak_rss_mib"], shadow_time


def _stage_frames(paths, rows, cols):
    """In-memory frames of a crop, as the two pipelines track them.

    Returns
    -------
    rgb : (T, h, w, 3) float32 ndarray
        Demosaiced frames (what the workflow's frame store holds).
    signal : (T, h, w, 1) float32 ndarray
        Channel-sum planes from the mosaic (what the file pipeline tracks).
    """
    from shadowcam.io.decode import read_frame
    from shadowcam.io.mosaic_reader import MosaicReader
    from shadowcam.lab.mosaic_signal import mosaic_signal

    mosaics = MosaicReader(paths[0])
    rgb, signal = [], []
    for path in paths:
        rgb.append(read_frame(path)[rows, cols])
        mosaic, levels = mosaics.read(path)
        plane, _ = mosaic_signal(mosaic, pattern=levels["cfa_pattern"], black=levels["black_sites"],
                                 white=levels["white_sites"])
        signal.append(plane[rows, cols, None])
    return np.stack(rgb), np.stack(signal)


def run_benchmark(directory, *, scene=None, short=100, workers=2, stage_frames=240, compression="ljpeg",
                  log=print):
    """Measure every figure of ``make bench``.

    Parameters
    ----------
    directory : str or Path
        Where the DNG files are rendered (and reused).
    scene : WireScene, optional
        Default: 1000 frames of 1200 x 1600.
    short : int, optional
        Frames of the short run (peak-memory comparison).
    workers : int, optional
        Processes (cores) for decoding and tracking.
    stage_frames : int, optional
        In-memory frames (central quarter of the image) for the stage-alone
        measurement; enough that the per-pixel minimum lists settle.
    compression : {"ljpeg", "none"}, optional
        DNG compression of the rendered files: lossless JPEG as cameras
        write, or none (where rawpy's decode is cheapest).
    log : callable, optional
        Progress messages.

    Returns
    -------
    dict
        Figures (see :func:`format_report`).
    """
    scene = scene or WireScene()
    log(f"rendering {scene.n_frames} DNG frames ({compression}) of {scene.height}x{scene.width_px} "
        f"into {directory} ...")
    paths = write_sweep_dngs(scene, directory, workers=workers, compression=compression)
    pixels = scene.height * scene.width_px
    figures = {"height": scene.height, "width": scene.width_px, "n_frames": scene.n_frames,
               "short": short, "workers": workers, "compression": compression}

    log("reading the files once (page cache) ...")
    for path in paths:
        path.read_bytes()
    log("warming up (compiled kernels are cached on first use) ...")
    end_to_end(paths[:min(20, len(paths))], workers=workers)
    log("decode floors, end to end, rawpy floor again ...")
    floors = {reader: decode_floor_seconds(paths, workers=workers, reader=reader)
              for reader in ("rawpy", "direct", "read_frame")}
    e2e_long, rss_long, shadow_time = end_to_end(paths, workers=workers)
    floors["rawpy"] = min(floors["rawpy"], decode_floor_seconds(paths, workers=workers))
    log("end to end, short sequence ...")
    e2e_short, rss_short, _ = end_to_end(paths[:short], workers=workers)
    pixel_frames = pixels * scene.n_frames
    figures.update(
        end_to_end_s=e2e_long, end_to_end_mpfs=pixel_frames / e2e_long / 1e6,
        ratio_to_decode_floor=floors["rawpy"] / e2e_long, ratio_to_direct_floor=floors["direct"] / e2e_long,
        peak_rss_short_mib=rss_short, peak_rss_long_mib=rss_long,
        peak_rss_ratio=rss_long / rss_short, end_to_end_short_s=e2e_short,
    )
    for reader, seconds in floors.items():
        figures[f"{reader}_floor_s"] = seconds
        figures[f"{reader}_floor_mpfs"] = pixel_frames / seconds / 1e6
    truth = scene.truth()
    figures["accuracy"] = shadow_time_errors(shadow_time, truth, lit=np.ones(truth.shape, bool))
    log("per-stage CPU time on one thread (the whole sweep, so that every pixel has its dip) ...")
    figures["stages"] = stage_ns(paths, repeats=1)

    log(f"stage alone on {stage_frames} in-memory frames (central quarter of the image) ...")
    middle = scene.n_frames // 2 - stage_frames // 2
    rows = slice(scene.height // 4, scene.height // 4 + scene.height // 2)
    cols = slice(scene.width_px // 4, scene.width_px // 4 + scene.width_px // 2)
    stages = dict(zip(("rgb", "signal"), _stage_frames(paths[middle:middle + stage_frames], rows, cols)))
    figures["stage_frames"] = stage_frames
    for name, frames in stages.items():
        tracking, finishing = stage_seconds(frames)
        numpy_pass = numpy_pass_seconds(frames)
        crop = frames.shape[1] * frames.shape[2]
        stage_mpfs = crop * stage_frames / tracking / 1e6
        finish_s = finishing * pixels / crop
        figures[name] = {
            "tracking_mpfs": stage_mpfs, "numpy_pass_mpfs": crop * stage_frames / numpy_pass / 1e6,
            "ratio_to_numpy_pass": numpy_pass / tracking, "tracking_cpu_ns": tracking_cpu_ns(frames),
            "finish_s": finish_s,
            "with_finish_mpfs_at_n": pixel_frames / (pixel_frames / (stage_mpfs * 1e6) + finish_s) / 1e6,
        }
    return figures


def format_report(figures):
    """Printable text of :func:`run_benchmark`'s figures."""
    f = figures
    acc = f["accuracy"]
    floor_note = {
        "rawpy": "rawpy open + raw_image_visible: the pipeline's rawpy settings, nothing else",
        "direct": "shadowcam.io.mosaic_reader: the pipeline's own mosaic read (checked against rawpy)",
        "read_frame": "shadowcam.io.decode.read_frame: rawpy + bilinear demosaic + float32 RGB",
    }
    lines = [
        f"shadowcam benchmark: {f['n_frames']} DNG frames of {f['height']}x{f['width']} "
        f"(14-bit, compression {f['compression']}), {f['workers']} processes; best-effort timings on a shared machine",
        "",
        "end to end (DNG files -> shadow-time map, default method):",
        f"  pipeline            {f['end_to_end_s']:8.1f} s  {f['end_to_end_mpfs']:8.1f} M pixel-frames/s",
    ]
    for reader, note in floor_note.items():
        lines.append(f"  {reader + ' floor':19s} {f[reader + '_floor_s']:8.1f} s  "
                     f"{f[reader + '_floor_mpfs']:8.1f} M pixel-frames/s   ({note})")
    lines += [
        f"  ratio to decode floor (direct)  {f['ratio_to_direct_floor']:.3f}   (target >= 0.8: the decode the pipeline uses)",
        f"  ratio to decode floor (rawpy)   {f['ratio_to_decode_floor']:.3f}",
        "",
    ]
    g = f["stages"]
    lines += [
        f"CPU time per stage on one thread ({g['frames']} frames of the sweep, ns per pixel-frame):",
        f"  decode (direct mosaic read) {g['decode']:6.1f}   mosaic -> signal {g['signal']:6.1f}"
        f"   own site in the first pass {g['own']:6.1f}   tracker update {g['track']:6.1f}",
        f"  own site's second read of every file {g['site_read']:6.1f}",
        f"  least tracker arithmetic (store, smooth, compare) {g['minimal_track']:6.1f};"
        f" one numpy pass over the signal {g['numpy_pass']:6.1f}",
        f"  once per sweep: finish {g['finish_s']:.2f} s, interval from the windows {g['interval_s']:.2f} s"
        f" ({g['interval_unresolved']} of {g['pixels']} pixels need a second read), classify + time"
        f" {g['timing_s']:.2f} s",
        f"  budget: tracking the decoded frames costs"
        f" {(g['signal'] + g['own'] + g['track'] + g['site_read']) / g['decode']:.2f}"
        " of the decode"
        f" (0.25 would give 0.8 end to end on the same cores)",
        "",
        f"shadow-time stage alone ({f['stage_frames']} in-memory frames of the central quarter):",
    ]
    for name, label in (("signal", "(T, H/2, W/2) channel-sum planes, as the file pipeline tracks them"),
                        ("rgb", "(T, H/2, W/2, 3) RGB frames, as the workflow's frame store holds them")):
        g = f[name]
        lines += [
            f"  {label}:",
            f"    tracking        {g['tracking_mpfs']:8.1f} M pixel-frames/s;"
            f" one numpy pass over the same bytes {g['numpy_pass_mpfs']:8.1f}",
            f"    ratio to numpy pass    {g['ratio_to_numpy_pass']:.3f}   (aim >= 0.25);"
            f" tracker CPU {g['tracking_cpu_ns']:.1f} ns per pixel-frame on one thread",
            f"    classify + time once per sweep (full image) {g['finish_s']:.2f} s;"
            f" whole stage at {f['n_frames']} frames {g['with_finish_mpfs_at_n']:.1f} M pixel-frames/s",
        ]
    lines += [
        "",
        "peak memory of the end-to-end run (parent + workers):",
        f"  {f['short']:5d} frames  {f['peak_rss_short_mib']:8.0f} MiB",
        f"  {f['n_frames']:5d} frames  {f['peak_rss_long_mib']:8.0f} MiB",
        f"  ratio              {f['peak_rss_ratio']:.2f}   (must stay < 1.2)",
        "",
        f"accuracy of the default configuration ({f['n_frames']} frames, exact truth):",
        f"  |time error| median {acc['median']:.3f}  p95 {acc['p95']:.3f}  max {acc['max']:.2f} frame;"
        f" coverage {100 * acc['coverage']:.1f} %",
    ]
    return "\n".join(lines)
