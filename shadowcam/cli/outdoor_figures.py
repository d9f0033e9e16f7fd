"""``shadowcam outdoor-figures``: report figures of an outdoor time-lapse (paper Fig. 18).

Keyframes with the tracked edge, the edge over time, the arrival map, the
pushbroom beside the real view (sky masked), and with an accuracy report the
error histogram and an HTML table of the figures against the targets.

Offers
------
add_parser : register the step and its options.
run : draw and write the figures.
"""

import html
import json
from pathlib import Path

import numpy as np

from shadowcam.outdoor.arrival import ARRIVAL_REASONS
from shadowcam.cli.outdoor_io import open_dataset
from shadowcam.report.figures import save_png
from shadowcam.io.frame_store import open_frames
from shadowcam.io.frame_times import median_interval
from shadowcam.io.images import atomic_path
from shadowcam.report.outdoor_figures import (arrival_map_figure, display_step, edge_over_time_figure, keyframes_figure,
                                       pushbroom_figure)
from shadowcam.cameras.pushbroom import resample_uniform_time
from shadowcam.outdoor.translation import translate


def add_parser(subparsers, name):
    """Register ``outdoor-figures`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="report figures of an outdoor time-lapse",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--frames", required=True)
    parser.add_argument("--photometry", required=True)
    parser.add_argument("--edges", required=True)
    parser.add_argument("--arrival", required=True)
    parser.add_argument("--pushbroom", required=True)
    parser.add_argument("--accuracy", default=None, help="outdoor accuracy JSON (optional)")
    parser.add_argument("--outdir", required=True)
    return parser


def _accuracy_html(report):
    rows = []
    for estimator, by_definition in report["errors"].items():
        for definition, stats in by_definition.items():
            rows.append(
                f"<tr><td>{html.escape(estimator)}</td><td>{html.escape(definition)}</td>"
                f"<td>{stats['median_abs']:.3f}</td><td>{stats['p95_abs']:.3f}</td>"
                f"<td>{100 * stats['frac_over_5']:.2f}%</td><td>{100 * stats['frac_within_1']:.2f}%</td>"
                f"<td>{100 * stats['coverage']:.2f}%</td></tr>")
    targets = "".join(
        f"<li>{html.escape(t['target'])} = {t['value']:.4f} (&lt;= {t['threshold']}): {'pass' if t['pass'] else 'FAIL'}</li>"
        for t in report["targets"])
    return (
        "<html><body><h2>Outdoor arrival-time accuracy</h2>"
        f"<p>Errors in median capture intervals ({report['interval_s']:.1f} s) over the {report['n_class3']} "
        f"non-sky pixels the shadow reaches; targets ({html.escape(report['condition'])}) checked for "
        f"{html.escape(report['primary_estimator'])} against {html.escape(report['primary_definition'])}.</p>"
        f"<ul>{targets}</ul><table border='1'><tr><th>estimator</th><th>GT definition</th><th>median</th>"
        "<th>p95</th><th>&gt; 5</th><th>within 1</th><th>coverage</th></tr>" + "".join(rows) + "</table></body></html>")


def run(args):
    """Draw the outdoor figures into ``args.outdir``."""
    frames = open_frames(args.frames)
    photometry, edges = open_dataset(args.photometry), open_dataset(args.edges)
    arrival, pushbroom = open_dataset(args.arrival), open_dataset(args.pushbroom)
    outdir = Path(args.outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    sky = photometry["sky"].values.astype(bool)
    time_s = edges["time_s"].values
    picks = np.linspace(0, time_s.size - 1, 6).round().astype(int)
    step = display_step(sky.shape)
    shown = []
    for k in picks:  # six frames only: registered, divided by their lit gain, decimated for display
        frame = frames["image"].isel(time=int(k)).values
        shift = (float(photometry["shift_row"][k]), float(photometry["shift_col"][k]))
        shown.append(translate(frame, shift, method="opencv_cubic")[::step, ::step] / np.float32(photometry["gain"].values[k]))
        del frame
    save_png(keyframes_figure(shown, [edges["edge_row"].values[k] for k in picks], time_s[picks], sky=sky,
                              is_keyframe=edges["is_keyframe"].values[picks], step=step), outdir / "keyframes.png")
    reference = photometry["reference"].values
    save_png(edge_over_time_figure(edges["edge_row"].values, time_s, reference=reference, sky=sky),
             outdir / "edge_over_time.png")
    save_png(arrival_map_figure(arrival["arrival_time_s"].values, sky=sky), outdir / "arrival_map.png")
    uniform_t, uniform = resample_uniform_time(pushbroom["pushbroom"].values, time_s,
                                               step_s=median_interval(time_s))
    save_png(pushbroom_figure(reference, uniform, uniform_t, sky=sky), outdir / "pushbroom.png")
    reasons = arrival["reason"].values
    counts = {name: int((reasons == code).sum()) for code, name in ARRIVAL_REASONS.items()}
    summary = {"reasons": counts, "keyframes": int(edges["is_keyframe"].values.sum()),
               "frames": int(time_s.size), "interpolated_edges": int(edges["interpolated"].values.sum())}
    if args.accuracy:
        report = json.loads(Path(args.accuracy).read_text())
        with atomic_path(outdir / "accuracy.html") as tmp:
            tmp.write_text(_accuracy_html(report))
        summary["all_targets_pass"] = report["all_targets_pass"]
    with atomic_path(outdir / "summary.json") as tmp:
        tmp.write_text(json.dumps(summary, indent=2))
