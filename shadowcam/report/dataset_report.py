"""The report figures of one lab dataset, written as one directory (all or nothing).

The directory receives:

* ``primal.png`` - the camera image (the reference image, else the lit image of the
  first sweep),
* ``shadow_time_<sweep>.png`` - one shadow-time map per sweep,
* ``dual_view.png`` - the dual view, next to the ground-truth reciprocal view when the
  capture has ground truth,
* ``error_histogram.png`` - shadow-time errors against ground truth (ground truth only),
* ``viewpoints.png`` - with viewpoints (paper Fig. 13): each viewpoint's dual view beside
  its reciprocal render on the same grid, one row per viewpoint,
* ``accuracy.html`` - the accuracy CSV as an HTML table with the ground truth's
  definition (when given).

Offers
------
table_html : an HTML page with rows as a table (pass column coloured).
csv_to_html : an HTML page with a CSV file as a table.
primal_image : the camera image shown as the primal view.
dual_view_report_figure : the dual view beside its ground truth on the same grid, model and coverage.
viewpoints_report_figure : each viewpoint's dual view beside its reciprocal render (Fig. 13).
write_report_figures : write every figure of a dataset into a directory, atomically.
"""

import csv
import html
from pathlib import Path

import numpy as np

from shadowcam._shared.atomic import atomic_directory
from shadowcam.report import figures


def table_html(rows, *, title, note=None):
    """Return an HTML page with `rows` (first row = header) as a table, under `title` and `note`.

    A ``pass`` column is coloured (yes green, no red); the first column is left-aligned.
    """
    rows = [list(row) for row in rows]
    if not rows:
        raise ValueError("rows must hold at least a header row")
    verdict = rows[0].index("pass") if "pass" in rows[0] else None

    def cell(index, text):
        style = ""
        if index == verdict and text in ("yes", "no"):
            style = " style='color:{}'".format("#080" if text == "yes" else "#c00")
        return f"<td{style}>{html.escape(text)}</td>"

    head = "".join(f"<th>{html.escape(text)}</th>" for text in rows[0])
    body = "\n".join("<tr>" + "".join(cell(i, text) for i, text in enumerate(row)) + "</tr>" for row in rows[1:])
    paragraph = f"<p>{html.escape(note)}</p>\n" if note else ""
    return (
        "<!DOCTYPE html>\n<html><head><meta charset='utf-8'>"
        f"<title>{html.escape(title)}</title><style>"
        "body{font-family:sans-serif;font-size:14px;max-width:60em}"
        "table{border-collapse:collapse}"
        "th,td{border:1px solid #bbb;padding:3px 8px;text-align:right}"
        "td:first-child,th:first-child{text-align:left}"
        "th{background:#eee}</style></head><body>"
        f"<h3>{html.escape(title)}</h3>\n{paragraph}<table>\n<tr>{head}</tr>\n{body}\n</table>"
        "</body></html>\n"
    )


def csv_to_html(csv_path, *, title, note=None):
    """Return an HTML page with the CSV file at `csv_path` as a table (:func:`table_html`)."""
    with open(csv_path, newline="") as handle:
        rows = list(csv.reader(handle))
    if not rows:
        raise ValueError(f"accuracy CSV {csv_path}: the file is empty")
    return table_html(rows, title=title, note=note)


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


def dual_view_report_figure(dual_view, *, dual_coords=None, truth=None, camera_kind=None):
    """The dual view beside its ground truth on the same dual grid, with model and coverage.

    The reciprocal render is resampled onto the dual grid exactly as the accuracy
    step does (:func:`shadowcam.lab.accuracy.reciprocal_on_dual_grid`), so pixel
    (v, u) of both panels is the same ray from the light.

    Parameters
    ----------
    dual_view : xarray.Dataset
        ``dual_view (v, u, channel)``, ``coverage (v, u)``.
    dual_coords : xarray.Dataset, optional
        Its attrs: the dual grid (``method``, ``scale``, ``offset``, ``plane_window``), the
        camera kind (``projection``, named in the title without `camera_kind`), the chosen
        ``model`` and ``model_choice`` (why).
    truth : xarray.Dataset, optional
        Lab ground truth (``reciprocal``, ``dual_cam_visible``).
    camera_kind : str, optional
        The capture plan's camera model (``CapturePlan.camera_model``), named in the title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from shadowcam.lab.accuracy import reciprocal_on_dual_grid

    dual = dual_view["dual_view"].transpose("v", "u", ...).values
    covered = np.asarray(dual_view["coverage"].transpose("v", "u").values, dtype=bool)
    attrs = dual_coords.attrs if dual_coords is not None else {}
    reciprocal = visible = None
    if truth is not None:
        reciprocal, visible = reciprocal_on_dual_grid(truth, covered.shape, dual_coords=dual_coords)
    coverage = f"coverage {covered.mean():.0%} of the grid"
    if visible is not None and visible.any():
        coverage = f"coverage {(covered & visible).sum() / visible.sum():.0%} of what the camera sees"
    model = attrs.get("model", dual_view.attrs.get("dual_coords_model", "?"))
    kind = camera_kind or attrs.get("projection")
    camera = f"{kind.replace('_', '-')} shadow camera" if kind else "shadow camera"
    title = f"dual view ({camera}), model {model}\n{coverage}"
    note = attrs.get("model_choice")
    return figures.dual_view_figure(dual, reciprocal=reciprocal, title=title,
                                    reciprocal_title="ground truth: reciprocal render from the light\nresampled onto the same dual grid",
                                    note=f"dual model: {note}" if note else None)


def viewpoints_report_figure(viewpoints, *, truth=None):
    """Each viewpoint's dual view beside its reciprocal render on the same grid (paper Fig. 13).

    Parameters
    ----------
    viewpoints : dict of str to (xarray.Dataset, xarray.Dataset)
        Viewpoint name -> its ``(dual_view, dual_coords)``, in reading order.
    truth : xarray.Dataset, optional
        Lab ground truth with ``reciprocal_<viewpoint>`` and ``dual_cam_visible_<viewpoint>``
        (a capture under an area light); resampled onto each dual grid like the accuracy step.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from shadowcam.lab.accuracy import reciprocal_on_dual_grid

    rows = []
    for name, (dual_view, dual_coords) in viewpoints.items():
        dual = dual_view["dual_view"].transpose("v", "u", ...).values
        reciprocal = None
        keys = (f"reciprocal_{name}", f"dual_cam_visible_{name}")
        if truth is not None and all(k in truth for k in keys):
            own = truth.assign(reciprocal=truth[keys[0]], dual_cam_visible=truth[keys[1]])
            reciprocal, _ = reciprocal_on_dual_grid(own, dual.shape[:2], dual_coords=dual_coords)
        rows.append((str(name), dual, reciprocal))
    return figures.viewpoints_figure(rows)


