"""``shadowcam report-figures``: the PNG figures (and accuracy table) of the HTML report.

Writes into ``--outdir``:

* ``primal.png`` - the camera image (``--reference`` frame, else the lit image of the
  first sweep from ``--shadow-time``),
* ``shadow_time_<sweep>.png`` - one shadow-time map per sweep of ``--shadow-time``,
* ``dual_view.png`` - the dual view, next to the ground-truth reciprocal view when the
  capture has ground truth,
* ``error_histogram.png`` - shadow-time errors against ground truth (ground truth only),
* ``accuracy.html`` - the ``--accuracy`` CSV as an HTML table (when given).

Offers ``add_parser(subparsers, name)`` and ``run(args)``.
"""

import csv
import html
import logging
import shutil
import tempfile
from pathlib import Path

import xarray as xr

from shadowcam.report import figures

LOG = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register the step `name` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="write the report figures of one dataset",
                                   description=__doc__)
    parser.add_argument("--manifest", required=True,
                        help="capture description (data_manifest/X.yaml or capture.json)")
    parser.add_argument("--shadow-time", required=True, help="shadow_time.nc")
    parser.add_argument("--dual-view", required=True, help="dual_view.nc")
    parser.add_argument("--reference", help="reference frame store (reference.zarr), optional")
    parser.add_argument("--accuracy", help="accuracy.csv to show as a table, optional")
    parser.add_argument("--outdir", required=True, help="output directory (created)")
    return parser


def _primal_image(reference, shadow_time):
    if reference is not None:
        from shadowcam.io.frame_store import open_frames

        image = open_frames(reference)["image"]
        if "time" in image.dims:
            image = image.isel(time=0)
        return image.transpose("row", "col", ...).values
    lit = shadow_time["lit_image" if "lit_image" in shadow_time else "lit_level"]
    if "sweep" in lit.dims:
        lit = lit.isel(sweep=0)
    return lit.transpose("row", "col", ...).values


def _ground_truth(manifest_path):
    """Return the ground-truth dataset of the capture, or None if it has none."""
    from shadowcam.io.manifest import load_manifest

    manifest = load_manifest(manifest_path)
    if not manifest.get("ground_truth") and not manifest.get("synthetic"):
        return None
    from shadowcam.io.ground_truth import load_ground_truth

    return load_ground_truth(manifest)


def csv_to_html(csv_path, *, title):
    """Return an HTML page with the CSV file at `csv_path` as a table."""
    with open(csv_path, newline="") as handle:
        rows = list(csv.reader(handle))
    if not rows:
        raise ValueError(f"--accuracy {csv_path}: the file is empty")
    head = "".join(f"<th>{html.escape(cell)}</th>" for cell in rows[0])
    body = "\n".join(
        "<tr>" + "".join(f"<td>{html.escape(cell)}</td>" for cell in row) + "</tr>"
        for row in rows[1:]
    )
    return (
        "<!DOCTYPE html>\n<html><head><meta charset='utf-8'>"
        f"<title>{html.escape(title)}</title><style>"
        "table{border-collapse:collapse;font-family:sans-serif;font-size:14px}"
        "th,td{border:1px solid #bbb;padding:3px 8px;text-align:right}"
        "th{background:#eee}</style></head><body>"
        f"<h3>{html.escape(title)}</h3>\n<table>\n<tr>{head}</tr>\n{body}\n</table>"
        "</body></html>\n"
    )


def _write_all(args, outdir):
    with xr.open_dataset(args.shadow_time, engine="h5netcdf") as shadow_time, \
            xr.open_dataset(args.dual_view, engine="h5netcdf") as dual_view:
        shadow_time = shadow_time.load()
        dual = dual_view["dual_view"].transpose("v", "u", ...).values
    figures.save_png(figures.primal_figure(_primal_image(args.reference, shadow_time)),
                     outdir / "primal.png")
    times = shadow_time["shadow_time"]
    for sweep in times["sweep"].values:
        figures.save_png(
            figures.time_map_figure(times.sel(sweep=sweep).transpose("row", "col").values,
                                    title=f"shadow time, sweep {sweep}"),
            outdir / f"shadow_time_{sweep}.png",
        )
    truth = _ground_truth(args.manifest)
    reciprocal = None
    if truth is not None:
        reciprocal = truth["reciprocal"].transpose("v", "u", ...).values
        errors = {}
        for sweep in ("u", "v"):
            if f"t_{sweep}" in truth and sweep in times["sweep"].values:
                error = times.sel(sweep=sweep) - truth[f"t_{sweep}"]
                errors[f"sweep {sweep}"] = error.where(truth["lit"]).values.ravel()
        if errors:
            figures.save_png(figures.error_histogram_figure(errors),
                             outdir / "error_histogram.png")
    figures.save_png(figures.dual_view_figure(dual, reciprocal=reciprocal),
                     outdir / "dual_view.png")
    if args.accuracy:
        (outdir / "accuracy.html").write_text(
            csv_to_html(args.accuracy, title=f"accuracy: {Path(args.accuracy).parent.name}")
        )


def run(args):
    """Write the figures of one dataset into ``args.outdir`` (all or nothing)."""
    outdir = Path(args.outdir)
    for option in ("shadow_time", "dual_view", "accuracy", "manifest"):
        value = getattr(args, option)
        if value and not Path(value).exists():
            raise FileNotFoundError(f"--{option.replace('_', '-')} {value}: no such file")
    outdir.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{outdir.name}.", dir=outdir.parent))
    try:
        _write_all(args, staging)
        if outdir.exists():
            shutil.rmtree(outdir)
        staging.rename(outdir)
    finally:
        if staging.exists():
            shutil.rmtree(staging)
    LOG.info("wrote %s", ", ".join(sorted(p.name for p in outdir.iterdir())))
