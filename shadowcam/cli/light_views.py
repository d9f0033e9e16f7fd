"""``shadowcam light-views``: one shadow camera per light of a several-lights capture.

Each sweep's minima are assigned to the lights by their order along the sweep, checked
by spatial continuity, and timed by ``edge_fit`` over each light's own map
(:func:`shadowcam.lab.light_views.light_set_views`); the lights' positions along the sweep
measured from the data must agree with the capture's ``light_along_*``. Writes the
per-light shadow times, reasons, contrast, confidence, positions and dual views.

Example::

    shadowcam light-views --capture results/synthetic_lights/lights/capture.nc \\
        --out results/synthetic_lights/lights/light_views.nc

Offers
------
add_parser : register the step and its options.
run : compute and write the views.
"""

import xarray as xr

from shadowcam.io.datasets import write_dataset
from shadowcam.lab.light_views import light_set_views


def add_parser(subparsers, name):
    """Register ``light-views`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="one shadow camera per light")
    parser.add_argument("--capture", required=True, help="capture.nc written by render-lights")
    parser.add_argument("--half-window", type=int, default=4,
                        help="frames: at least half the widest dip (a tube across the wire is wide); default 4")
    parser.add_argument("--skip-order-check", action="store_true",
                        help="do not check the lights' measured positions against the capture's "
                             "light_along_* (lights at different heights)")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/lights/light_views.nc")
    return parser


def run(args):
    """Write the per-light views."""
    with xr.open_dataset(args.capture) as opened:
        capture = opened.load()
    views = light_set_views(capture, half_window=args.half_window, check_order=not args.skip_order_check)
    write_dataset(views, args.out, config={"half_window": args.half_window,
                                           "check_order": not args.skip_order_check}, inputs=(capture,),
                  step="light-views")
