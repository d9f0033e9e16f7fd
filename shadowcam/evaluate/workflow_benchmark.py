"""Per-stage throughput and memory of a workflow run, and their extrapolation to a long capture.

Reads the Snakemake ``benchmark:`` files of one dataset (the jobs of a
time-parted stage, ``<stage>_part<...>.tsv``, are summed) and tabulates per
stage: jobs, wall time (sum over jobs), seconds per frame, frames/s, MP/s, peak
RSS of its largest job; then extrapolates to a number of frames on a number of
cores: every stage is taken as linear in the number of frames (fixed costs
included in the per-frame rate, so an overestimate for short runs), stages run
as several jobs divide by the cores, and memory is the peak per job (it does
not grow with the number of frames: compare runs of several lengths) times the jobs that run
at once. Disk: the decoded frame store per frame.

The scale targets of an outdoor time-lapse are ratios measured in one run:
the frame store's size over the RAW files' size, the end-to-end time (sum of
every job's wall time) and the first pass (registration and gains) over the
decode-only time of the same frames (the pipeline's own mosaic reader, timed
in the same run), the largest job's peak RSS, and the growth of each stage's
peak RSS from 100 to 1000 frames, a least-squares line through runs of
different lengths.

Offers
------
read_benchmarks : stage -> list of (seconds, max RSS MB) per job.
directory_bytes : total size of the files under a directory.
benchmark_table : the per-stage table and the extrapolation, as text lines.
registration_line : the registration error at a sample's size against its applied shake, as text.
accuracy_line : the arrival-time accuracy of a run against its ground truth, as text.
time_decode : decode-only time and size of RAW frames, with the pipeline's reader.
memory_growth : per-stage peak RSS, a least-squares line through runs of several lengths, at two frame counts.
growth_table : its lines, per stage.
read_runs : the benchmarks of several runs, longest first.
scale_targets : the four scale ratios of a run against their targets, as text lines.
"""

import csv
import math
import re
import time
from pathlib import Path

import numpy as np

from shadowcam._shared.validation import check_in
from shadowcam.outdoor.accuracy import registration_errors


def read_benchmarks(directory, *, clock="wall"):
    """Return ``{stage: [(seconds, max_rss_mb), ...]}`` from the benchmark TSVs in `directory`.

    `clock` ``"wall"`` reads the wall time (column ``s``), ``"cpu"`` the CPU time of
    the job's processes (``cpu_time``: what a job costs whatever else loads the machine).
    """
    column = {"wall": "s", "cpu": "cpu_time"}.get(clock)
    if column is None:
        raise ValueError(f"clock must be 'wall' or 'cpu'; got {clock!r}")
    directory = Path(directory)
    files = sorted(directory.glob("*.tsv"))
    if not files:
        raise ValueError(f"no benchmark files in {directory}; run the workflow first")
    stages = {}
    for path in files:
        with path.open() as handle:
            rows = list(csv.DictReader(handle, delimiter="\t"))
        # the jobs of a stage run in time parts or column strips count as one stage
        stage = re.sub(r"_(part|strip)[^_]*$", lambda match: f"_{match.group(1)}s", path.stem)
        for row in rows[-1:]:
            rss = float(row["max_rss"]) if row["max_rss"] not in ("", "NA", "-") else float("nan")
            stages.setdefault(stage, []).append((float(row[column]), rss))
    return stages


def directory_bytes(path):
    """Total size in bytes of the files under `path`."""
    return sum(f.stat().st_size for f in Path(path).rglob("*") if f.is_file())


