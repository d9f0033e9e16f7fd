"""``shadowcam bench-report``: per-stage throughput and memory of a workflow run, extrapolated.

Reads the Snakemake ``benchmark:`` files of one dataset (``benchmarks/<ds>/*.tsv``;
the jobs of a time-parted stage, ``<stage>_part<...>.tsv``, are summed) and prints per
stage (:mod:`shadowcam.evaluate.workflow_benchmark`): jobs, wall time (sum over jobs), seconds per frame, frames/s, MP/s, peak RSS
of its largest job; then the extrapolation to ``--extrapolate`` frames on ``--cores``
cores: every stage is taken as linear in the number of frames (fixed costs included
in the per-frame rate, so an overestimate for short runs), stages run as several
jobs divide by the cores, and memory is the peak per job (it does not grow with the
number of frames: compare runs with ``--compare``) times the jobs that run at
once. Disk: the decoded frame store per frame. With ``--photometry`` and ``--shake``
(a sample's sidecar, ``shadowcam outdoor-sample``) it also prints the registration
error at that size against the applied shake; with ``--accuracy`` (the run's
``accuracy.json``) the arrival accuracy against the ground truth; with ``--render``
the render's time (kept out of the stages). With ``--raw`` (the run's RAW
frames) it times decoding them with the pipeline's reader and prints the scale
targets side by side: frame store / RAW bytes, end-to-end / decode-only time,
first pass / decode-only (in CPU time, a job's cost whatever else loads a shared
machine, and in wall time), the largest job's peak RSS and (with ``--compare``)
its growth from 100 to 1000 frames, a least-squares line through the runs (``--compare``
repeated: three or more frame counts tell a slope from noise); with ``--compare`` the peak
of every stage at 100 and 1000 frames is printed too.

Example::

    shadowcam bench-report --benchmarks benchmarks/dev_ridge \\
        --frames results/dev_ridge/frames/timelapse.zarr --extrapolate 1000

Offers
------
add_parser : register the step and its options.
run : print the table.
"""

import json
from pathlib import Path

from shadowcam.evaluate.workflow_benchmark import (accuracy_line, benchmark_table, directory_bytes, growth_table, memory_growth,
                                                  read_benchmarks, read_runs, registration_line, scale_targets, time_decode)
from shadowcam.io.datasets import open_dataset
from shadowcam.io.frame_store import open_frames


def add_parser(subparsers, name):
    """Register ``bench-report`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="per-stage throughput / memory of a run, extrapolated")
    parser.add_argument("--benchmarks", required=True, help="benchmarks/<ds> directory of a finished run")
    parser.add_argument("--frames", required=True, help="the run's frame store (results/<ds>/frames/<sweep>.zarr)")
    parser.add_argument("--compare", action="append", default=[], help="benchmarks/<ds> of a shorter run (repeatable)")
    parser.add_argument("--compare-frames", type=int, action="append", default=[], help="frames of each --compare run")
    parser.add_argument("--extrapolate", type=int, default=1000, help="frames to extrapolate to")
    parser.add_argument("--cores", type=int, default=2, help="cores (jobs side by side) of the target machine")
    parser.add_argument("--photometry", default=None, help="the run's results/<ds>/outdoor/photometry.nc (estimated shifts)")
    parser.add_argument("--shake", default=None, help="sidecar JSON with the applied shake_dx_px, shake_dy_px")
    parser.add_argument("--raw", default=None, help="directory of the run's RAW frames (decode-only time, sizes)")
    parser.add_argument("--accuracy", default=None,
                        help="the run's results/<ds>/outdoor/accuracy.json (arrival accuracy against the ground truth)")
    parser.add_argument("--render", default=None,
                        help="directory of the render's benchmark file, kept apart from the run's stages (render time)")
    return parser


def run(args):
    """Print the per-stage table and the extrapolation."""
    frames = open_frames(args.frames)
    shape, n_frames, store_bytes = (frames.sizes["row"], frames.sizes["col"]), frames.sizes["time"], directory_bytes(args.frames)
    stages, shorter = read_benchmarks(args.benchmarks), read_runs(args.compare, args.compare_frames)
    before, before_frames = shorter[0] if shorter else (None, None)  # per added frame: against the nearest
    print("\n".join(benchmark_table(stages, n_frames=n_frames, shape=shape, store_bytes=store_bytes, before=before,
                                    before_frames=before_frames, extrapolate=args.extrapolate, cores=args.cores)))
    growth = memory_growth([(stages, n_frames), *shorter]) if shorter else None
    if growth:
        print("\n".join(growth_table(growth)))
    if args.raw:
        decode = time_decode(sorted(p for p in Path(args.raw).iterdir() if p.is_file()))
        for clock in ("cpu", "wall"):  # CPU: a job's cost whatever else loads a shared machine
            timed = stages if clock == "wall" else read_benchmarks(args.benchmarks, clock=clock)
            previous = read_runs(args.compare, args.compare_frames, clock=clock)[0][0] if shorter else None
            print("\n".join(scale_targets(timed, n_frames=n_frames, store_bytes=store_bytes, decode=decode,
                                          growth=growth, before=previous, before_frames=before_frames,
                                          clock=clock)))
    if args.photometry and args.shake:
        print(registration_line(open_dataset(args.photometry), json.loads(Path(args.shake).read_text()), shape=shape))
    if args.accuracy:
        print(accuracy_line(json.loads(Path(args.accuracy).read_text()), shape=shape))
    if args.render:
        for clock in ("wall", "cpu"):
            spent = sum(s for jobs in read_benchmarks(args.render, clock=clock).values() for s, _ in jobs)
            print(f"render (not a pipeline stage) {clock}: {spent:.1f} s, {spent / n_frames:.2f} s per frame "
                  f"of {shape[1]}x{shape[0]}")
