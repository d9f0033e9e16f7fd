"""``shadowcam render-lightfield``: render a ``kind: lightfield`` capture from its manifest.

The manifest's ``synthetic`` block (scene ``reflector``, seed, height, width, frames,
noise) and ``lightfield`` block (screens with ``position_m`` in metres, bracket
``exposure_times_s`` in seconds) give the capture
(:func:`shadowcam.synthetic.lightfield.capture.capture_from_plan`). Writes
``<screen id>/<x|y>/frame<t>_b<e>.dng`` (12-bit RAW, one file per bracket) and
``capture.json`` into ``--out``, atomically.

Example::

    shadowcam render-lightfield --manifest data_manifest/synthetic_lightfield.yaml \\
        --out results/synthetic_lightfield/lightfield/capture

Offers
------
add_parser : register the step and its options.
run : render and write the capture.
"""

from shadowcam.io.capture_plan import capture_plan
from shadowcam.io.manifest import load_manifest
from shadowcam.synthetic.lightfield.capture import capture_from_plan, write_capture


def add_parser(subparsers, name):
    """Register ``render-lightfield`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="render a synthetic light-field capture")
    parser.add_argument("--manifest", required=True, help="data_manifest/<ds>.yaml (kind lightfield, synthetic)")
    parser.add_argument("--out", required=True, help="output capture folder")
    return parser


def run(args):
    """Render the capture the manifest describes."""
    manifest = load_manifest(args.manifest)
    if "synthetic" not in manifest or manifest["kind"] != "lightfield":
        raise ValueError(f"manifest {args.manifest}: needs kind: lightfield and a 'synthetic' block to be rendered")
    write_capture(args.out, capture_from_plan(capture_plan(args.manifest), manifest["synthetic"]))
