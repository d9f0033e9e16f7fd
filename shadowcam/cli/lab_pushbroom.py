"""``shadowcam lab-pushbroom``: the shadow pushbroom of a single-sweep lab capture.

One sweep is enough for this camera (paper Fig. 10 IV-V): the image has the shadow time
(frames) along one axis and the position along the shadow line (the camera row for a
vertical wire, pixels) along the other, coloured with the scene lit from both the camera
and the light (the reference frame, else the sweep's lit image)
(:func:`shadowcam.cameras.pushbroom.pushbroom_from_shadow_time`). Writes
``results/<ds>/pushbroom.nc`` and an sRGB PNG preview (time downward).

Example::

    shadowcam lab-pushbroom --shadow-time results/dev_spheres_u/shadow_time.nc \\
        --reference results/dev_spheres_u/frames/reference.zarr \\
        --out results/dev_spheres_u/pushbroom.nc --png results/dev_spheres_u/pushbroom.png

Offers
------
add_parser : register the step and its options.
run : assemble and write the pushbroom.
"""

import logging

from shadowcam.cameras.pushbroom import pushbroom_from_shadow_time
from shadowcam.io.datasets import open_dataset, write_dataset
from shadowcam.io.frame_store import open_frames
from shadowcam.io.images import write_png_preview

log = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register ``lab-pushbroom`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="shadow pushbroom of a single-sweep lab capture")
    parser.add_argument("--shadow-time", required=True, help="results/<ds>/shadow_time.nc (times in frames)")
    parser.add_argument("--sweep", default=None, help="sweep to use (default: the only sweep in --shadow-time)")
    parser.add_argument("--reference", default=None, help="reference frame store (results/<ds>/frames/reference.zarr)")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/pushbroom.nc")
    parser.add_argument("--png", default=None, help="8-bit sRGB preview PNG")
    return parser


def run(args):
    """Assemble the pushbroom and write it with its preview."""
    shadow_time = open_dataset(args.shadow_time)
    sweep = args.sweep or str(shadow_time["sweep"].values[0])
    reference = open_frames(args.reference) if args.reference else None
    dataset = pushbroom_from_shadow_time(shadow_time, sweep=sweep, reference=reference)
    inputs = (shadow_time,) + ((reference,) if reference is not None else ())
    write_dataset(dataset, args.out, config={"sweep": sweep, "reference": bool(args.reference)},
                  inputs=inputs, step="lab-pushbroom")
    if args.png:
        write_png_preview(args.png, dataset["pushbroom"].values)
    log.info("wrote %s", ", ".join(p for p in (args.out, args.png) if p))
