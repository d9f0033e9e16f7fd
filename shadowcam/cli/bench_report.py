"""``shadowcam bench-report``: per-stage throughput and memory of a workflow run, extrapolated.

Reads the Snakemake ``benchmark:`` files of one dataset (``benchmarks/<ds>/*.tsv``;
the jobs of a time-parted stage, ``<stage>_part<...>.tsv``, are summed) and prints per
stage: jobs, wall time (sum over jobs), seconds per frame, frames/s, MP/s, peak RSS
of its largest job; then the extrapolation to ``--extrapolate`` frames on ``--cores``
cores: every stage is taken as linear in the number of frames (fixed costs included
in the per-frame rate, so an overestimate for short runs), stages run as several
jobs divide by the cores, and memory is the peak per job (it does not grow with the
number of frames: compare two runs with ``--compare``) times the jobs that run at
once. Disk: the decoded frame store per frame. With ``--photometry`` and ``--shake``
(a sample's sidecar, ``shadowcam outdoor-sample``) it also prints the registration
error at that size against the applied shake.

Offers
------
add_parser : register the step and its options.
read_benchmarks : stage -> list of (seconds, max RSS MB) per job.
run : print the table.
"""

import csv
import json
import re
from pathlib import Path

from shadowcam.io.datasets import open_dataset
from shadowcam.io.frame_store import open_frames
from shadowcam.outdoor.accuracy import registration_errors


def add_parser(subparsers, name):
    """Register ``bench-report`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="per-stage throughput / memory of a run, extrapolated",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--benchmarks", required=True, help="benchmarks/<ds> directory of a finished run")
    parser.add_argument("--frames", required=True, help="the run's frame store (results/<ds>/frames/<sweep>.zarr)")
    parser.add_argument("--compare", default=None, help="benchmarks/<ds> of a run with fewer frames (memory growth)")
    parser.add_argument("--compare-frames", type=int, default=None, help="number of frames of the --compare run")
    parser.add_argument("--extrapolate", type=int, default=1000, help="frames to extrapolate to")
    parser.add_argument("--cores", type=int, default=2, help="cores (jobs side by side) of the target machine")
    parser.add_argument("--photometry", default=None, help="the run's results/<ds>/outdoor/photometry.nc (estimated shifts)")
    parser.add_argument("--shake", default=None, help="sidecar JSON with the applied shake_dx_px, shake_dy_px")
    return parser


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


def _store_bytes(path):
    return sum(f.stat().st_size for f in Path(path).rglob("*") if f.is_file())


def run(args):
    """Print the per-stage table and the extrapolation."""
    frames = open_frames(args.frames)
    n_frames = frames.sizes["time"]
    megapixels = frames.sizes["row"] * frames.sizes["col"] / 1e6
    stages = read_benchmarks(args.benchmarks)
    before = read_benchmarks(args.compare) if args.compare else {}
    print(f"{n_frames} frames of {frames.sizes['col']}x{frames.sizes['row']} ({megapixels:.1f} MP); "
          "wall = sum over the stage's jobs; shared machine: timings are noisy")
    header = f"{'stage':28s} {'jobs':>4s} {'wall_s':>8s} {'s/frame':>8s} {'frames/s':>8s} {'MP/s':>7s} {'peak_MB':>8s}"
    if before:
        header += f" {'peak_MB@' + str(args.compare_frames or '?'):>12s} {'ratio':>6s}"
    print(header)
    total_wall, total_1000, peak_parallel = 0.0, 0.0, 0.0
    for stage, jobs in stages.items():
        seconds = sum(s for s, _ in jobs)
        peak = max(r for _, r in jobs)
        per_frame = seconds / n_frames
        line = (f"{stage:28s} {len(jobs):4d} {seconds:8.1f} {per_frame:8.2f} {1 / per_frame:8.3f} "
                f"{megapixels / per_frame:7.1f} {peak:8.0f}")
        if stage in before:
            old = max(r for _, r in before[stage])
            line += f" {old:12.0f} {peak / old:6.2f}"
        print(line)
        side_by_side = min(args.cores, len(jobs)) if len(jobs) > 1 else 1
        total_wall += seconds
        total_1000 += per_frame * args.extrapolate / side_by_side
        peak_parallel = max(peak_parallel, peak * side_by_side)
    store = _store_bytes(args.frames) / n_frames
    print(f"{'all stages':28s} {'':4s} {total_wall:8.1f} {total_wall / n_frames:8.2f} "
          f"{n_frames / total_wall:8.3f} {n_frames * megapixels / total_wall:7.1f}")
    print(f"extrapolated to {args.extrapolate} frames on {args.cores} cores: {total_1000 / 3600:.1f} h "
          f"(parted stages {args.cores} jobs side by side, the others one job), peak memory "
          f"{peak_parallel / 1024:.1f} GB (largest job x jobs side by side), decoded store "
          f"{store * args.extrapolate / 1e9:.0f} GB ({store / 1e6:.0f} MB/frame)")
    if args.photometry and args.shake:
        photometry = open_dataset(args.photometry)
        shake = json.loads(Path(args.shake).read_text())
        errors = registration_errors(photometry["shift_row"].values, photometry["shift_col"].values,
                                     shake_dy=shake["shake_dy_px"], shake_dx=shake["shake_dx_px"])
        print(f"registration at {frames.sizes['col']}x{frames.sizes['row']} against the applied shake "
              f"(up to {errors['true_max_px']:.2f} px from frame 0): rms {errors['rms_px']:.3f} px "
              f"(rows {errors['rms_row_px']:.3f}, cols {errors['rms_col_px']:.3f}), max {errors['max_abs_px']:.3f} px")
