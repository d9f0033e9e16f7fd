"""``shadowcam render-array``: render a virtual-camera-array capture from its manifest.

The manifest's ``synthetic.camera_array`` block sets the static wire grid; the light
moves along e_u, then e_v, and one image is lit from each wire crossing. The capture is
written as a camera would (:func:`shadowcam.synthetic.lab.array_capture.write_array_capture`):
frame files of sweeps ``horizontal`` and ``vertical``, the crossing images, ``capture.json``
(the manifest of a captured array) and ``ground_truth.nc``; ``synthetic.format``
(dng or tiff), ``noise`` and ``bit_depth`` as in the lab manifests.

Example::

    shadowcam render-array --manifest data_manifest/synthetic_array.yaml \\
        --out results/synthetic_array/array/capture

Offers
------
add_parser : register the step and its options.
run : render and write the capture.
"""

from shadowcam.synthetic.capture_options import capture_options
from shadowcam.synthetic.lab.array_capture import write_array_capture


def add_parser(subparsers, name):
    """Register ``render-array`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="render a virtual-camera-array capture")
    parser.add_argument("--manifest", required=True, help="data_manifest/<ds>.yaml with synthetic.camera_array")
    parser.add_argument("--out", required=True, help="output capture folder, e.g. results/<ds>/array/capture")
    return parser


def run(args):
    """Write the rendered capture."""
    write_array_capture(capture_options(args.manifest), args.out)
