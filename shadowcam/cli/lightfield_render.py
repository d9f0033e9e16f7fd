"""``shadowcam lightfield-render``: the light field rendered on screens at new positions.

Each ray tube is rasterised with exact area weights on a plane normal to the axis
(:func:`shadowcam.lightfield.stages.render_positions`); the grid pitch is
``--pitch-factor`` times the near camera's pixel pitch magnified to the position.
Positions are distances from the source in metres.

Example::

    shadowcam lightfield-render --rays results/synthetic_lightfield/lightfield/rays.nc \\
        --capture results/synthetic_lightfield/lightfield/capture --positions-m 0.35 0.675 \\
        --pitch-factor 2 --out results/synthetic_lightfield/lightfield/renders.nc

Offers
------
add_parser : register the step and its options.
run : render and write the screens.
"""

from shadowcam.io.datasets import open_dataset, write_dataset
from shadowcam.lightfield.stages import read_description, render_positions


def add_parser(subparsers, name):
    """Register ``lightfield-render`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="render a light field at new screen positions")
    parser.add_argument("--rays", required=True, help="rays netCDF of lightfield-rays")
    parser.add_argument("--capture", required=True, help="capture folder with capture.json")
    parser.add_argument("--positions-m", nargs="+", type=float, required=True, help="distances from the source, m")
    parser.add_argument("--pitch-factor", type=float, default=2.0, help="grid pitch / near camera pitch (magnified)")
    parser.add_argument("--out", required=True, help="output netCDF (position, row, col), lux")
    return parser


def run(args):
    """Render the screens."""
    ray_set = open_dataset(args.rays)
    renders = render_positions(ray_set, read_description(args.capture), [1e3 * p for p in args.positions_m],
                               pitch_factor=args.pitch_factor)
    write_dataset(renders, args.out, config={"positions_m": args.positions_m, "pitch_factor": args.pitch_factor},
                  inputs=(ray_set,), step="lightfield-render")
