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

from shadowcam.io.frame_times import time_to_frame
from shadowcam.outdoor.arrival import arrival_from_edges, combine_arrivals
from shadowcam.cli.options import parse_params
from shadowcam.io.datasets import open_dataset, write_dataset
from shadowcam.io.frame_times import median_interval
from shadowcam.outdoor.datasets import arrival_dataset


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
    time_s = edges["time_s"].values
    interval = median_interval(time_s)
    sky = photometry["sky"].values.astype(bool)
    lit = photometry["lit_at_start"].values.astype(bool)
    edge_s = arrival_from_edges(edges["edge_row"].values, time_s, eligible=lit & ~sky)
    coverage_s = edges["coverage_arrival_s"].values
    arrival, reason = combine_arrivals(edge_s, coverage_s, sky=sky, lit_at_start=lit,
                                       tolerance_s=params.get("tolerance_intervals", 1.5) * interval)
    dataset = arrival_dataset(arrival, time_to_frame(arrival, time_s, outside="clamp"), reason, edge_arrival_s=edge_s,
                              coverage_arrival_s=coverage_s, interval_s=interval)
    write_dataset(dataset, args.out, config=params, inputs=(photometry, edges), step="arrival")
