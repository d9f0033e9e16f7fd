"""``shadowcam pushbroom``: the ridge pushbroom image from the tracked edges.

Colours of the registered first frame along each frame's edge, stacked over
time (:mod:`shadowcam.cameras.pushbroom`). Writes ``results/<ds>/outdoor/pushbroom.nc``
and a PNG preview resampled to evenly spaced times (time upward).

Example::

    shadowcam pushbroom --photometry results/dev_ridge/outdoor/photometry.nc \\
        --edges results/dev_ridge/outdoor/edges.nc --out results/dev_ridge/outdoor/pushbroom.nc \\
        --png results/dev_ridge/outdoor/pushbroom.png

Offers
------
add_parser : register the step and its options.
run : assemble and write the pushbroom.
"""

from shadowcam.io.datasets import open_dataset, write_dataset
from shadowcam.io.frame_times import median_interval
from shadowcam._shared.atomic import atomic_path
from shadowcam.io.images import write_png_preview
from shadowcam.outdoor.datasets import pushbroom_dataset
from shadowcam.cameras.pushbroom import assemble_pushbroom, resample_uniform_time


def add_parser(subparsers, name):
    """Register ``pushbroom`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="ridge pushbroom from the tracked edges")
    parser.add_argument("--photometry", required=True, help="results/<ds>/outdoor/photometry.nc")
    parser.add_argument("--edges", required=True, help="results/<ds>/outdoor/edges.nc")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/outdoor/pushbroom.nc")
    parser.add_argument("--png", required=True, help="preview PNG (evenly spaced times, time upward)")
    return parser


def run(args):
    """Assemble the pushbroom and write it with its preview."""
    photometry = open_dataset(args.photometry)
    edges = open_dataset(args.edges)
    time_s = edges["time_s"].values
    image = assemble_pushbroom(photometry["reference"].values, edges["edge_row"].values)
    write_dataset(pushbroom_dataset(image, edges["edge_row"].values, time_s), args.out,
                  config={"colour": "registered first frame"}, inputs=(photometry, edges),
                  step="pushbroom")
    _, uniform = resample_uniform_time(image, time_s, step_s=median_interval(time_s))
    with atomic_path(args.png) as tmp:
        write_png_preview(tmp, uniform[::-1])
