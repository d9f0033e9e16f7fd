"""``shadowcam outdoor-accuracy``: arrival map, edges and pushbroom against outdoor ground truth.

Evaluates the combined arrival map, its two ingredients (edge crossing,
coverage crossing) and the naive per-pixel baseline (streamed from the frame
store with the same evaluation code) against both GT definitions, checks the
issue's targets for the capture's condition (``--params '{"condition":
"clean"|"nuisances"}'``, else the manifest's ``ground_truth.noise`` if it is
one of these, else ``nuisances``), and writes JSON plus a flat CSV
(:func:`shadowcam.outdoor.accuracy.outdoor_accuracy`).

Example::

    shadowcam outdoor-accuracy --manifest data_manifest/dev_ridge.yaml \\
        --frames results/dev_ridge/frames/timelapse.zarr --photometry results/dev_ridge/outdoor/photometry.nc \\
        --edges results/dev_ridge/outdoor/edges.nc --arrival results/dev_ridge/outdoor/arrival.nc \\
        --pushbroom results/dev_ridge/outdoor/pushbroom.nc \\
        --out-json results/dev_ridge/outdoor/accuracy.json --out-csv results/dev_ridge/outdoor/accuracy.csv

Offers
------
add_parser : register the step and its options.
run : evaluate and write the report.
"""

import logging

from shadowcam._shared.atomic import atomic_path
from shadowcam.cli.options import parse_params
from shadowcam.io.datasets import open_dataset
from shadowcam.io.frame_store import open_frames
from shadowcam.io.ground_truth import load_ground_truth
from shadowcam.io.manifest import load_manifest
from shadowcam.lab.accuracy import report_to_json
from shadowcam.outdoor.accuracy import accuracy_condition, outdoor_accuracy, report_to_csv

log = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register ``outdoor-accuracy`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="outdoor accuracy against ground truth, with the naive baseline")
    parser.add_argument("--manifest", required=True, help="capture description with a ground_truth entry")
    parser.add_argument("--frames", required=True, help="frame store (for the naive baseline)")
    parser.add_argument("--photometry", required=True, help="results/<ds>/outdoor/photometry.nc")
    parser.add_argument("--edges", required=True, help="results/<ds>/outdoor/edges.nc")
    parser.add_argument("--arrival", required=True, help="results/<ds>/outdoor/arrival.nc")
    parser.add_argument("--pushbroom", required=True, help="results/<ds>/outdoor/pushbroom.nc")
    parser.add_argument("--params", default="{}", help='JSON: {"condition": "clean" | "nuisances"}')
    parser.add_argument("--out-json", required=True, help="results/<ds>/outdoor/accuracy.json")
    parser.add_argument("--out-csv", required=True, help="results/<ds>/outdoor/accuracy.csv")
    return parser


def run(args):
    """Evaluate and write the outdoor accuracy report."""
    params = parse_params(args.params, allowed={"condition"})
    manifest = load_manifest(args.manifest)
    report = outdoor_accuracy(
        load_ground_truth(manifest, frame_maps=False), open_frames(args.frames), open_dataset(args.photometry),
        open_dataset(args.edges), open_dataset(args.arrival), open_dataset(args.pushbroom),
        condition=accuracy_condition(manifest, params.get("condition")))
    report["dataset"] = manifest["name"]
    with atomic_path(args.out_json) as tmp:
        tmp.write_text(report_to_json(report))
    with atomic_path(args.out_csv) as tmp:
        tmp.write_text(report_to_csv(report))
    primary = report["errors"]["combined"][report["primary_definition"]]
    log.info("combined vs %s: median %.3f p95 %.3f >5: %.2f%% coverage %.2f%% (targets %s)",
             report["primary_definition"], primary["median_abs"], primary["p95_abs"], 100 * primary["frac_over_5"],
             100 * primary["coverage"], "met" if report["all_targets_pass"] else "NOT met")
