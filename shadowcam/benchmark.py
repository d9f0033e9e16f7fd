"""Speed benchmark of the shadow-time pipeline against its hardware floors (``make bench``).

A wire's shadow sweeps a textured plane; frames are rendered analytically
(exact shadow time at every pixel centre), mosaicked, given sensor noise and
written as 14-bit DNG files. The benchmark then measures, on this machine:

* end to end, DNG files -> shadow-time maps (:func:`shadowcam.sweep_files.sweep_shadow_times_from_files`,
  both cores), against the decode floor: the same files decoded by the
  pipeline's own decoder (and by rawpy alone) in as many processes, doing
  nothing else;
* the shadow-time stage alone on in-memory frames, in pixel-frames per
  second, against one numpy pass over the same bytes (memory-bandwidth floor);
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

import numpy as np

from shadowcam.accuracy import shadow_time_errors
from shadowcam.raw_writer import write_dng
from shadowcam.sensor import SensorModel, simulate_raw
from shadowcam.sweep_files import _CONTEXT


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


def _write_frames(scene, directory, indices):
    """Worker: render, add noise and write frames `indices` of `scene`."""
    albedo = scene.albedo()
    for k in indices:
        raw = simulate_raw(scene.frame(k, albedo), sensor=_SENSOR, scale=scene.electrons,
                           seed=[scene.seed, int(k)])
        write_dng(Path(directory) / f"frame_{k:05d}.dng", raw, bit_depth=14,
                  black_level=_SENSOR.black_level)


def write_sweep_dngs(scene, directory, *, workers=2):
    """Render `scene` to ``directory/frame_NNNNN.dng`` unless already there; return the paths.

    Parameters
    ----------
    scene : WireScene
    directory : str or Path
        Reused when its ``scene.json`` matches `scene`.
    workers : int, optional
        Rendering processes.

    Returns
    -------
    list of Path
    """
    directory = Path(directory)
    stamp = directory / "scene.json"
    paths = [directory / f"frame_{k:05d}.dng" for k in range(scene.n_frames)]
    if stamp.is_file() and json.loads(stamp.read_text()) == asdict(scene) and all(p.is_file() for p in paths):
        return paths
    directory.mkdir(parents=True, exist_ok=True)
    stamp.unlink(missing_ok=True)
    parts = np.array_split(np.arange(scene.n_frames), workers)
    with ProcessPoolExecutor(workers, mp_context=_CONTEXT) as pool:
        list(pool.map(_write_frames, [scene] * workers, [directory] * workers, parts))
    stamp.write_text(json.dumps(asdict(scene)))
    return paths


def _decode_files(paths, reader):
    if reader == "rawpy":
        import rawpy

        for path in paths:
            with rawpy.imread(str(path)) as raw:
                raw.raw_image_visible.copy()
    else:
        from shadowcam.decode import read_frame

        for path in paths:
            read_frame(path)


def decode_floor_seconds(paths, *, workers=2, reader="shadowcam"):
    """Wall time to decode `paths` in `workers` processes and do nothing else.

    Parameters
    ----------
    paths : sequence of Path
    workers : int, optional
    reader : {"shadowcam", "rawpy"}, optional
        ``shadowcam``: :func:`shadowcam.decode.read_frame` (rawpy, demosaic,
        linear float32 -- the pipeline's own decode); ``rawpy``: open and
        unpack the mosaic only.
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
    from shadowcam.shadow_time import summary_shadow_times, track_sweep

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

    from shadowcam.dip_tracker import DipTracker

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


_END_TO_END = """
import json, resource, sys, time
import numpy as np
from shadowcam.sweep_files import sweep_shadow_times_from_files
paths, workers, out = json.loads(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
start = time.perf_counter()
result = sweep_shadow_times_from_files(paths, workers=workers)
seconds = time.perf_counter() - start
np.save(out, result["shadow_time"])
own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
child = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
print(json.dumps({"seconds": seconds, "peak_rss_mib": (own + workers * child) / 1024}))
"""


def end_to_end(paths, *, workers=2, out=None):
    """Run :func:`~shadowcam.sweep_files.sweep_shadow_times_from_files` in a fresh process.

    Returns
    -------
    seconds : float
        Wall time of the call (decode, tracking, merge, timing).
    peak_rss_mib : float
        Peak resident memory of the parent plus `workers` times the largest
        worker's (an upper bound of the simultaneous total).
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


def run_benchmark(directory, *, scene=None, short=100, workers=2, stage_frames=240, log=print):
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
    log : callable, optional
        Progress messages.

    Returns
    -------
    dict
        Figures (see :func:`format_report`).
    """
    from shadowcam.decode import read_frame

    scene = scene or WireScene()
    log(f"rendering {scene.n_frames} DNG frames of {scene.height}x{scene.width_px} into {directory} ...")
    paths = write_sweep_dngs(scene, directory, workers=workers)
    pixels = scene.height * scene.width_px
    figures = {"height": scene.height, "width": scene.width_px, "n_frames": scene.n_frames,
               "short": short, "workers": workers}

    log("reading the files once (page cache) ...")
    for path in paths:
        path.read_bytes()
    log("decode floor, end to end, decode floor again ...")
    floor_long = decode_floor_seconds(paths, workers=workers)
    rawpy_long = decode_floor_seconds(paths, workers=workers, reader="rawpy")
    e2e_long, rss_long, shadow_time = end_to_end(paths, workers=workers)
    floor_long = min(floor_long, decode_floor_seconds(paths, workers=workers))
    log("end to end, short sequence ...")
    e2e_short, rss_short, _ = end_to_end(paths[:short], workers=workers)
    figures.update(
        decode_floor_s=floor_long, rawpy_floor_s=rawpy_long, end_to_end_s=e2e_long,
        end_to_end_mpfs=pixels * scene.n_frames / e2e_long / 1e6,
        decode_floor_mpfs=pixels * scene.n_frames / floor_long / 1e6,
        rawpy_floor_mpfs=pixels * scene.n_frames / rawpy_long / 1e6,
        ratio_to_decode_floor=floor_long / e2e_long, ratio_to_rawpy_floor=rawpy_long / e2e_long,
        peak_rss_short_mib=rss_short, peak_rss_long_mib=rss_long,
        peak_rss_ratio=rss_long / rss_short, end_to_end_short_s=e2e_short,
    )
    truth = scene.truth()
    figures["accuracy"] = shadow_time_errors(shadow_time, truth, lit=np.ones(truth.shape, bool))

    log(f"stage alone on {stage_frames} in-memory frames (central quarter of the image) ...")
    middle = scene.n_frames // 2 - stage_frames // 2
    rows = slice(scene.height // 4, scene.height // 4 + scene.height // 2)
    cols = slice(scene.width_px // 4, scene.width_px // 4 + scene.width_px // 2)
    frames = np.stack([read_frame(p)[rows, cols] for p in paths[middle:middle + stage_frames]])
    tracking, finishing = stage_seconds(frames)
    numpy_pass = numpy_pass_seconds(frames)
    figures["tracking_cpu_ns"] = tracking_cpu_ns(frames)
    crop = frames.shape[1] * frames.shape[2]
    figures.update(
        stage_frames=stage_frames,
        stage_tracking_mpfs=crop * stage_frames / tracking / 1e6,
        stage_finish_s=finishing * pixels / crop,
        numpy_pass_mpfs=crop * stage_frames / numpy_pass / 1e6,
        ratio_to_numpy_pass=numpy_pass / tracking,
    )
    figures["stage_with_finish_mpfs_at_n"] = pixels * scene.n_frames / (
        pixels * scene.n_frames / (figures["stage_tracking_mpfs"] * 1e6) + figures["stage_finish_s"]) / 1e6
    return figures


def format_report(figures):
    """Printable text of :func:`run_benchmark`'s figures."""
    f = figures
    acc = f["accuracy"]
    lines = [
        f"shadowcam benchmark: {f['n_frames']} DNG frames of {f['height']}x{f['width']} "
        f"(14-bit, uncompressed), {f['workers']} processes; best-effort timings on a shared machine",
        "",
        "end to end (DNG files -> shadow-time map, default method):",
        f"  pipeline           {f['end_to_end_s']:8.1f} s  {f['end_to_end_mpfs']:8.1f} M pixel-frames/s",
        f"  decode floor       {f['decode_floor_s']:8.1f} s  {f['decode_floor_mpfs']:8.1f} M pixel-frames/s"
        "   (shadowcam.decode.read_frame: rawpy + demosaic + linear float32, nothing else)",
        f"  rawpy-only floor   {f['rawpy_floor_s']:8.1f} s  {f['rawpy_floor_mpfs']:8.1f} M pixel-frames/s"
        "   (rawpy open + raw_image_visible)",
        f"  ratio to decode floor  {f['ratio_to_decode_floor']:.2f}   (target >= 0.8)",
        f"  ratio to rawpy floor   {f['ratio_to_rawpy_floor']:.2f}",
        "",
        f"shadow-time stage alone ({f['stage_frames']} in-memory (T, H/2, W/2, 3) float32 frames):",
        f"  tracking           {f['stage_tracking_mpfs']:8.1f} M pixel-frames/s",
        f"  one numpy pass     {f['numpy_pass_mpfs']:8.1f} M pixel-frames/s over the same bytes",
        f"  ratio to numpy pass    {f['ratio_to_numpy_pass']:.3f}   (aim >= 0.25)",
        f"  tracker CPU time   {f['tracking_cpu_ns']:8.1f} ns per pixel-frame on one thread"
        " (process CPU time: less sensitive to other jobs)",
        f"  classify + time (once per sweep, scaled to the full image) {f['stage_finish_s']:.2f} s;"
        f" whole stage at {f['n_frames']} frames {f['stage_with_finish_mpfs_at_n']:.1f} M pixel-frames/s",
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
