"""``shadowcam report-figures``: the PNG figures (and accuracy table) of the HTML report.

Writes into ``--outdir`` (:func:`shadowcam.report.dataset_report.write_report_figures`):
``primal.png`` (the ``--reference`` frame, else the lit image of the first sweep),
``shadow_time_<sweep>.png``, ``dual_view.png`` (next to the ground-truth reciprocal view
when the capture has ground truth), ``error_histogram.png`` (ground truth only) and
``accuracy.html`` (the ``--accuracy`` CSV as a table, when given).

Example::

    shadowcam report-figures --manifest data_manifest/dev_spheres.yaml \\
        --shadow-time results/dev_spheres/shadow_time.nc --dual-view results/dev_spheres/dual_view.nc \\
        --outdir results/dev_spheres/figures

Offers ``add_parser(subparsers, name)`` and ``run(args)``.
"""

import logging
from pathlib import Path

from shadowcam.io.capture_plan import capture_plan
from shadowcam.io.datasets import open_dataset
from shadowcam.io.manifest import load_manifest
from shadowcam.report.dataset_report import write_report_figures

LOG = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register the step `name` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="write the report figures of one dataset")
    parser.add_argument("--manifest", required=True,
                        help="capture description (data_manifest/X.yaml or capture.json)")
    parser.add_argument("--shadow-time", required=True, help="shadow_time.nc")
    parser.add_argument("--dual-view", required=True, help="dual_view.nc")
    parser.add_argument("--dual-coords", help="dual_coords.nc (grid and model choice of the dual view), optional")
    parser.add_argument("--reference", help="reference frame store (reference.zarr), optional")
    parser.add_argument("--accuracy", help="accuracy.csv to show as a table, optional")
    parser.add_argument("--viewpoint", nargs=4, action="append", default=[],
                        metavar=("NAME", "SHADOW_TIME", "DUAL_COORDS", "DUAL_VIEW"),
                        help="a viewpoint's products (results/<ds>/viewpoints/<name>/*.nc), drawn in viewpoints.png; repeatable")
    parser.add_argument("--outdir", required=True, help="output directory (created)")
    return parser


def run(args):
    """Write the figures of one dataset into ``args.outdir`` (all or nothing)."""
    for option in ("shadow_time", "dual_view", "dual_coords", "accuracy", "manifest"):
        value = getattr(args, option)
        if value and not Path(value).exists():
            raise FileNotFoundError(f"--{option.replace('_', '-')} {value}: no such file")
    manifest = load_manifest(args.manifest)
    truth = None
    if manifest.get("ground_truth") or manifest.get("synthetic"):
        from shadowcam.io.ground_truth import load_ground_truth

        truth = load_ground_truth(manifest)
    reference = None
    if args.reference is not None:
        from shadowcam.io.frame_store import open_frames

        reference = open_frames(args.reference)
    written = write_report_figures(args.outdir, shadow_time=open_dataset(args.shadow_time),
                                   dual_view=open_dataset(args.dual_view), truth=truth,
                                   dual_coords=open_dataset(args.dual_coords) if args.dual_coords else None,
                                   reference=reference, accuracy_csv=args.accuracy,
                                   camera_kind=capture_plan(args.manifest).camera_model,
                                   viewpoints={name: (open_dataset(view), open_dataset(coords))
                                               for name, _, coords, view in args.viewpoint})
    LOG.info("wrote %s", ", ".join(written))
