"""``shadowcam lightfield-accuracy``: renders and far field of a rendered light field against ground truth.

For each render position: relative RMSE after one gain fit of the render and of the
naive baseline (the nearest captured screen rescaled by inverse square and
magnification), their ratio (target <= 0.5), the correlation of the DoG(1, 4 px)
band-passed render and truth (target >= 0.9) and the relative RMSE of the band-passed
images (the ring pattern's fine structure; the render's below the baseline's); the far
field of the rays on the equal-area direction chart at the capture's angular resolution
(near + far camera pitch over the screen separation) against the true intensity
integrated over the same cells: median relative error over cells above 5 % of the peak
(target 5 %); the fraction of pixels with a ray
(:func:`shadowcam.lightfield.accuracy.lightfield_accuracy`). The ground truth is
``lightfield-truth``'s dataset. Writes JSON and a quantity table CSV.

Example::

    shadowcam lightfield-accuracy --capture results/synthetic_lightfield/lightfield/capture \\
        --sweeps results/synthetic_lightfield/lightfield/shadow_times/*.nc \\
        --rays results/synthetic_lightfield/lightfield/rays.nc \\
        --renders results/synthetic_lightfield/lightfield/renders.nc \\
        --truth results/synthetic_lightfield/lightfield/truth.nc \\
        --json results/synthetic_lightfield/lightfield/accuracy.json \\
        --csv results/synthetic_lightfield/lightfield/accuracy.csv

Offers
------
add_parser : register the step and its options.
run : score and write the report.
"""

import json
from pathlib import Path

import numpy as np

from shadowcam._shared.atomic import atomic_path
from shadowcam._shared.quantity_table import table_to_csv
from shadowcam.io.datasets import open_dataset
from shadowcam.lightfield.accuracy import accuracy_rows, lightfield_accuracy
from shadowcam.lightfield.photometry_export import far_field_grid, rays_resolution_deg
from shadowcam.lightfield.stages import read_description, screen_maps


def add_parser(subparsers, name):
    """Register ``lightfield-accuracy`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="accuracy of a rendered light field")
    for option, text in (("truth", "ground-truth netCDF of lightfield-truth"),
                         ("capture", "capture folder with capture.json"), ("rays", "rays netCDF of lightfield-rays"),
                         ("renders", "renders netCDF of lightfield-render (lux)"),
                         ("json", "output JSON of the scores"), ("csv", "output quantity table CSV")):
        parser.add_argument(f"--{option}", required=True, help=text)
    parser.add_argument("--sweeps", nargs="+", required=True, help="<screen>_<h|v>.nc of lightfield-shadow-times")
    return parser


def run(args):
    """Score the light field against the renderer's ground truth."""
    truth, renders = open_dataset(args.truth), open_dataset(args.renders)
    if not np.allclose(truth["position"].values, renders["position"].values):
        raise ValueError(f"{args.truth} holds the truth at {truth['position'].values} mm but {args.renders} renders "
                         f"{renders['position'].values} mm: run lightfield-truth on these renders again")
    sweeps = {tuple(Path(p).stem.rsplit("_", 1)): open_dataset(p) for p in args.sweeps}
    ray_set = open_dataset(args.rays)
    far = far_field_grid(ray_set["direction"].values, ray_set["flux"].values,
                         resolution_deg=rays_resolution_deg(ray_set))
    scores = lightfield_accuracy(
        renders, far, screen_maps(sweeps, read_description(args.capture)),
        truth["irradiance"].values, far_truth=truth["far_field"].values, flags=ray_set["flag"].values)
    with atomic_path(args.json) as tmp:
        tmp.write_text(json.dumps(scores, indent=1))
    with atomic_path(args.csv) as tmp:
        tmp.write_text(table_to_csv(accuracy_rows(scores)))
