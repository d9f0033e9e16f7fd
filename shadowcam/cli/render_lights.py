"""``shadowcam render-lights``: render a several-lights capture and write it as a camera would.

The manifest's ``synthetic.lights`` entries place point and tube lights around the
scene's light (:func:`shadowcam.synthetic.lab.light_set_capture.render_light_set_capture`).
The capture is written as a standard lab capture shot under those lights
(:func:`shadowcam.synthetic.lab.light_set_capture.write_light_set_capture`): frame files of
sweeps ``u`` and ``v``, the reference frame, ``capture.json`` (the manifest of a captured
several-lights capture, with its ``lights`` block) and ``ground_truth.nc`` (per-light
times); ``synthetic.format`` (dng or tiff), ``noise`` and ``bit_depth`` as in the lab
manifests.

Example::

    shadowcam render-lights --manifest data_manifest/synthetic_lights.yaml \\
        --out results/synthetic_lights/lights/capture

Offers
------
add_parser : register the step and its options.
run : render and write the capture.
"""

from shadowcam.synthetic.capture_options import capture_options
from shadowcam.synthetic.lab.light_set_capture import write_light_set_capture


def add_parser(subparsers, name):
    """Register ``render-lights`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="render a several-lights capture")
    parser.add_argument("--manifest", required=True, help="data_manifest/<ds>.yaml with synthetic.lights")
    parser.add_argument("--out", required=True, help="output capture folder, e.g. results/<ds>/lights/capture")
    return parser


def run(args):
    """Write the rendered capture."""
    write_light_set_capture(capture_options(args.manifest), args.out)
