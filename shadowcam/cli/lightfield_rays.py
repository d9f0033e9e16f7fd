"""``shadowcam lightfield-rays``: the rays of a light field from its screens' mask positions.

A ray starts at a pixel of the ``--anchor`` screen (default the near one, the finer
screen image of the rings) and goes through the pixel's mask point on the mask plane; its
flux is that screen's irradiance times the pixel's screen area; the other screen must see
the same mask point (:func:`shadowcam.lightfield.stages.rays_from_sweeps`). The netCDF ray table
(``origin``, ``direction`` in mm, ``flux`` in lm, ``confidence``, ``flag``) is the
open ray-set form (docs/contracts.md).

Example::

    shadowcam lightfield-rays --capture results/synthetic_lightfield/lightfield/capture \\
        --sweeps results/synthetic_lightfield/lightfield/shadow_times/{near_h,near_v,far_h,far_v}.nc \\
        --anchor near --out results/synthetic_lightfield/lightfield/rays.nc

Offers
------
add_parser : register the step and its options.
run : assemble and write the rays.
"""

from pathlib import Path

from shadowcam.io.datasets import open_dataset, write_dataset
from shadowcam.lightfield.rays import ANCHORS
from shadowcam.lightfield.stages import rays_from_sweeps, read_description


def add_parser(subparsers, name):
    """Register ``lightfield-rays`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="rays of a light field")
    parser.add_argument("--capture", required=True, help="capture folder with capture.json")
    parser.add_argument("--sweeps", nargs="+", required=True, help="<screen>_<h|v>.nc of lightfield-shadow-times")
    parser.add_argument("--anchor", choices=ANCHORS, default="far",
                        help="screen whose pixels carry the rays (default far)")
    parser.add_argument("--out", required=True, help="output rays netCDF")
    return parser


def run(args):
    """Assemble the rays."""
    sweeps = {tuple(Path(p).stem.rsplit("_", 1)): open_dataset(p) for p in args.sweeps}
    ray_set = rays_from_sweeps(sweeps, read_description(args.capture), anchor=args.anchor)
    write_dataset(ray_set, args.out, inputs=tuple(sweeps.values()), step="lightfield-rays")
