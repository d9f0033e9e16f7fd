"""``shadowcam array-accuracy``: score a virtual camera array against its rendered ground truth.

Writes ``accuracy.json`` (per-camera coordinate RMSE and coverage, rectification,
disparity against depth, views against the reciprocal renders after one gain;
:func:`shadowcam.cameras.array.capture_accuracy`) and the Fig. 6 layout figure: the
array's views beside the reciprocal renders
(:func:`shadowcam.report.array_figure.array_figure`).

Example::

    shadowcam array-accuracy --ground-truth results/synthetic_array/array/capture/ground_truth.nc \\
        --array results/synthetic_array/array/camera_array.nc \\
        --out-json results/synthetic_array/array/accuracy.json \\
        --out-png results/synthetic_array/array/views.png

Offers
------
add_parser : register the step and its options.
run : score and draw.
"""

import json

import xarray as xr

from shadowcam._shared.atomic import atomic_path
from shadowcam.cameras.array import capture_accuracy
from shadowcam.report.array_figure import array_figure
from shadowcam.report.figures import save_png


def add_parser(subparsers, name):
    """Register ``array-accuracy`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="score a camera array against its ground truth")
    parser.add_argument("--ground-truth", required=True,
                        help="ground_truth.nc of the capture (render-array writes it beside capture.json)")
    parser.add_argument("--array", required=True, help="camera_array.nc written by camera-array")
    parser.add_argument("--out-json", required=True, help="results/<ds>/array/accuracy.json")
    parser.add_argument("--out-png", required=True, help="results/<ds>/array/views.png")
    return parser


def run(args):
    """Write the accuracy JSON and the figure."""
    with xr.open_dataset(args.ground_truth) as a, xr.open_dataset(args.array) as b:
        truth, array = a.load(), b.load()
    report = capture_accuracy(array, truth)
    with atomic_path(args.out_json) as tmp:
        tmp.write_text(json.dumps(report, indent=2, allow_nan=True))
    with atomic_path(args.out_png) as tmp:
        save_png(array_figure(array["view"].values, truth["reciprocal"].values), tmp)
