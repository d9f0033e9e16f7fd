"""``shadowcam light-views``: one shadow camera per light of a several-lights capture.

Reads a several-lights manifest (a user's ``data_manifest/<ds>.yaml`` with a top-level
``lights`` block, or the ``capture.json`` that render-lights writes), decodes the u and v
sweeps one after the other; each sweep's minima are assigned to the lights by their order
along the sweep, checked by spatial continuity, and timed by ``edge_fit`` over each
light's own map (:func:`shadowcam.lab.light_files.light_set_views_of_plan`). The v sweep's
lights are paired with the u sweep's by their contrast maps (each light's share of a pixel's
light is the same in both sweeps); a pairing the maps do not decide is flagged
(``pairing_decided`` 0, a warning) and the shadows' order kept. The lights' positions along
the sweep measured from the data, and a decided pairing, must agree with the manifest's
``lights.light_along_*`` when it gives them. A light whose dip a sweep cannot show (its
minima no more than noise alone places) keeps no time there: reason ``unresolved_dip``,
``shown`` 0. Writes the per-light shadow times, reasons, contrast, confidence, ``shown``,
positions and dual views.

Example::

    shadowcam light-views --manifest results/synthetic_lights/lights/capture/capture.json \\
        --out results/synthetic_lights/lights/light_views.nc

Offers
------
add_parser : register the step and its options.
run : compute and write the views.
"""

from shadowcam.io.capture_plan import capture_plan
from shadowcam.io.datasets import write_dataset
from shadowcam.lab.light_files import light_set_views_of_plan


def add_parser(subparsers, name):
    """Register ``light-views`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="one shadow camera per light")
    parser.add_argument("--manifest", required=True,
                        help="several-lights manifest: data_manifest/<ds>.yaml or a rendered capture.json")
    parser.add_argument("--half-window", type=int, default=4,
                        help="frames: at least half the widest dip (a tube across the wire is wide); default 4")
    parser.add_argument("--skip-order-check", action="store_true",
                        help="do not check the lights' measured positions and pairing against the "
                             "manifest's lights.light_along_* (lights at different heights): warn instead")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/lights/light_views.nc")
    return parser


def run(args):
    """Write the per-light views."""
    plan = capture_plan(args.manifest)
    views = light_set_views_of_plan(plan, half_window=args.half_window, check_order=not args.skip_order_check)
    write_dataset(views, args.out, config={"half_window": args.half_window, "manifest": plan.manifest_path,
                                           "check_order": not args.skip_order_check}, step="light-views")
