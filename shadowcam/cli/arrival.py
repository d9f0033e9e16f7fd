"""``shadowcam arrival``: per-pixel shadow-arrival time map (seconds, sub-frame).

Edge crossing of the tracked edges, checked against the pixel's own coverage
crossing (:mod:`shadowcam.outdoor.arrival`). Writes ``results/<ds>/outdoor/arrival.nc``.

Example::

    shadowcam arrival --photometry results/dev_ridge/outdoor/photometry.nc \\
        --edges results/dev_ridge/outdoor/edges.nc --out results/dev_ridge/outdoor/arrival.nc

Offers
------
add_parser : register the step and its options.
run : compute and write the arrival map.
"""

from shadowcam.cli.options import parse_params
from shadowcam.io.datasets import open_dataset, write_dataset
from shadowcam.outdoor.arrival import arrival_map


def add_parser(subparsers, name):
    """Register ``arrival`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="per-pixel shadow-arrival time map from the tracked edges")
    parser.add_argument("--photometry", required=True, help="results/<ds>/outdoor/photometry.nc")
    parser.add_argument("--edges", required=True, help="results/<ds>/outdoor/edges.nc")
    parser.add_argument("--params", default="{}",
                        help="JSON: tolerance_intervals (edge vs coverage agreement, median intervals; default 1.5)")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/outdoor/arrival.nc")
    return parser


def run(args):
    """Compute the arrival map and write it."""
    params = parse_params(args.params, allowed={"tolerance_intervals"})
    photometry = open_dataset(args.photometry)
    edges = open_dataset(args.edges)
    dataset = arrival_map(photometry, edges, tolerance_intervals=params.get("tolerance_intervals", 1.5))
    write_dataset(dataset, args.out, config=params, inputs=(photometry, edges), step="arrival")
