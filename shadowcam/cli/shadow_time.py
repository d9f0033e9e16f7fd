"""``shadowcam shadow-time``: per-pixel shadow times of a capture's sweeps.

Streams each sweep's frame store (one time chunk at a time) through the
shadow-time method and writes ``results/<ds>/shadow_time.nc``
(:func:`shadowcam.lab.shadow_time.shadow_time_of_stores`). With
``--partials SWEEP FILE...`` (per sweep) the dips were tracked per time chunk
by ``shadowcam shadow-time-chunk`` jobs: their partials are merged instead
(the result is the same bit for bit). Stores of demosaiced RAW (``cfa_pattern``) are
read once more for each pixel's own mosaic site in its dip window: ``edge_fit`` times the
pixel from it where its noise allows (:mod:`shadowcam.lab.site_signal`).

Example::

    shadowcam shadow-time --frames results/dev_spheres/frames/u.zarr results/dev_spheres/frames/v.zarr \\
        --sweeps u v --method edge_fit --out results/dev_spheres/shadow_time.nc

Offers
------
add_parser : register the step and its options.
run : compute and write the dataset.
"""

from shadowcam._shared.coverage import MIN_COVERAGE
from shadowcam.cli.options import parse_params
from shadowcam.io.capture_plan import footprint_variance
from shadowcam.io.datasets import write_dataset
from shadowcam.io.manifest import load_manifest
from shadowcam.io.frame_store import open_frames
from shadowcam.lab.shadow_time import SHADOW_TIME_METHODS, shadow_time_of_stores


def add_parser(subparsers, name):
    """Register ``shadow-time`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="per-pixel shadow times of the sweeps")
    parser.add_argument("--frames", nargs="+", required=True, help="frame stores, one per sweep")
    parser.add_argument("--sweeps", nargs="+", required=True, help="sweep names, same order")
    parser.add_argument("--method", default="edge_fit", choices=sorted(SHADOW_TIME_METHODS),
                        help="how each pixel's sub-frame shadow time is found (default edge_fit)")
    parser.add_argument("--params", default="{}", help="JSON: half_window, method_params, classify_params, min_coverage")
    parser.add_argument("--manifest", help="capture description: its sensor.footprint_variance_px2 (if any) "
                        "is edge_fit's footprint_variance unless --params sets one")
    parser.add_argument("--partials", nargs="+", action="append", metavar="SWEEP FILE",
                        help="a sweep name and the partial files of all its time chunks (repeat per sweep); "
                             "default: stream the frames")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/shadow_time.nc")
    return parser


def run(args):
    """Compute the shadow times of every sweep and write one dataset."""
    if len(args.frames) != len(args.sweeps):
        raise ValueError(f"--frames has {len(args.frames)} stores but --sweeps names {len(args.sweeps)}")
    params = parse_params(args.params, allowed={"half_window", "method_params", "classify_params",
                                                     "min_coverage"})
    partials = {group[0]: group[1:] for group in args.partials or []}
    if args.partials and (set(partials) != set(args.sweeps) or not all(partials.values())):
        raise ValueError(f"--partials must name each of the sweeps {sorted(args.sweeps)} once, each with "
                         f"its partial files; got {sorted(partials)}")
    stores = {sweep: open_frames(path) for path, sweep in zip(args.frames, args.sweeps)}
    method_params = dict(params.get("method_params") or {})
    if args.manifest and args.method == "edge_fit" and "footprint_variance" not in method_params:
        declared = footprint_variance(load_manifest(args.manifest))
        method_params.update({} if declared is None else {"footprint_variance": declared})
    dataset = shadow_time_of_stores(stores, method=args.method, partials=partials,
                                    half_window=params.get("half_window", 4), method_params=method_params,
                                    classify_params=params.get("classify_params"),
                                    min_coverage=params.get("min_coverage", MIN_COVERAGE))
    write_dataset(dataset, args.out, config={"method": args.method, **params, "method_params": method_params},
                  inputs=tuple(stores.values()),
                  step="shadow-time")
