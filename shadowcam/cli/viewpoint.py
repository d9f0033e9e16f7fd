"""``shadowcam viewpoint``: the shadow times of one viewpoint across each pixel's dip interval.

Reads ``results/<ds>/shadow_time.nc`` and writes a copy whose shadow time is
the time at the viewpoint (``entry``, ``centre``, ``exit`` or a fraction in
[0, 1] across the interval; :func:`shadowcam.lab.viewpoints.shadow_time_at`);
the dual stages then give the dual view from that point of the source.

Example::

    shadowcam viewpoint --shadow-time results/synthetic_lab/shadow_time.nc --viewpoint entry \\
        --out results/synthetic_lab/viewpoints/entry/shadow_time.nc

Offers
------
add_parser : register the step and its options.
run : compute and write the dataset.
"""

import xarray as xr

from shadowcam.io.datasets import write_dataset
from shadowcam.lab.viewpoints import shadow_time_at


def add_parser(subparsers, name):
    """Register ``viewpoint`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="shadow times of one viewpoint across the dip interval")
    parser.add_argument("--shadow-time", required=True, help="shadow_time.nc with interval_entry/exit (penumbra_first/last for the outer viewpoints)")
    parser.add_argument("--viewpoint", required=True, help="entry, centre, exit, a fraction in [0, 1], penumbra_first or penumbra_last")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/viewpoints/entry/shadow_time.nc")
    return parser


def run(args):
    """Write the viewpoint's shadow-time dataset."""
    with xr.open_dataset(args.shadow_time) as opened:
        source = opened.load()
    write_dataset(shadow_time_at(source, args.viewpoint), args.out, config={"viewpoint": args.viewpoint},
                  inputs=(source,), step="viewpoint")
