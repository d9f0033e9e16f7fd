"""``shadowcam lightfield-export``: the light field's far field as IES LM-63 and EULUMDAT files.

The candela table (photometric type C, nadir = the source's axis) is the rays' flux
per solid angle on a tangent-plane grid of ``--gamma-step-deg`` degrees, gamma from 0
to the widest ray, C every ``--c-step-deg`` degrees
(:func:`shadowcam.lightfield.stages.far_field`). Also writes the table as netCDF (cd).

Example::

    shadowcam lightfield-export --rays results/synthetic_lightfield/lightfield/rays.nc \\
        --ies results/synthetic_lightfield/lightfield/source.ies \\
        --ldt results/synthetic_lightfield/lightfield/source.ldt \\
        --table results/synthetic_lightfield/lightfield/far_field.nc

Offers
------
add_parser : register the step and its options.
run : compute and write the table and its files.
"""

from shadowcam.io.datasets import open_dataset, write_dataset
from shadowcam.lightfield.photometry_export import write_photometry
from shadowcam.lightfield.stages import far_field


def add_parser(subparsers, name):
    """Register ``lightfield-export`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="IES and EULUMDAT files of a light field")
    parser.add_argument("--rays", required=True, help="rays netCDF of lightfield-rays")
    parser.add_argument("--c-step-deg", type=float, default=15.0, help="C-plane step, degrees")
    parser.add_argument("--gamma-step-deg", type=float, default=1.0, help="gamma step and bin, degrees")
    parser.add_argument("--ies", required=True, help="output .ies")
    parser.add_argument("--ldt", required=True, help="output .ldt")
    parser.add_argument("--table", required=True, help="output netCDF of the candela table (C, gamma)")
    return parser


def run(args):
    """Write the candela table and its IES and EULUMDAT files."""
    ray_set = open_dataset(args.rays)
    table = far_field(ray_set, c_step_deg=args.c_step_deg, gamma_step_deg=args.gamma_step_deg)
    name = ray_set.attrs.get("dataset", "shadowcam light field")
    write_photometry(args.ies, table, name=name)
    write_photometry(args.ldt, table, name=name)
    write_dataset(table.to_dataset(name="intensity"), args.table, inputs=(ray_set,), step="lightfield-export",
                  config={"c_step_deg": args.c_step_deg, "gamma_step_deg": args.gamma_step_deg})