def _write_all(outdir, shadow_time, dual_view, dual_coords, truth, reference, accuracy_csv,
               camera_kind, viewpoints=None):
    figures.save_png(figures.primal_figure(primal_image(shadow_time, reference)), outdir / "primal.png")
    times = shadow_time["shadow_time"]
    for sweep in times["sweep"].values:
        figures.save_png(
            figures.time_map_figure(times.sel(sweep=sweep).transpose("row", "col").values,
                                    title=f"shadow time, sweep {sweep}"),
            outdir / f"shadow_time_{sweep}.png",
        )
    if truth is not None:
        errors = {}
        for sweep in ("u", "v"):
            if f"t_{sweep}" in truth and sweep in times["sweep"].values:
                error = times.sel(sweep=sweep) - truth[f"t_{sweep}"]
                errors[f"sweep {sweep}"] = error.where(truth["lit"]).values.ravel()
        if errors:
            figures.save_png(figures.error_histogram_figure(errors), outdir / "error_histogram.png")
    figures.save_png(dual_view_report_figure(dual_view, dual_coords=dual_coords, truth=truth,
                                             camera_kind=camera_kind),
                     outdir / "dual_view.png")
    if viewpoints:
        figures.save_png(viewpoints_report_figure(viewpoints, truth=truth), outdir / "viewpoints.png")
    if accuracy_csv:
        from shadowcam.lab.accuracy import GROUND_TRUTH_DEFINITION

        (outdir / "accuracy.html").write_text(
            csv_to_html(accuracy_csv, title=f"accuracy: {Path(accuracy_csv).parent.name}",
                        note=GROUND_TRUTH_DEFINITION))


def write_report_figures(outdir, *, shadow_time, dual_view, dual_coords=None, truth=None, reference=None,
                         accuracy_csv=None, camera_kind=None, viewpoints=None):
    """Write the report figures of one dataset into `outdir` (replaced whole, or left as it was).

    Parameters
    ----------
    outdir : str or Path
    shadow_time : xarray.Dataset
        ``shadow_time (sweep, row, col)`` and the lit image.
    dual_view : xarray.Dataset
        ``dual_view (v, u, channel)``.
    dual_coords : xarray.Dataset, optional
        Dual coordinates: their grid and model choice (attrs), for the dual-view figure.
    truth : xarray.Dataset, optional
        Lab ground truth (``reciprocal``, ``lit``, ``t_u``, ``t_v``).
    reference : xarray.Dataset, optional
        Reference frame store for the primal image.
    accuracy_csv : str or Path, optional
        Accuracy table to show as ``accuracy.html``.
    camera_kind : str, optional
        The capture plan's camera model, named in the dual-view figure's title.
    viewpoints : dict of str to (xarray.Dataset, xarray.Dataset), optional
        Viewpoint name -> its ``(dual_view, dual_coords)``: drawn as ``viewpoints.png``.

    Returns
    -------
    list of str
        Names of the files written.
    """
    if accuracy_csv and not Path(accuracy_csv).is_file():
        raise FileNotFoundError(f"accuracy_csv {accuracy_csv}: no such file")
    with atomic_directory(outdir) as tmp:
        _write_all(tmp, shadow_time, dual_view, dual_coords, truth, reference, accuracy_csv,
                   camera_kind, viewpoints)
    return sorted(p.name for p in Path(outdir).iterdir())
