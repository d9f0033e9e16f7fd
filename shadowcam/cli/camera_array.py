"""``shadowcam camera-array``: the virtual camera array of a grid-mask capture.

Each pixel's dips of the two experiments are assigned to the wires; crossing (i, j)
becomes a camera whose pixel of a scene point is (time of horizontal wire i, time of
vertical wire j), coloured from the image lit from that crossing
(:func:`shadowcam.cameras.array.camera_array_of_capture`). Writes the dataset over
(camera_row, camera_col, v, u, channel).

Example::

    shadowcam camera-array --capture results/synthetic_array/array/capture.nc \\
        --out results/synthetic_array/array/camera_array.nc

Offers
------
add_parser : register the step and its options.
run : compute and write the array.
"""

import xarray as xr

from shadowcam.cameras.array import camera_array_of_capture
from shadowcam.io.datasets import write_dataset


def add_parser(subparsers, name):
    """Register ``camera-array`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="the virtual camera array of a grid-mask capture")
    parser.add_argument("--capture", required=True, help="capture.nc written by render-array")
    parser.add_argument("--tolerance", type=float, default=0.5,
                        help="frames by which a pixel's gaps between wire dips may differ (default 0.5)")
    parser.add_argument("--method", default="mesh", help="dual-view resampler: mesh or idw (default mesh)")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/array/camera_array.nc")
    return parser


def run(args):
    """Write the camera-array dataset."""
    with xr.open_dataset(args.capture) as opened:
        capture = opened.load()
    array = camera_array_of_capture(capture, tolerance=args.tolerance, method=args.method)
    write_dataset(array, args.out, config={"tolerance": args.tolerance, "method": args.method},
                  inputs=(capture,), step="camera-array")
