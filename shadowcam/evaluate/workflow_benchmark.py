"""Per-stage throughput and memory of a workflow run, and their extrapolation to a long capture.

Reads the Snakemake ``benchmark:`` files of one dataset (the jobs of a
time-parted stage, ``<stage>_part<...>.tsv``, are summed) and tabulates per
stage: jobs, wall time (sum over jobs), seconds per frame, frames/s, MP/s, peak
RSS of its largest job; then extrapolates to a number of frames on a number of
cores: every stage is taken as linear in the number of frames (fixed costs
included in the per-frame rate, so an overestimate for short runs), stages run
as several jobs divide by the cores, and memory is the peak per job (it does
not grow with the number of frames: compare two runs) times the jobs that run
at once. Disk: the decoded frame store per frame.

Offers
------
read_benchmarks : stage -> list of (seconds, max RSS MB) per job.
directory_bytes : total size of the files under a directory.
benchmark_table : the per-stage table and the extrapolation, as text lines.
registration_line : the registration error at a sample's size against its applied shake, as text.
"""

import csv
import re
from pathlib import Path

from shadowcam.outdoor.accuracy import registration_errors


def read_benchmarks(directory):
    """Return ``{stage: [(seconds, max_rss_mb), ...]}`` from the benchmark TSVs in `directory`."""
    directory = Path(directory)
    files = sorted(directory.glob("*.tsv"))
    if not files:
        raise ValueError(f"no benchmark files in {directory}; run the workflow first")
    stages = {}
    for path in files:
        with path.open() as handle:
            rows = list(csv.DictReader(handle, delimiter="\t"))
        stage = re.sub(r"_part[^_]*$", "_parts", path.stem)
        for row in rows[-1:]:
            rss = float(row["max_rss"]) if row["max_rss"] not in ("", "NA", "-") else float("nan")
            stages.setdefault(stage, []).append((float(row["s"]), rss))
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
