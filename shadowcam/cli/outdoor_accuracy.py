"""``shadowcam outdoor-accuracy``: arrival map, edges and pushbroom against outdoor ground truth.

Evaluates the combined arrival map, its two ingredients (edge crossing,
coverage crossing) and the naive per-pixel baseline (streamed from the frame
store with the same evaluation code) against both GT definitions, checks the
issue's targets for the capture's condition (``--params '{"condition":
"clean"|"nuisances"}'``, else the manifest's ``ground_truth.noise`` if it is
one of these, else ``nuisances``), and writes JSON plus a flat CSV.

Offers
------
add_parser : register the step and its options.
run : evaluate and write the report.
"""

import logging

import numpy as np

from shadowcam.lab.accuracy import report_to_csv, report_to_json
from shadowcam.cli.options import parse_params
from shadowcam.cli.outdoor_io import iter_frames, open_dataset
from shadowcam.io.frame_store import open_frames
from shadowcam.io.frame_times import median_interval
from shadowcam.io.ground_truth import load_ground_truth
from shadowcam.io.images import atomic_path
from shadowcam.io.manifest import load_manifest
from shadowcam.outdoor.accuracy import (
    NaiveBaseline, TARGETS, edge_errors, edges_to_truth_camera, evaluate_arrivals, false_arrivals,
    map_to_truth_camera, registration_errors,
)

log = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register ``outdoor-accuracy`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="outdoor accuracy against ground truth, with the naive baseline",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--manifest", required=True, help="capture description with a ground_truth entry")
    parser.add_argument("--frames", required=True, help="frame store (for the naive baseline)")
    parser.add_argument("--photometry", required=True, help="results/<ds>/outdoor/photometry.nc")
    parser.add_argument("--edges", required=True, help="results/<ds>/outdoor/edges.nc")
    parser.add_argument("--arrival", required=True, help="results/<ds>/outdoor/arrival.nc")
    parser.add_argument("--pushbroom", required=True, help="results/<ds>/outdoor/pushbroom.nc")
    parser.add_argument("--params", default="{}", help='JSON: {"condition": "clean" | "nuisances"}')
    parser.add_argument("--out-json", required=True)
    parser.add_argument("--out-csv", required=True)
    return parser


def _condition(params, manifest):
    if "condition" in params:
        return params["condition"]
    noise = manifest.get("ground_truth", {}).get("noise")
    return noise if noise in TARGETS else "nuisances"


def run(args):
    """Evaluate and write the outdoor accuracy report."""
    params = parse_params(args.params, allowed={"condition"})
    manifest = load_manifest(args.manifest)
    truth = load_ground_truth(manifest)
    frames = open_frames(args.frames)
    photometry, edges = open_dataset(args.photometry), open_dataset(args.edges)
    arrival, pushbroom = open_dataset(args.arrival), open_dataset(args.pushbroom)
    time_s = frames["time_s"].values
    if "times_s" in truth and truth["times_s"].size == time_s.size:
        log.info("frame times vs GT: max |difference| %.3g s", float(np.max(np.abs(truth["times_s"].values - time_s))))
    baseline = NaiveBaseline((frames.sizes["row"], frames.sizes["col"]))
    for frame, t in zip(iter_frames(frames), time_s):
        baseline.update(frame, t)
    # our maps are in the first frame's pixel grid; synthetic GT is in the unshaken camera
    shift = {"shift_row": 0.0, "shift_col": 0.0}
    if "shake_dy_px" in truth and truth["shake_dy_px"].size == time_s.size:
        shift = {"shift_row": float(truth["shake_dy_px"].values[0]),
                 "shift_col": float(truth["shake_dx_px"].values[0])}
        log.info("first frame's shake (GT): row %+.3f px, col %+.3f px; maps resampled into the GT camera",
                 shift["shift_row"], shift["shift_col"])
    estimates = {
        name: map_to_truth_camera(arrival[variable].values, **shift)
        for name, variable in (("combined", "arrival_time_s"), ("edge_crossing", "edge_arrival_s"),
                               ("coverage_crossing", "coverage_arrival_s"))
    }
    # the baseline works on the frames as delivered (no registration)
    estimates["naive_baseline"] = baseline.arrival_s
    interval = median_interval(time_s)
    report = evaluate_arrivals(estimates, truth, interval_s=interval, condition=_condition(params, manifest))
    report["false_arrivals"] = {name: false_arrivals(est, truth) for name, est in estimates.items()}
    report["first_frame_shake_px"] = shift
    if "pb_edge_y" in truth and truth["pb_edge_y"].shape == edges["edge_row"].shape:
        unambiguous = truth["pb_n_transitions"].values == 1 if "pb_n_transitions" in truth else None
        report["edge_row"] = edge_errors(edges_to_truth_camera(edges["edge_row"].values, **shift),
                                         truth["pb_edge_y"].values, unambiguous=unambiguous)
    if "pb_front" in truth and truth["pb_front"].shape == pushbroom["pushbroom"].shape:
        ours, gt = pushbroom["pushbroom"].values, truth["pb_front"].values
        both = np.isfinite(ours).all(-1) & np.isfinite(gt).all(-1) & (gt.sum(-1) > 0)
        scale = float(np.median(ours[both].sum(-1) / gt[both].sum(-1))) if both.any() else float("nan")
        rel = np.abs(ours[both] / scale - gt[both]).sum(-1) / gt[both].sum(-1)
        report["pushbroom"] = {"n": int(both.sum()), "scale_to_gt": scale,
                               "median_rel_error": float(np.median(rel)) if rel.size else float("nan"),
                               "p95_rel_error": float(np.percentile(rel, 95)) if rel.size else float("nan")}
    if "shake_dy_px" in truth and truth["shake_dy_px"].size == time_s.size:
        report["registration"] = registration_errors(photometry["shift_row"].values, photometry["shift_col"].values,
                                                     shake_dy=truth["shake_dy_px"].values,
                                                     shake_dx=truth["shake_dx_px"].values)
    report["dataset"] = manifest["name"]
    with atomic_path(args.out_json) as tmp:
        tmp.write_text(report_to_json(report))
    with atomic_path(args.out_csv) as tmp:
        tmp.write_text(report_to_csv(report))
    primary = report["errors"]["combined"][report["primary_definition"]]
    log.info("combined vs %s: median %.3f p95 %.3f >5: %.2f%% coverage %.2f%% (targets %s)",
             report["primary_definition"], primary["median_abs"], primary["p95_abs"], 100 * primary["frac_over_5"],
             100 * primary["coverage"], "met" if report["all_targets_pass"] else "NOT met")