def benchmark_table(stages, *, n_frames, shape, store_bytes, before=None, before_frames=None,
                    extrapolate=1000, cores=2):
    """The per-stage table of a run and its extrapolation.

    Parameters
    ----------
    stages : mapping
        :func:`read_benchmarks` of the run.
    n_frames : int
        Frames of the run.
    shape : (int, int)
        ``(rows, cols)`` of a frame.
    store_bytes : int
        Size of the run's decoded frame store.
    before : mapping, optional
        :func:`read_benchmarks` of a run with fewer frames (memory growth).
    before_frames : int, optional
        Its number of frames (shown in the header).
    extrapolate : int
        Frames to extrapolate to.
    cores : int
        Jobs side by side on the target machine.

    Returns
    -------
    list of str
    """
    if n_frames < 1 or cores < 1 or extrapolate < 1:
        raise ValueError(f"n_frames, cores and extrapolate must be >= 1; got {n_frames}, {cores}, {extrapolate}")
    before = before or {}
    rows, cols = shape
    megapixels = rows * cols / 1e6
    lines = [f"{n_frames} frames of {cols}x{rows} ({megapixels:.1f} MP); "
             "wall = sum over the stage's jobs; shared machine: timings are noisy"]
    header = f"{'stage':28s} {'jobs':>4s} {'wall_s':>8s} {'s/frame':>8s} {'frames/s':>8s} {'MP/s':>7s} {'peak_MB':>8s}"
    if before:
        header += f" {'peak_MB@' + str(before_frames or '?'):>12s} {'ratio':>6s}"
    lines.append(header)
    total_wall, total_target, peak_parallel = 0.0, 0.0, 0.0
    for stage, jobs in stages.items():
        seconds = sum(s for s, _ in jobs)
        peak = max(r for _, r in jobs)
        per_frame = seconds / n_frames
        line = (f"{stage:28s} {len(jobs):4d} {seconds:8.1f} {per_frame:8.2f} {1 / per_frame:8.3f} "
                f"{megapixels / per_frame:7.1f} {peak:8.0f}")
        if stage in before:
            old = max(r for _, r in before[stage])
            line += f" {old:12.0f} {peak / old:6.2f}"
        lines.append(line)
        side_by_side = min(cores, len(jobs)) if len(jobs) > 1 else 1
        total_wall += seconds
        total_target += per_frame * extrapolate / side_by_side
        peak_parallel = max(peak_parallel, peak * side_by_side)
    store = store_bytes / n_frames
    lines.append(f"{'all stages':28s} {'':4s} {total_wall:8.1f} {total_wall / n_frames:8.2f} "
                 f"{n_frames / total_wall:8.3f} {n_frames * megapixels / total_wall:7.1f}")
    lines.append(f"extrapolated to {extrapolate} frames on {cores} cores: {total_target / 3600:.1f} h "
                 f"(parted stages {cores} jobs side by side, the others one job), peak memory "
                 f"{peak_parallel / 1024:.1f} GB (largest job x jobs side by side), decoded store "
                 f"{store * extrapolate / 1e9:.0f} GB ({store / 1e6:.0f} MB/frame)")
    return lines


def registration_line(photometry, shake, *, shape):
    """The registration error of `photometry` against a sample's applied `shake`, as text.

    Parameters
    ----------
    photometry : xarray.Dataset
        With ``shift_row``, ``shift_col`` (estimated shifts to frame 0).
    shake : mapping
        ``shake_dx_px``, ``shake_dy_px`` of the sample's sidecar.
    shape : (int, int)
        ``(rows, cols)`` of the frames.
    """
    errors = registration_errors(photometry["shift_row"].values, photometry["shift_col"].values,
                                 shake_dy=shake["shake_dy_px"], shake_dx=shake["shake_dx_px"])
    return (f"registration at {shape[1]}x{shape[0]} against the applied shake "
            f"(up to {errors['true_max_px']:.2f} px from frame 0): rms {errors['rms_px']:.3f} px "
            f"(rows {errors['rms_row_px']:.3f}, cols {errors['rms_col_px']:.3f}), max {errors['max_abs_px']:.3f} px")


def accuracy_line(accuracy, *, shape):
    """The arrival-time accuracy of a run against its ground truth, as text.

    Parameters
    ----------
    accuracy : mapping
        The run's ``outdoor/accuracy.json`` (``shadowcam outdoor-accuracy``): errors in
        frame intervals of the primary estimator and definition, its targets.
    shape : (int, int)
        ``(rows, cols)`` of the frames.
    """
    errors = accuracy["errors"][accuracy["primary_estimator"]][accuracy["primary_definition"]]
    verdict = ", ".join(f"{t['target']} {t['comparison']} {t['threshold']:g} {'pass' if t['pass'] else 'FAIL'}"
                        for t in accuracy["targets"])
    return (f"arrival accuracy at {shape[1]}x{shape[0]} ({accuracy['primary_estimator']}, "
            f"{accuracy['primary_definition']}, {errors['n_evaluated']} pixels, interval "
            f"{accuracy['interval_s']:.1f} s): median {errors['median_abs']:.3f}, p95 {errors['p95_abs']:.3f} "
            f"intervals, beyond 5 intervals {100 * errors['frac_over_5']:.2f} %, coverage "
            f"{100 * errors['coverage']:.1f} % ({verdict})")


#: scale targets of an outdoor time-lapse: store / RAW bytes, end-to-end / decode,
#: first pass / decode, largest job's peak RSS (MB), peak RSS at 1000 / 100 frames
SCALE_TARGETS = {"store": 1.5, "end_to_end": 3.0, "pass1": 1.0, "peak_mb": 4096.0, "growth": 1.2}


