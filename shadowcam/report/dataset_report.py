"""The report figures of one lab dataset, written as one directory (all or nothing).

The directory receives:

* ``primal.png`` - the camera image (the reference image, else the lit image of the
  first sweep),
* ``shadow_time_<sweep>.png`` - one shadow-time map per sweep,
* ``dual_view.png`` - the dual view, next to the ground-truth reciprocal view when the
  capture has ground truth,
* ``error_histogram.png`` - shadow-time errors against ground truth (ground truth only),
* ``accuracy.html`` - the accuracy CSV as an HTML table (when given).

Offers
------
csv_to_html : an HTML page with a CSV file as a table.
primal_image : the camera image shown as the primal view.
write_report_figures : write every figure of a dataset into a directory, atomically.
"""

import csv
import html
from pathlib import Path

from shadowcam._shared.atomic import atomic_directory
from shadowcam.report import figures


def csv_to_html(csv_path, *, title):
    """Return an HTML page with the CSV file at `csv_path` as a table."""
    with open(csv_path, newline="") as handle:
        rows = list(csv.reader(handle))
    if not rows:
        raise ValueError(f"accuracy CSV {csv_path}: the file is empty")
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


def primal_image(shadow_time, reference=None):
    """The camera image of the report: `reference`, else the lit image of the first sweep.

    Parameters
    ----------
    shadow_time : xarray.Dataset
        With ``lit_image`` (or ``lit_level``), optionally per ``sweep``.
    reference : xarray.Dataset, optional
        Reference frame store (``image (row, col, channel)`` or with ``time``: the first frame is used).

    Returns
    -------
    ndarray, shape (H, W, C)
    """
    if reference is not None:
        image = reference["image"]
        if "time" in image.dims:
            image = image.isel(time=0)
        return image.transpose("row", "col", ...).values
    lit = shadow_time["lit_image" if "lit_image" in shadow_time else "lit_level"]
    if "sweep" in lit.dims:
        lit = lit.isel(sweep=0)
    return lit.transpose("row", "col", ...).values


def _write_all(outdir, shadow_time, dual_view, truth, reference, accuracy_csv):
    dual = dual_view["dual_view"].transpose("v", "u", ...).values
    figures.save_png(figures.primal_figure(primal_image(shadow_time, reference)), outdir / "primal.png")
    times = shadow_time["shadow_time"]
    for sweep in times["sweep"].values:
        figures.save_png(
            figures.time_map_figure(times.sel(sweep=sweep).transpose("row", "col").values,
                                    title=f"shadow time, sweep {sweep}"),
            outdir / f"shadow_time_{sweep}.png",
        )
    reciprocal = None
    if truth is not None:
        reciprocal = truth["reciprocal"].transpose("v", "u", ...).values
        errors = {}
        for sweep in ("u", "v"):
            if f"t_{sweep}" in truth and sweep in times["sweep"].values:
                error = times.sel(sweep=sweep) - truth[f"t_{sweep}"]
                errors[f"sweep {sweep}"] = error.where(truth["lit"]).values.ravel()
        if errors:
            figures.save_png(figures.error_histogram_figure(errors), outdir / "error_histogram.png")
    figures.save_png(figures.dual_view_figure(dual, reciprocal=reciprocal), outdir / "dual_view.png")
    if accuracy_csv:
        (outdir / "accuracy.html").write_text(
            csv_to_html(accuracy_csv, title=f"accuracy: {Path(accuracy_csv).parent.name}"))


def write_report_figures(outdir, *, shadow_time, dual_view, truth=None, reference=None, accuracy_csv=None):
    """Write the report figures of one dataset into `outdir` (replaced whole, or left as it was).

    Parameters
    ----------
    outdir : str or Path
    shadow_time : xarray.Dataset
        ``shadow_time (sweep, row, col)`` and the lit image.
    dual_view : xarray.Dataset
        ``dual_view (v, u, channel)``.
    truth : xarray.Dataset, optional
        Lab ground truth (``reciprocal``, ``lit``, ``t_u``, ``t_v``).
    reference : xarray.Dataset, optional
        Reference frame store for the primal image.
    accuracy_csv : str or Path, optional
        Accuracy table to show as ``accuracy.html``.

    Returns
    -------
    list of str
        Names of the files written.
    """
    if accuracy_csv and not Path(accuracy_csv).is_file():
        raise FileNotFoundError(f"accuracy_csv {accuracy_csv}: no such file")
    with atomic_directory(outdir) as tmp:
        _write_all(tmp, shadow_time, dual_view, truth, reference, accuracy_csv)
    return sorted(p.name for p in Path(outdir).iterdir())
