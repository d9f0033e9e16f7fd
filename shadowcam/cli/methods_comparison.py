"""``shadowcam methods-comparison``: speed against error of every method on one dataset.

Runs every shadow-time method on the dataset's decoded sweeps and every
dual-view resampling method on its dual coordinates, measures wall time,
throughput, peak memory and error against the ground truth, and writes the
table (netCDF and CSV) and the speed-versus-error chart with the Pareto front.

Offers
------
add_parser : register the step and its options.
run : measure and write the comparison.
"""

import logging

from shadowcam.cli.options import parse_params

log = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register ``methods-comparison`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="speed against error of every method",
                                   description=__doc__.split("\n\n")[0].strip("`"))
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


def _load(path):
    import xarray as xr

    with xr.open_dataset(path, engine="h5netcdf") as ds:
        return ds.load()


def run(args):
    """Measure every method against the ground truth and write table and chart."""
    from shadowcam.cameras.dual_view import camera_colours
    from shadowcam.io.frame_store import iter_frame_chunks, open_frames
    from shadowcam.io.ground_truth import load_ground_truth
    from shadowcam._shared.atomic import atomic_path
    from shadowcam.io.datasets import write_netcdf
    from shadowcam.io.manifest import load_manifest
    from shadowcam.evaluate.methods_comparison import (
        compare_dual_view_methods, compare_shadow_time_methods, methods_dataset, speed_error_figure,
    )
    from shadowcam.io.provenance import attach_provenance

    if len(args.frames) != len(args.sweeps):
        raise ValueError(f"--frames has {len(args.frames)} stores but --sweeps names {len(args.sweeps)}")
    params = parse_params(args.params, allowed={"half_window"})
    manifest = load_manifest(args.manifest)
    gt = load_ground_truth(manifest)
    lit = gt["lit"].transpose("row", "col").values.astype(bool)
    sweeps, cfa = {}, None
    for path, sweep in zip(args.frames, args.sweeps):
        if f"t_{sweep}" not in gt:
            raise ValueError(f"--sweeps: the ground truth has no t_{sweep}; compare scene sweeps only")
        frames = open_frames(path)
        cfa = frames.attrs.get("cfa_pattern") or None
        # in memory, so that the tracker is timed and not the frame store's codec
        loaded = [block for _, block in iter_frame_chunks(frames)]

        def blocks(loaded=loaded):
            return iter(loaded)

        sweeps[sweep] = (blocks, gt[f"t_{sweep}"].transpose("row", "col").values, lit)
    rows = compare_shadow_time_methods(sweeps, half_window=params.get("half_window", 4), cfa_pattern=cfa)

    coords = _load(args.dual_coords)
    reference = None
    if args.reference:
        image = open_frames(args.reference)["image"]
        image = image.mean("time") if "time" in image.dims else image
        reference = image.transpose("row", "col", "channel").values
    colours = camera_colours(_load(args.shadow_time), reference=reference)
    rows += compare_dual_view_methods(
        colours, coords["u"].transpose("row", "col").values, coords["v"].transpose("row", "col").values,
        shape=(int(coords.attrs["dual_height"]), int(coords.attrs["dual_width"])),
        valid=coords["valid"].values, reciprocal=gt["reciprocal"].transpose("v", "u", "channel").values,
        dual_cam_visible=gt["dual_cam_visible"].transpose("v", "u").values,
    )
    dataset = methods_dataset(rows)
    for row, on_front in zip(rows, dataset["pareto"].values):
        log.info("%-12s %-38s %9.3g /s  p95 %.4f  coverage %.3f  %s", row["stage"], row["method"],
                 row["throughput"], row["p95"], row["coverage"], "Pareto" if on_front else "")
    dataset = attach_provenance(dataset, config={"dataset": manifest["name"], **params},
                                input_checksums={}, step="methods-comparison")
    write_netcdf(dataset, args.out)
    with atomic_path(args.csv) as tmp:
        dataset.to_dataframe().to_csv(tmp)
    figure = speed_error_figure(dataset, title=f"{manifest['name']}: speed against error")
    with atomic_path(args.figure) as tmp:
        figure.savefig(tmp, format="png", dpi=110)
    log.info("wrote %s, %s, %s", args.out, args.csv, args.figure)