def time_decode(paths):
    """Decode-only time and total size of a sweep's RAW frames, read as the pipeline reads them.

    The mosaics are read through one :class:`shadowcam.io.mosaic_reader.MosaicReader`
    (directly from the DNG data where verified equal to rawpy, else rawpy);
    building the reader (its rawpy check of the first frame) is not timed, and
    every frame, the first included, is read again timed. Then every frame is
    decoded to linear float32 RGB (:func:`shadowcam.io.decode.read_frame`:
    mosaic, bilinear demosaic, levels), timed separately.

    Parameters
    ----------
    paths : sequence of str or Path
        RAW frame files of one sweep (at least one).

    Returns
    -------
    dict
        ``frames``, ``raw_bytes`` (sum of the file sizes), ``mosaic_s`` (total
        seconds of the mosaic reads), ``mosaic_cpu_s`` (their CPU seconds), ``rgb_s`` (total seconds of the decodes
        to float RGB), ``direct`` (whether the direct reader was used).
    """
    from shadowcam.io.decode import read_frame
    from shadowcam.io.mosaic_reader import MosaicReader

    paths = [Path(p) for p in paths]
    if not paths:
        raise ValueError("paths must list at least one RAW frame")
    reader = MosaicReader(paths[0])
    reader.read(paths[0])  # hands out the cached first mosaic: later reads of it decode again
    started, cpu = time.perf_counter(), time.process_time()
    for path in paths:
        reader.read(path)
    mosaic_s, mosaic_cpu_s = time.perf_counter() - started, time.process_time() - cpu
    started = time.perf_counter()
    for path in paths:
        read_frame(path, mosaics=reader)
    rgb_s = time.perf_counter() - started
    return {"frames": len(paths), "raw_bytes": sum(p.stat().st_size for p in paths), "mosaic_s": mosaic_s,
            "mosaic_cpu_s": mosaic_cpu_s, "rgb_s": rgb_s, "direct": reader.direct}


def read_runs(paths, frames, *, clock="wall"):
    """Read the benchmarks of several runs, longest first.

    Parameters
    ----------
    paths : sequence of str or Path
        ``benchmarks/<ds>`` directories (:func:`read_benchmarks`).
    frames : sequence of int
        The frames of each run, in the same order.
    clock : {"wall", "cpu"}
        As :func:`read_benchmarks`.

    Returns
    -------
    list of (mapping, int)
        ``(stages, frames)`` per run, by decreasing frames.
    """
    if len(paths) != len(frames):
        raise ValueError(f"runs: {len(paths)} benchmark directories but {len(frames)} frame counts; give one "
                         "frame count per run (--compare-frames once per --compare)")
    runs = [(read_benchmarks(path, clock=clock), int(n)) for path, n in zip(paths, frames)]
    return sorted(runs, key=lambda run: -run[1])


def memory_growth(runs, *, low=100, high=1000):
    """Per-stage peak RSS of the largest job, extrapolated linearly to `low` and `high` frames.

    Each stage's peak is fitted as ``a + b * frames`` by least squares through the
    runs (two runs: the line through them; a small run's slope is mostly noise,
    so three or more frame counts tell a slope from noise better). A negative
    slope, the longer runs peaking lower, is taken as 0 (a peak cannot shrink as
    frames are added), and the line then passes through the runs' mean peak.

    Parameters
    ----------
    runs : sequence of (mapping, int)
        ``(stages, frames)``: :func:`read_benchmarks` of a run and its number of frames;
        at least two different frame counts.
    low, high : int
        Frame counts to extrapolate to.

    Returns
    -------
    dict
        ``{stage: (peak_mb_at_low, peak_mb_at_high, ratio)}`` for the stages in every run
        with a finite peak.
    """
    runs = [(stages, int(frames)) for stages, frames in runs]
    counts = [frames for _, frames in runs]
    if len(set(counts)) < 2 or min(counts + [low, high]) < 1:
        raise ValueError(f"runs must have at least two different frame counts, all >= 1; got {counts}")
    out = {}
    for stage in set.intersection(*(set(stages) for stages, _ in runs)):
        peaks = np.array([max(r for _, r in stages[stage]) for stages, _ in runs])
        if not np.isfinite(peaks).all():
            continue
        x = np.array(counts, dtype=np.float64)
        slope = max(0.0, float(np.polyfit(x, peaks, 1)[0]))
        base = float(np.mean(peaks - slope * x))
        at_low, at_high = base + slope * low, base + slope * high
        out[stage] = (at_low, at_high, at_high / at_low if at_low > 0 else float("inf"))
    return out


