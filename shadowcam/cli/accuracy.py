"""``shadowcam accuracy``: accuracy of a synthetic dataset's products against its ground truth.

Writes the nested report as JSON and a flat ``metric,value`` CSV table. The
noise condition that selects the shadow-time target comes from ``--params
'{"noise": "noise_free"|"raw12"}'``, else from the manifest's ``ground_truth.noise``
or ``synthetic.noise``,
else ``noise_free``.

Offers
------
add_parser : register the step and its options.
run : evaluate and write the report.
"""

import logging

from shadowcam.cli.options import parse_params

log = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register ``accuracy`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="accuracy against ground truth (synthetic data)",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--manifest", required=True, help="capture description with a ground_truth entry")
    parser.add_argument("--shadow-time", required=True, help="results/<ds>/shadow_time.nc")
    parser.add_argument("--dual-coords", default=None, help="results/<ds>/dual_coords.nc")
    parser.add_argument("--dual-view", default=None, help="results/<ds>/dual_view.nc")
    parser.add_argument("--params", default="{}", help='JSON: {"noise": "noise_free" | "raw12"}')
    parser.add_argument("--out-json", required=True, help="results/<ds>/accuracy.json")
    parser.add_argument("--out-csv", required=True, help="results/<ds>/accuracy.csv")
    return parser


def _open(path):
    import xarray as xr

    if path is None:
        return None
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        return ds.load()


def run(args):
    """Evaluate the products against the manifest's ground truth and write the report."""
    from shadowcam.lab.accuracy import accuracy_report, report_to_csv, report_to_json
    from shadowcam.io.ground_truth import load_ground_truth
    from shadowcam._shared.atomic import atomic_path
    from shadowcam.io.manifest import load_manifest
    from shadowcam.io.provenance import file_sha256

    params = parse_params(args.params, allowed={"noise"})
    manifest = load_manifest(args.manifest)
    gt = load_ground_truth(manifest)
    synthetic = manifest.get("synthetic") or {}
    declared = (manifest.get("ground_truth") or {}).get("noise")
    if "noise" in params:
        noise, source = params["noise"], "--params"
    elif declared:
        noise, source = declared, "manifest ground_truth.noise"
    elif "noise" in synthetic:
        noise, source = ("raw12" if synthetic["noise"] else "noise_free"), "manifest synthetic.noise"
    else:
        noise, source = "noise_free", "default"
    report = accuracy_report(_open(args.shadow_time), gt, dual_coords=_open(args.dual_coords),
                             dual_view=_open(args.dual_view), noise=noise)
    report["noise_source"] = source
    report["dataset"] = manifest["name"]
    report["inputs"] = {str(p): file_sha256(p) for p in (args.shadow_time, args.dual_coords, args.dual_view) if p}
    report["ground_truth_sha256"] = gt.attrs.get("source_sha256", "")
    for target in report["targets"]:
        log.info("%s [%s] = %.4g (%s %.4g): %s", target["target"], target["sweep"], target["value"],
                 target["comparison"], target["threshold"], "pass" if target["pass"] else "FAIL")
    with atomic_path(args.out_json) as tmp:
        tmp.write_text(report_to_json(report))
    with atomic_path(args.out_csv) as tmp:
        tmp.write_text(report_to_csv(report))
    log.info("wrote %s, %s", args.out_json, args.out_csv)
