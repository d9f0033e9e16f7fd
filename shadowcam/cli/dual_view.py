"""``shadowcam dual-view``: resample the camera colours into the dual grid.

Reads ``dual_coords.nc`` and ``shadow_time.nc`` (for the mean lit image, or
``--reference`` a reference frame store) and writes ``dual_view.nc``, a
linear float EXR and an 8-bit sRGB PNG preview (holes in grey)
(:func:`shadowcam.cameras.dual_view.dual_view_from_coords`).

Example::

    shadowcam dual-view --dual-coords results/dev_spheres/dual_coords.nc \\
        --shadow-time results/dev_spheres/shadow_time.nc --out results/dev_spheres/dual_view.nc \\
        --png results/dev_spheres/dual_view.png

Offers
------
add_parser : register the step and its options.
run : resample and write the outputs.
"""

import logging

from shadowcam.cameras.dual_view import DUAL_VIEW_METHODS, dual_view_from_coords
from shadowcam.cameras.intrinsics import INTRINSICS_OPTIONS, coords_to_intrinsics
from shadowcam.cli.options import parse_params
from shadowcam.io.datasets import open_dataset, write_dataset
from shadowcam.io.frame_store import open_frames
from shadowcam.io.images import write_exr, write_png_preview
from shadowcam.io.provenance import file_sha256

log = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register ``dual-view`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="resample camera colours into the dual view")
    parser.add_argument("--dual-coords", required=True, help="results/<ds>/dual_coords.nc")
    parser.add_argument("--shadow-time", required=True, help="results/<ds>/shadow_time.nc (lit_image)")
    parser.add_argument("--reference", default=None, help="reference frame store (results/<ds>/frames/reference.zarr)")
    parser.add_argument("--method", default="mesh", choices=sorted(DUAL_VIEW_METHODS),
                        help="resampling onto the dual grid (default mesh)")
    parser.add_argument("--params", default="{}",
                        help="JSON method options: mesh: max_edge, smooth_tol, density, three_corners; idw: k, radius, power")
    parser.add_argument("--intrinsics", default="{}",
                        help="JSON virtual intrinsics of the output: skew_deg, aspect, size [height, width]")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/dual_view.nc")
    parser.add_argument("--exr", default=None, help="linear float EXR of the dual view")
    parser.add_argument("--png", default=None, help="8-bit sRGB preview PNG")
    return parser


def run(args):
    """Resample the camera colours into the dual grid and write the outputs."""
    params = parse_params(args.params)
    intrinsics = parse_params(args.intrinsics, allowed=set(INTRINSICS_OPTIONS))
    coords, shadow_time = open_dataset(args.dual_coords), open_dataset(args.shadow_time)
    if intrinsics:
        coords = coords_to_intrinsics(coords, **intrinsics)
    reference = open_frames(args.reference) if args.reference else None
    dataset = dual_view_from_coords(coords, shadow_time, reference=reference, method=args.method, **params)
    inputs = (coords, shadow_time) + ((reference,) if reference is not None else ())
    checksums = {str(path): file_sha256(path) for path in (args.dual_coords, args.shadow_time)}
    write_dataset(dataset, args.out, config={"method": args.method, **params, **({"intrinsics": intrinsics} if intrinsics else {}), "reference": bool(args.reference)},
                  inputs=inputs, checksums=checksums, step="dual-view")
    image = dataset["dual_view"].values
    if args.exr:
        write_exr(args.exr, image)
    if args.png:
        write_png_preview(args.png, image)
    log.info("wrote %s", ", ".join(p for p in (args.out, args.exr, args.png) if p))
