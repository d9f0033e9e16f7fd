"""``shadowcam outdoor-figures``: report figures of an outdoor time-lapse (paper Fig. 18).

Keyframes with the tracked edge, the edge over time, the arrival map, the
pushbroom beside the real view (sky masked), and with an accuracy report the
error histogram and an HTML table of the figures against the targets
(:func:`shadowcam.report.outdoor_report.write_outdoor_figures`).

Example::

    shadowcam outdoor-figures --frames results/dev_ridge/frames/timelapse.zarr \\
        --photometry results/dev_ridge/outdoor/photometry.nc --edges results/dev_ridge/outdoor/edges.nc \\
        --arrival results/dev_ridge/outdoor/arrival.nc --pushbroom results/dev_ridge/outdoor/pushbroom.nc \\
        --outdir results/dev_ridge/outdoor/figures

Offers
------
add_parser : register the step and its options.
run : draw and write the figures.
"""

import json
from pathlib import Path

from shadowcam.io.datasets import open_dataset
from shadowcam.io.frame_store import open_frames
from shadowcam.report.outdoor_report import write_outdoor_figures


def add_parser(subparsers, name):
    """Register ``outdoor-figures`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="report figures of an outdoor time-lapse")
    parser.add_argument("--frames", required=True, help="frame store of the time-lapse sweep")
    parser.add_argument("--photometry", required=True, help="results/<ds>/outdoor/photometry.nc")
    parser.add_argument("--edges", required=True, help="results/<ds>/outdoor/edges.nc")
    parser.add_argument("--arrival", required=True, help="results/<ds>/outdoor/arrival.nc")
    parser.add_argument("--pushbroom", required=True, help="results/<ds>/outdoor/pushbroom.nc")
    parser.add_argument("--accuracy", default=None, help="outdoor accuracy JSON (optional)")
    parser.add_argument("--outdir", required=True, help="output directory of the PNG figures (created)")
    return parser


def run(args):
    """Draw the outdoor figures into ``args.outdir``."""
    report = json.loads(Path(args.accuracy).read_text()) if args.accuracy else None
    write_outdoor_figures(args.outdir, frames=open_frames(args.frames), photometry=open_dataset(args.photometry),
                          edges=open_dataset(args.edges), arrival=open_dataset(args.arrival),
                          pushbroom=open_dataset(args.pushbroom), report=report)
