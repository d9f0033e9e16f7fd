"""``shadowcam accuracy``: accuracy of a synthetic dataset's products against its ground truth.

Writes the nested report as JSON and a CSV table (one row per quantity: value, unit, target, pass). The
noise condition that selects the shadow-time target comes from ``--params
'{"noise": "noise_free"|"raw12"}'``, else from the manifest's ``ground_truth.noise``
or ``synthetic.noise``,
else ``noise_free``.

Example::

    shadowcam accuracy --manifest data_manifest/synthetic_lab.yaml \\
        --shadow-time results/synthetic_lab/shadow_time.nc --dual-coords results/synthetic_lab/dual_coords.nc \\
        --dual-view results/synthetic_lab/dual_view.nc \\
        --out-json results/synthetic_lab/accuracy.json --out-csv results/synthetic_lab/accuracy.csv

Offers
------
add_parser : register the step and its options.
run : evaluate and write the report.
"""

import logging

from shadowcam._shared.atomic import atomic_path
from shadowcam.cli.options import parse_params
from shadowcam.io.datasets import open_dataset

log = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register ``accuracy`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="accuracy against ground truth (synthetic data)")
    parser.add_argument("--manifest", required=True, help="capture description with a ground_truth entry")
    parser.add_argument("--shadow-time", required=True, help="results/<ds>/shadow_time.nc")
    parser.add_argument("--dual-coords", default=None, help="results/<ds>/dual_coords.nc")
    parser.add_argument("--dual-view", default=None, help="results/<ds>/dual_view.nc")
    parser.add_argument("--pushbroom", default=None, help="results/<ds>/pushbroom.nc (single-sweep lab capture)")
    parser.add_argument("--reference", default=None, help="reference frame store the pushbroom was coloured with")
    parser.add_argument("--viewpoint", nargs=4, action="append", default=[],
                        metavar=("NAME", "SHADOW_TIME", "DUAL_COORDS", "DUAL_VIEW"),
                        help="a viewpoint's products (results/<ds>/viewpoints/<name>/*.nc); repeatable")
    parser.add_argument("--params", default="{}", help='JSON: {"noise": "noise_free" | "raw12"}')
    parser.add_argument("--out-json", required=True, help="results/<ds>/accuracy.json")
    parser.add_argument("--out-csv", required=True, help="results/<ds>/accuracy.csv")
    return parser


def run(args):
    """Evaluate the products against the manifest's ground truth and write the report."""
    from shadowcam.cameras.accuracy import add_camera_checks
    from shadowcam.cameras.dual_view import reference_image
    from shadowcam.io.capture_plan import capture_plan
    from shadowcam.io.frame_store import open_frames
    from shadowcam.io.ground_truth import load_ground_truth
    from shadowcam.io.manifest import load_manifest
    from shadowcam.io.provenance import file_sha256
    from shadowcam.lab.accuracy import (
        accuracy_report, add_interval_checks, noise_condition, report_to_csv, report_to_json,
    )

    params = parse_params(args.params, allowed={"noise"})
    manifest = load_manifest(args.manifest)
    gt = load_ground_truth(manifest)
    noise, source = noise_condition(manifest, params.get("noise"))
    report = accuracy_report(open_dataset(args.shadow_time), gt, noise=noise,
                             dual_coords=open_dataset(args.dual_coords) if args.dual_coords else None,
                             dual_view=open_dataset(args.dual_view) if args.dual_view else None,
                             pushbroom=open_dataset(args.pushbroom) if args.pushbroom else None,
                             reference=reference_image(open_frames(args.reference)) if args.reference else None)
    plan = capture_plan(manifest["manifest_path"])
    if not plan.is_outdoor:
        add_camera_checks(report, open_dataset(args.shadow_time), gt, camera_model=plan.camera_model,
                          description=plan.camera,
                          dual_coords=open_dataset(args.dual_coords) if args.dual_coords else None)
    add_interval_checks(report, open_dataset(args.shadow_time), gt,
                        viewpoints={name: tuple(open_dataset(p) for p in paths) for name, *paths in args.viewpoint})
    report.update(noise_source=source, dataset=manifest["name"],
                  inputs={str(p): file_sha256(p) for p in (args.shadow_time, args.dual_coords, args.dual_view, args.pushbroom) if p},
                  ground_truth_sha256=gt.attrs.get("source_sha256", ""))
    for target in report["targets"]:
        log.info("%s [%s] = %.4g (%s %.4g): %s", target["target"], target["sweep"], target["value"],
                 target["comparison"], target["threshold"], "pass" if target["pass"] else "FAIL")
    with atomic_path(args.out_json) as tmp:
        tmp.write_text(report_to_json(report))
    with atomic_path(args.out_csv) as tmp:
        tmp.write_text(report_to_csv(report))
    log.info("wrote %s, %s", args.out_json, args.out_csv)
