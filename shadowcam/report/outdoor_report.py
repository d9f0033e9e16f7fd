"""The report of one outdoor time-lapse: figures (paper Fig. 18), summary and accuracy table.

Offers
------
accuracy_html : an HTML page of an outdoor accuracy report against its targets.
outdoor_summary : counts of arrival reasons, keyframes and interpolated edges.
arrival_in_truth_camera : the arrival map and its ground truth on the ground truth's pixel grid.
transient_events_of : the transient-events figure of an arrival dataset's event table.
write_outdoor_figures : write the figures, ``summary.json`` and ``accuracy.html`` into a directory.
"""

import json
from pathlib import Path

import numpy as np

from shadowcam._shared.atomic import atomic_path
from shadowcam.cameras.pushbroom import resample_uniform_time
from shadowcam.io.frame_times import median_interval
from shadowcam.outdoor.arrival import ARRIVAL_REASONS
from shadowcam.outdoor.translation import translate
from shadowcam.report.dataset_report import table_html
from shadowcam.report.figures import save_png
from shadowcam.report.outdoor_figures import (
    arrival_map_figure, display_step, edge_over_time_figure, keyframes_figure, pushbroom_figure,
    transient_events_figure,
)

#: frames shown in the keyframes figure
SHOWN_FRAMES = 6


def accuracy_html(report):
    """Return an HTML page of `report` (:func:`shadowcam.outdoor.accuracy.outdoor_accuracy`).

    The table is :func:`shadowcam.outdoor.accuracy.accuracy_table` (one row per quantity,
    with unit, target and pass), under the ground truth's definition.
    """
    from shadowcam.outdoor.accuracy import GROUND_TRUTH_DEFINITION, accuracy_table

    rows = accuracy_table(report)
    return table_html([list(rows[0])] + [list(row.values()) for row in rows],
                      title="Outdoor arrival-time accuracy", note=GROUND_TRUTH_DEFINITION)


def outdoor_summary(edges, arrival, report=None):
    """Counts of the outdoor products: arrival reasons, keyframes, frames, interpolated edges.

    Parameters
    ----------
    edges, arrival : xarray.Dataset
    report : dict, optional
        Accuracy report; adds ``all_targets_pass``.

    Returns
    -------
    dict
    """
    reasons = arrival["reason"].values
    summary = {"reasons": {name: int((reasons == code).sum()) for code, name in ARRIVAL_REASONS.items()},
               "keyframes": int(edges["is_keyframe"].values.sum()),
               "frames": int(edges["time_s"].size), "interpolated_edges": int(edges["interpolated"].values.sum())}
    if report is not None:
        summary["all_targets_pass"] = report["all_targets_pass"]
    return summary


def arrival_in_truth_camera(arrival_s, truth):
    """The arrival map, sky and ground-truth arrival on one grid: the ground truth's camera.

    The map is in the first frame's pixel grid; synthetic ground truth is in the unshaken
    camera, so the map is moved by the first frame's recorded shake, as the accuracy step does.

    Returns
    -------
    estimate_s, truth_s : (H, W) ndarray
    sky : (H, W) bool ndarray
    """
    from shadowcam.outdoor.accuracy import map_to_truth_camera

    shift = {"shift_row": 0.0, "shift_col": 0.0}
    if "shake_dy_px" in truth and truth["shake_dy_px"].size:
        shift = {"shift_row": float(truth["shake_dy_px"].values[0]),
                 "shift_col": float(truth["shake_dx_px"].values[0])}
    sky = truth["sky_mask"].values.astype(bool) if "sky_mask" in truth else np.zeros(np.shape(arrival_s), bool)
    return map_to_truth_camera(arrival_s, **shift), truth["arrival_time_s"].values, sky