def growth_table(growth):
    """Lines of :func:`memory_growth`: per stage, the peak at 100 and 1000 frames and their ratio."""
    lines = [f"{'peak RSS per job (line through the runs)':44s} {'MB@100':>8s} {'MB@1000':>8s} {'ratio':>6s}"]
    for stage, (low, high, ratio) in sorted(growth.items(), key=lambda item: -item[1][2]):
        lines.append(f"{stage:44s} {low:8.0f} {high:8.0f} {ratio:6.2f}")
    return lines


def _job_seconds(stages, prefix=""):
    return sum(s for stage, jobs in stages.items() if stage.startswith(prefix) for s, _ in jobs)


def scale_targets(stages, *, n_frames, store_bytes, decode, growth=None, before=None, before_frames=None,
                  clock="wall"):
    """The scale ratios of an outdoor run against :data:`SCALE_TARGETS`, as text lines.

    Parameters
    ----------
    stages : mapping
        :func:`read_benchmarks` of the run.
    n_frames : int
        Frames of the run (those timed by `decode`).
    store_bytes : int
        Size of the run's frame store.
    decode : mapping
        :func:`time_decode` of the run's RAW frames.
    growth : mapping, optional
        :func:`memory_growth` of the run and shorter ones; the worst
        stage whose jobs read the whole sweep is shown (a parted stage's jobs
        read a fixed number of frames whatever the sweep's length).
    before, before_frames : mapping and int, optional
        :func:`read_benchmarks` of a shorter run and its frames: the time
        ratios are also given per added frame (the run's time minus the
        shorter run's over the frames added, against the decode time per
        frame), which leaves out the fixed costs of the jobs (start-up, DAG)
        that dominate small runs; parted stages add jobs as frames grow, so
        their per-job costs stay in.
    clock : {"wall", "cpu"}
        The clock of `stages` and `before` (:func:`read_benchmarks`); the
        decode time compared is ``mosaic_s`` or ``mosaic_cpu_s`` to match.

    Returns
    -------
    list of str
        One line per target: quantity, measured, target, ``ok`` or ``MISSED``.
    """
    if decode["frames"] != n_frames:
        raise ValueError(f"decode must time the run's {n_frames} frames; got {decode['frames']}")
    peaks = {stage: max(r for _, r in jobs) for stage, jobs in stages.items()}
    largest = max(peaks, key=lambda stage: peaks[stage] if math.isfinite(peaks[stage]) else -1.0)
    check_in(clock, "clock", ("wall", "cpu"))
    decode_s = decode["mosaic_s" if clock == "wall" else "mosaic_cpu_s"]
    per = decode_s / n_frames
    reader = "direct mosaic reader" if decode["direct"] else "rawpy"
    lines = [f"{clock} time; decode-only ({reader}, same frames, this run): {per:.3f} s/frame mosaic, "
             f"{decode['rgb_s'] / n_frames:.3f} s/frame to float RGB (wall); RAW {decode['raw_bytes'] / n_frames / 1e6:.1f} "
             f"MB/frame",
             f"{'target':52s} {'measured':>10s} {'target':>8s}"]

    def row(name, value, limit):
        verdict = "ok" if value <= limit else "MISSED"
        return f"{name:52s} {value:10.2f} {limit:8.2f}  {verdict}"

    lines.append(row("frame store / RAW bytes", store_bytes / decode["raw_bytes"], SCALE_TARGETS["store"]))
    marginal = bool(before and before_frames and before_frames != n_frames)
    for name, prefix, limit in (("end-to-end (all jobs)", "", "end_to_end"),
                                ("pass 1 (registration, gains)", "outdoor_normalise", "pass1")):
        spent = _job_seconds(stages, prefix)
        lines.append(row(f"{name} / decode-only time", spent / decode_s, SCALE_TARGETS[limit]))
        if marginal:
            added = (spent - _job_seconds(before, prefix)) / (n_frames - before_frames)
            lines.append(row(f"  the same per added frame ({before_frames} -> {n_frames})", added / per,
                             SCALE_TARGETS[limit]))
    lines.append(row(f"peak RSS per job, MB ({largest})", peaks[largest], SCALE_TARGETS["peak_mb"]))
    # a parted stage's jobs read a fixed number of frames whatever the sweep's length: only the
    # stages whose jobs read the whole sweep can grow with it
    whole = {stage: value for stage, value in (growth or {}).items() if not stage.endswith("_parts")}
    if whole:
        worst = max(whole, key=lambda stage: whole[stage][2])
        low, high, ratio = whole[worst]
        lines.append(row(f"peak RSS 1000 / 100 frames ({worst})", ratio, SCALE_TARGETS["growth"]))
        lines.append(f"  (least-squares line through the runs: {low:.0f} MB at 100 frames, {high:.0f} MB at 1000; "
                     "parted stages: jobs of a fixed number of frames)")
    return lines
