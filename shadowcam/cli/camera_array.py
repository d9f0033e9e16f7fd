"""``shadowcam camera-array``: the virtual camera array of a grid-mask capture.

Reads a camera-array manifest (a user's ``data_manifest/<ds>.yaml`` or the ``capture.json``
that render-array writes): each pixel's dips of the two experiments are assigned to the
wires; crossing (i, j) becomes a camera whose pixel of a scene point is (time of
horizontal wire i, time of vertical wire j), coloured from the image lit from that
crossing (:func:`shadowcam.cameras.array_files.camera_array_of_plan`). Writes the dataset
over (camera_row, camera_col, v, u, channel).

Example::

    shadowcam camera-array --manifest results/synthetic_array/array/capture/capture.json \\
        --out results/synthetic_array/array/camera_array.nc

Offers
------
add_parser : register the step and its options.
run : compute and write the array.
"""

from shadowcam.cameras.array_files import camera_array_of_plan
from shadowcam.io.capture_plan import capture_plan
from shadowcam.io.datasets import write_dataset


def add_parser(subparsers, name):
    """Register ``camera-array`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="the virtual camera array of a grid-mask capture")
    parser.add_argument("--manifest", required=True,
                        help="camera-array manifest: data_manifest/<ds>.yaml or a rendered capture.json")
    parser.add_argument("--tolerance", type=float, default=0.5,
                        help="frames by which a pixel's gaps between wire dips may differ (default 0.5)")
    parser.add_argument("--method", default="mesh", help="dual-view resampler: mesh or idw (default mesh)")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/array/camera_array.nc")
    return parser


def run(args):
    """Write the camera-array dataset."""
    plan = capture_plan(args.manifest)
    array = camera_array_of_plan(plan, tolerance=args.tolerance, method=args.method)
    write_dataset(array, args.out, config={"tolerance": args.tolerance, "method": args.method},
                  step="camera-array")
