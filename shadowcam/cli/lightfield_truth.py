"""``shadowcam lightfield-truth``: ground truth of a rendered light field, once for its accuracy and report.

The source of the manifest's ``synthetic`` block: its irradiance on each render's grid
(``--renders``) and its far field on the equal-area chart at the capture's angular
resolution, the rays' chart size (``--rays``)
(:func:`shadowcam.synthetic.lightfield.truth.truth_dataset`). Writes one netCDF that
``lightfield-accuracy`` and ``lightfield-report`` read.

Example::

    shadowcam lightfield-truth --manifest data_manifest/synthetic_lightfield.yaml \\
        --rays results/synthetic_lightfield/lightfield/rays.nc \\
        --renders results/synthetic_lightfield/lightfield/renders.nc \\
        --out results/synthetic_lightfield/lightfield/truth.nc

Offers
------
add_parser : register the step and its options.
run : compute and write the ground truth.
"""

from shadowcam.io.capture_plan import capture_plan
from shadowcam.io.datasets import open_dataset, write_dataset
from shadowcam.io.manifest import load_manifest
from shadowcam.synthetic.lightfield.capture import capture_from_plan
from shadowcam.synthetic.lightfield.truth import truth_dataset


def add_parser(subparsers, name):
    """Register ``lightfield-truth`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="ground truth of a rendered light field")
    for option, text in (("manifest", "data_manifest/<ds>.yaml (rendered, kind lightfield)"),
                         ("rays", "rays netCDF of lightfield-rays"), ("renders", "renders netCDF of lightfield-render"),
                         ("out", "output netCDF of the ground truth")):
        parser.add_argument(f"--{option}", required=True, help=text)
    return parser


def run(args):
    """Compute the ground truth on the renders' grids and the rays' far-field chart."""
    plan = capture_plan(args.manifest)
    if not plan.rendered:
        raise ValueError(f"manifest {args.manifest}: a captured light field has no ground truth; "
                         "lightfield-truth needs a rendered manifest (with a 'synthetic' block)")
    source = capture_from_plan(plan, load_manifest(args.manifest)["synthetic"]).source
    renders, ray_set = open_dataset(args.renders), open_dataset(args.rays)
    write_dataset(truth_dataset(source, renders, ray_set), args.out, inputs=(renders, ray_set),
                  step="lightfield-truth")