def transient_events_of(arrival, *, sky):
    """The transient-events figure of an arrival dataset's event table (None without one).

    Parameters
    ----------
    arrival : xarray.Dataset
        With ``event_row``, ``event_col``, ``event_start_s`` and ``event_kind`` (CF flags:
        ``flag_values``, ``flag_meanings``) over ``event``.
    sky : (H, W) bool ndarray

    Returns
    -------
    matplotlib.figure.Figure or None
    """
    if "event_kind" not in arrival:
        return None
    kind = arrival["event_kind"]
    codes = dict(zip(str(kind.attrs.get("flag_meanings", "")).split(),
                     np.atleast_1d(kind.attrs.get("flag_values", []))))
    transient = (kind.values == codes["transient"]) if "transient" in codes else np.zeros(kind.shape, bool)
    return transient_events_figure(arrival["event_row"].values, arrival["event_col"].values,
                                   arrival["event_start_s"].values, transient, sky=sky)


def write_outdoor_figures(outdir, *, frames, photometry, edges, arrival, pushbroom, report=None, truth=None):
    """Write the outdoor figures, ``summary.json`` and (with `report`) ``accuracy.html``.

    Parameters
    ----------
    outdir : str or Path
        Created if missing; files are written atomically one by one.
    frames : xarray.Dataset
        Frame store (only :data:`SHOWN_FRAMES` frames are read).
    photometry, edges, arrival, pushbroom : xarray.Dataset
        The pipeline's outdoor datasets.
    report : dict, optional
        Outdoor accuracy report.
    truth : xarray.Dataset, optional
        Outdoor ground truth: the arrival map is drawn beside the GT arrival map and the
        error map, all in the ground truth's camera (:func:`arrival_in_truth_camera`).

    Returns
    -------
    dict
        The summary written.

    Notes
    -----
    Files: ``keyframes.png``, ``edge_over_time.png``, ``arrival_map.png``,
    ``transient_events.png`` (when the arrival dataset has an event table),
    ``pushbroom.png``, ``summary.json``, ``accuracy.html`` (with `report`).
    """
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    sky = photometry["sky"].values.astype(bool)
    time_s = edges["time_s"].values
    picks = np.linspace(0, time_s.size - 1, SHOWN_FRAMES).round().astype(int)
    step = display_step(sky.shape)
    shown = []
    for k in picks:  # registered, divided by their lit gain, decimated for display
        frame = frames["image"].isel(time=int(k)).values
        shift = (float(photometry["shift_row"][k]), float(photometry["shift_col"][k]))
        shown.append(translate(frame, shift, method="opencv_cubic")[::step, ::step] / np.float32(photometry["gain"].values[k]))
        del frame
    save_png(keyframes_figure(shown, [edges["edge_row"].values[k] for k in picks], time_s[picks], sky=sky,
                              is_keyframe=edges["is_keyframe"].values[picks], step=step), outdir / "keyframes.png")
    reference = photometry["reference"].values
    save_png(edge_over_time_figure(edges["edge_row"].values, time_s, reference=reference, sky=sky),
             outdir / "edge_over_time.png")
    if truth is not None and "arrival_time_s" in truth:
        estimate_s, truth_s, truth_sky = arrival_in_truth_camera(arrival["arrival_time_s"].values, truth)
        figure = arrival_map_figure(estimate_s, sky=truth_sky, truth_s=truth_s, interval_s=median_interval(time_s))
    else:
        figure = arrival_map_figure(arrival["arrival_time_s"].values, sky=sky)
    save_png(figure, outdir / "arrival_map.png")
    events = transient_events_of(arrival, sky=sky)
    if events is not None:
        save_png(events, outdir / "transient_events.png")
    uniform_t, uniform = resample_uniform_time(pushbroom["pushbroom"].values, time_s,
                                               step_s=median_interval(time_s))
    save_png(pushbroom_figure(reference, uniform, uniform_t, sky=sky), outdir / "pushbroom.png")
    if report is not None:
        with atomic_path(outdir / "accuracy.html") as tmp:
            tmp.write_text(accuracy_html(report))
    summary = outdoor_summary(edges, arrival, report)
    with atomic_path(outdir / "summary.json") as tmp:
        tmp.write_text(json.dumps(summary, indent=2))
    return summary
