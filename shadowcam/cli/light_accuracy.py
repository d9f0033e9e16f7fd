"""``shadowcam light-accuracy``: score per-light shadow times against the ground truth and draw them.

Reads the capture's per-light truth (``ground_truth.nc``: ``t_center_<sweep>``,
``t_first_<sweep>``, ``t_last_<sweep>``, ``reference``) and the views. Writes
``accuracy.json`` (per light and sweep: p95 error, RMSE, coverage, contrast,
reason counts; :func:`shadowcam.lab.light_views.light_set_accuracy`) and a figure with
a row per light: estimated and exact times of each sweep and the light's dual view
and the light's dual view beside the one its exact times give
(:func:`shadowcam.report.light_set_figure.light_set_figure_of`).

Example::

    shadowcam light-accuracy --ground-truth results/synthetic_lights/lights/capture/ground_truth.nc \\
        --views results/synthetic_lights/lights/light_views.nc \\
        --out-json results/synthetic_lights/lights/accuracy.json \\
        --out-png results/synthetic_lights/lights/lights.png

Offers
------
add_parser : register the step and its options.
run : score and draw.
"""

import json

import xarray as xr

from shadowcam._shared.atomic import atomic_path
from shadowcam.lab.light_views import light_set_accuracy
from shadowcam.report.figures import save_png
from shadowcam.report.light_set_figure import light_set_figure_of


def add_parser(subparsers, name):
    """Register ``light-accuracy`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="score and draw per-light shadow times")
    parser.add_argument("--ground-truth", required=True,
                        help="ground_truth.nc of the capture (render-lights writes it beside capture.json)")
    parser.add_argument("--views", required=True, help="light_views.nc written by light-views")
    parser.add_argument("--out-json", required=True, help="results/<ds>/lights/accuracy.json")
    parser.add_argument("--out-png", required=True, help="results/<ds>/lights/lights.png")
    return parser


def run(args):
    """Write the accuracy JSON and the figure."""
    with xr.open_dataset(args.ground_truth) as a, xr.open_dataset(args.views) as b:
        truth, views = a.load(), b.load()
    with atomic_path(args.out_json) as tmp:
        tmp.write_text(json.dumps(light_set_accuracy(views, truth), indent=2))
    with atomic_path(args.out_png) as tmp:
        save_png(light_set_figure_of(views, truth), tmp)
