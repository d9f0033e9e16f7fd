"""``shadowcam lightfield-hdr``: merge one light-field sweep's exposure brackets into HDR frames.

Each frame's brackets (DN, exposure times in seconds from ``capture.json``) are merged
by inverse-variance weighting of the unsaturated samples
(:func:`shadowcam.lightfield.stages.merge_sweep`); the output ``.npy`` stack
``(T, H, W)`` float32 is screen irradiance in lux, NaN where every bracket saturated
(reason ``all_saturated``; the count is logged). Frames stream: memory does not grow with T.

Example::

    shadowcam lightfield-hdr --capture results/synthetic_lightfield/lightfield/capture \\
        --sweep near_h --out results/synthetic_lightfield/lightfield/hdr/near_h.npy

Offers
------
add_parser : register the step and its options.
run : merge and write the sweep.
"""

import logging
from shadowcam.lightfield.stages import merge_sweep, read_description, sweep_files

log = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register ``lightfield-hdr`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="HDR merge of one light-field sweep's brackets")
    parser.add_argument("--capture", required=True, help="capture folder with capture.json")
    parser.add_argument("--sweep", required=True, help="<screen id>_h or <screen id>_v")
    parser.add_argument("--out", required=True, help="output .npy stack (T, H, W), lux")
    return parser


def run(args):
    """Merge the sweep's brackets."""
    description = read_description(args.capture)
    files = sweep_files(args.capture, description, args.sweep)
    result = merge_sweep(files, args.out, exposure_times=description["exposure_times"], sensor=description["sensor"])
    log.info("%s: %d frames, %d photosites with every bracket saturated", args.sweep, result["n_frames"],
             result["all_saturated"])
