"""``shadowcam dual-view``: resample the camera colours into the dual grid.

Reads ``dual_coords.nc`` and ``shadow_time.nc`` (for the mean lit image, or
``--reference`` a reference frame store) and writes ``dual_view.nc``, a
linear float EXR and an 8-bit sRGB PNG preview (holes in grey).

Offers
------
add_parser : register the step and its options.
run : resample and write the outputs.
"""

import json
import logging
import time


from shadowcam.cli.options import parse_params
from shadowcam.cameras.dual_view import DUAL_VIEW_METHODS

log = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register ``dual-view`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="resample camera colours into the dual view",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--dual-coords", required=True, help="results/<ds>/dual_coords.nc")
    parser.add_argument("--shadow-time", required=True, help="results/<ds>/shadow_time.nc (lit_image)")
    parser.add_argument("--reference", default=None, help="reference frame store (results/<ds>/frames/reference.zarr)")
    parser.add_argument("--method", default="mesh", choices=sorted(DUAL_VIEW_METHODS))
    parser.add_argument("--params", default="{}",
                        help="JSON method options: mesh: max_edge; idw: k, radius, power")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/dual_view.nc")
    parser.add_argument("--exr", default=None, help="linear float EXR of the dual view")
    parser.add_argument("--png", default=None, help="8-bit sRGB preview PNG")
    return parser


def run(args):
    """Resample the camera colours into the dual grid and write the outputs."""
    import xarray as xr

    from shadowcam.cameras.dual_view import camera_colours, dual_view_dataset, resample_dual_view
    from shadowcam.io.images import write_exr, write_netcdf, write_png_preview
    from shadowcam.io.provenance import attach_provenance, file_sha256

    params = parse_params(args.params)
    with xr.open_dataset(args.dual_coords, engine="h5netcdf") as ds:
        coords = ds.load()
    with xr.open_dataset(args.shadow_time, engine="h5netcdf") as ds:
        shadow_time = ds[["lit_image"]].load() if "lit_image" in ds else ds.load()
    checksums = {}
    for path, ds in ((args.dual_coords, coords), (args.shadow_time, shadow_time)):
        checksums.update(json.loads(ds.attrs.get("input_checksums", "{}")))
        checksums[str(path)] = file_sha256(path)
    reference = None
    if args.reference:
        from shadowcam.io.frame_store import open_frames

        frames = open_frames(args.reference)
        image = frames["image"]
        if "time" in image.dims:
            image = image.mean("time")
        reference = image.transpose("row", "col", "channel").values
        checksums.update(json.loads(frames.attrs.get("input_checksums", "{}")))
    colours = camera_colours(shadow_time, reference=reference)
    shape = (int(coords.attrs["dual_height"]), int(coords.attrs["dual_width"]))
    u = coords["u"].transpose("row", "col").values
    v = coords["v"].transpose("row", "col").values
    if u.shape != colours.shape[:2]:
        raise ValueError(f"--dual-coords grid {u.shape} differs from the camera colours {colours.shape[:2]}")
    start = time.perf_counter()
    try:
        image, coverage = resample_dual_view(colours, u, v, shape=shape, valid=coords["valid"].values,
                                             method=args.method, **params)
    except TypeError as exc:
        raise ValueError(f"--params: {exc}") from None
    seconds = time.perf_counter() - start
    log.info("%s resampling: %d camera pixels in %.3f s (%.2f M px/s), coverage %.1f%% of %dx%d",
             args.method, u.size, seconds, u.size / seconds / 1e6, 100 * coverage.mean(), *shape)
    channels = [str(c) for c in shadow_time["channel"].values] if "channel" in shadow_time.coords else ("R", "G", "B")
    dataset = dual_view_dataset(image, coverage, method=args.method, params=params, channels=channels)
    dataset.attrs.update(colour_source="reference" if reference is not None else "mean lit_image of u, v",
                         dual_coords_model=coords.attrs.get("model", ""),
                         resampling_seconds=seconds)
    dataset = attach_provenance(dataset, config={"method": args.method, **params,
                                                 "reference": bool(args.reference)},
                                input_checksums=checksums, step="dual-view")
    write_netcdf(dataset, args.out)
    if args.exr:
        write_exr(args.exr, image)
    if args.png:
        write_png_preview(args.png, image)
    log.info("wrote %s", ", ".join(p for p in (args.out, args.exr, args.png) if p))
