"""``shadowcam render-array``: render a virtual-camera-array capture from its manifest.

The manifest's ``synthetic.camera_array`` block sets the static wire grid; the light
moves along e_u, then e_v, and one image is lit from each wire crossing
(:func:`shadowcam.synthetic.lab.array_capture.render_array_capture`). Writes one netCDF
with the two experiments' frames, the crossing images and the exact ground truth.

Example::

    shadowcam render-array --manifest data_manifest/synthetic_array.yaml \\
        --out results/synthetic_array/array/capture.nc

Offers
------
add_parser : register the step and its options.
run : render and write the capture.
"""

from shadowcam.io.datasets import write_dataset
from shadowcam.io.manifest import load_manifest
from shadowcam.synthetic.lab.array_capture import render_array_capture


def add_parser(subparsers, name):
    """Register ``render-array`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="render a virtual-camera-array capture")
    parser.add_argument("--manifest", required=True, help="data_manifest/<ds>.yaml with synthetic.camera_array")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/array/capture.nc")
    return parser


def run(args):
    """Write the rendered capture."""
    manifest = load_manifest(args.manifest)
    capture = render_array_capture(manifest.get("synthetic", {}), light=manifest.get("light", "point"))
    write_dataset(capture, args.out, config=dict(manifest["synthetic"]), step="render-array")
