"""``shadowcam lightfield-report``: the figures of a light-field capture (paper Fig. 17).

Writes ``inputs.png`` (one HDR frame per screen, log10 lux), ``time_maps.png`` (shadow
time in frames of each screen and sweep), ``renders.png`` (rendered vs ground-truth
irradiance at each render position, with the error map) and ``far_field.png`` (polar
intensity plot in cd, estimate vs ground truth), the last two with ``--truth`` (the dataset
of ``lightfield-truth``, rendered captures only)
(:mod:`shadowcam.report.lightfield_report`) into ``--outdir``, atomically.

Example::

    shadowcam lightfield-report --hdr results/synthetic_lightfield/lightfield/hdr/*.npy \\
        --sweeps results/synthetic_lightfield/lightfield/shadow_times/*.nc \\
        --renders results/synthetic_lightfield/lightfield/renders.nc \\
        --table results/synthetic_lightfield/lightfield/far_field.nc \\
        --truth results/synthetic_lightfield/lightfield/truth.nc \\
        --outdir results/synthetic_lightfield/lightfield/figures

Offers
------
add_parser : register the step and its options.
run : draw and write the figures.
"""

from pathlib import Path

import numpy as np

from shadowcam._shared.atomic import atomic_directory
from shadowcam.io.datasets import open_dataset
from shadowcam.lightfield.photometry_export import sample_far_field
from shadowcam.report import lightfield_report as lf


def add_parser(subparsers, name):
    """Register ``lightfield-report`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="figures of a light-field capture")
    for option, text in (("renders", "renders netCDF of lightfield-render (lux)"),
                         ("table", "candela table netCDF of lightfield-export (cd)"),
                         ("outdir", "output folder of the PNG figures")):
        parser.add_argument(f"--{option}", required=True, help=text)
    parser.add_argument("--truth", help="ground-truth netCDF of lightfield-truth (rendered captures)")
    parser.add_argument("--hdr", nargs="+", required=True, help="<screen>_<h|v>.npy of lightfield-hdr")
    parser.add_argument("--sweeps", nargs="+", required=True, help="<screen>_<h|v>.nc of lightfield-shadow-times")
    return parser


def run(args):
    """Draw the figures."""
    hdr = [p for p in args.hdr if Path(p).stem.endswith("_h")]
    figures = {"inputs": lf.inputs_figure([np.load(p, mmap_mode="r")[0] for p in hdr], [Path(p).stem[:-2] for p in hdr]),
               "time_maps": lf.time_maps_figure([open_dataset(p)["time"].values for p in args.sweeps],
                                                [Path(p).stem for p in args.sweeps])}
    renders, table = open_dataset(args.renders), open_dataset(args.table)["intensity"]
    if args.truth:
        truth = open_dataset(args.truth)
        figures["renders"] = lf.renders_figure(renders["irradiance"].values, truth["irradiance"].values,
                                               renders["position"].values)
        gamma, c = table["gamma"].values, table["C"].values
        far_truth = sample_far_field(truth["far_field"], gamma[None, :], c[:, None])
        figures["far_field"] = lf.far_field_figure(gamma, c, table.values, far_truth)
    with atomic_directory(args.outdir) as tmp:
        for name, figure in figures.items():
            figure.savefig(tmp / f"{name}.png")
