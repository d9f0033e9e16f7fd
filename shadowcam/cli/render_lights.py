"""``shadowcam render-lights``: render the u and v sweeps of a scene lit by several lights.

The manifest's ``synthetic.lights`` entries place point and tube lights around the
scene's light (:func:`shadowcam.synthetic.lab.light_set_capture.render_light_set_capture`).
Writes one netCDF with both sweeps' frames, the reference image and the per-light
ground truth.

Example::

    shadowcam render-lights --manifest data_manifest/synthetic_lights.yaml \\
        --out results/synthetic_lights/lights/capture.nc

Offers
------
add_parser : register the step and its options.
run : render and write the capture.
"""

from shadowcam.io.datasets import write_dataset
from shadowcam.io.manifest import load_manifest
from shadowcam.synthetic.lab.light_set_capture import render_light_set_capture


def add_parser(subparsers, name):
    """Register ``render-lights`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="render a several-lights capture")
    parser.add_argument("--manifest", required=True, help="data_manifest/<ds>.yaml with synthetic.lights")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/lights/capture.nc")
    return parser


def run(args):
    """Write the rendered capture."""
    manifest = load_manifest(args.manifest)
    capture = render_light_set_capture(manifest.get("synthetic", {}), light=manifest.get("light", "point"))
    write_dataset(capture, args.out, config={"lights": str(manifest["synthetic"].get("lights"))},
                  step="render-lights")
