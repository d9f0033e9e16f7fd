"""``shadowcam outdoor-figures``: report figures of an outdoor time-lapse (paper Fig. 18).

Keyframes with the tracked edge, the edge over time, the arrival map (beside its
ground truth and error when the ``--manifest`` has ground truth), the
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
from shadowcam.io.ground_truth import load_ground_truth
from shadowcam.io.manifest import load_manifest
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
    parser.add_argument("--manifest", default=None,
                        help="capture description; with a ground_truth entry the arrival map is drawn beside it")
    parser.add_argument("--outdir", required=True, help="output directory of the PNG figures (created)")
    return parser


def run(args):
    """Draw the outdoor figures into ``args.outdir``."""
    report = json.loads(Path(args.accuracy).read_text()) if args.accuracy else None
    truth = None
    if args.manifest:
        manifest = load_manifest(args.manifest)
        truth = load_ground_truth(manifest, frame_maps=False) if manifest.get("ground_truth") or manifest.get("synthetic") else None
    write_outdoor_figures(args.outdir, frames=open_frames(args.frames), photometry=open_dataset(args.photometry),
                          edges=open_dataset(args.edges), arrival=open_dataset(args.arrival),
                          pushbroom=open_dataset(args.pushbroom), report=report, truth=truth)
