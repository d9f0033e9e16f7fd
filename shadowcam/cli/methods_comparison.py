"""``shadowcam methods-comparison``: speed against error of every method on one dataset.

Runs every shadow-time method on the dataset's decoded sweeps and every
dual-view resampling method on its dual coordinates, measures wall time,
throughput, peak memory and error against the ground truth
(:func:`shadowcam.evaluate.methods_comparison.compare_methods`), and writes the
table (netCDF and CSV) and the speed-versus-error chart with the Pareto front.

Example::

    shadowcam methods-comparison --manifest data_manifest/synthetic_lab.yaml \\
        --frames results/synthetic_lab/frames/u.zarr results/synthetic_lab/frames/v.zarr --sweeps u v \\
        --shadow-time results/synthetic_lab/shadow_time.nc --dual-coords results/synthetic_lab/dual_coords.nc \\
        --out results/synthetic_lab/methods/methods.nc --csv results/synthetic_lab/methods/methods.csv \\
        --figure results/synthetic_lab/methods/speed_vs_error.png

Offers
------
add_parser : register the step and its options.
run : measure and write the comparison.
write_comparison : write a methods dataset, its CSV and its chart.
"""

import logging

from shadowcam._shared.atomic import atomic_path
from shadowcam.cli.options import parse_params
from shadowcam.io.datasets import open_dataset, write_dataset

log = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register ``methods-comparison`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="speed against error of every method")
    parser.add_argument("--manifest", required=True, help="capture description with ground truth")
    parser.add_argument("--frames", nargs="+", required=True, help="frame stores of the scene sweeps")
    parser.add_argument("--sweeps", nargs="+", required=True, help="their sweep names (u v)")
    parser.add_argument("--shadow-time", required=True, help="results/<ds>/shadow_time.nc (colours)")
    parser.add_argument("--dual-coords", required=True, help="results/<ds>/dual_coords.nc")
    parser.add_argument("--reference", default=None, help="reference frame store, if any")
    parser.add_argument("--params", default="{}", help="JSON: half_window")
    parser.add_argument("--out", required=True, help="results/<ds>/methods/methods.nc")
    parser.add_argument("--csv", required=True, help="results/<ds>/methods/methods.csv")
    parser.add_argument("--figure", required=True, help="results/<ds>/methods/speed_vs_error.png")
    return parser


def run(args):
    """Measure every method against the ground truth and write table and chart."""
    from shadowcam.evaluate.methods_comparison import compare_methods
    from shadowcam.io.frame_store import open_frames
    from shadowcam.io.ground_truth import load_ground_truth
    from shadowcam.io.manifest import load_manifest

    if len(args.frames) != len(args.sweeps):
        raise ValueError(f"--frames has {len(args.frames)} stores but --sweeps names {len(args.sweeps)}")
    params = parse_params(args.params, allowed={"half_window"})
    manifest = load_manifest(args.manifest)
    dataset = compare_methods(
        load_ground_truth(manifest), {sweep: open_frames(path) for path, sweep in zip(args.frames, args.sweeps)},
        open_dataset(args.shadow_time), open_dataset(args.dual_coords),
        reference=open_frames(args.reference) if args.reference else None, half_window=params.get("half_window", 4))
    write_comparison(dataset, args, name=manifest["name"], config=params, step="methods-comparison")


def write_comparison(dataset, args, *, name, config, step):
    """Write `dataset` to ``args.out`` (with provenance), its table to ``args.csv`` and its
    speed-versus-error chart to ``args.figure``."""
    from shadowcam.evaluate.methods_comparison import speed_error_figure

    dataset = write_dataset(dataset, args.out, config={"dataset": name, **config}, step=step)
    with atomic_path(args.csv) as tmp:
        dataset.to_dataframe().to_csv(tmp)
    figure = speed_error_figure(dataset, title=f"{name}: speed against error")
    with atomic_path(args.figure) as tmp:
        figure.savefig(tmp, format="png", dpi=110)
    log.info("wrote %s, %s, %s", args.out, args.csv, args.figure)
