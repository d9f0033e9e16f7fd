"""``shadowcam render-lightfield``: the capture folder of a ``kind: lightfield`` manifest.

A captured light field gets its ``capture.json`` only: screens, mask, bracket times
and the files of each sweep, from the manifest (:func:`shadowcam.lightfield.stages.describe_capture`).
A rendered one is rendered:
the manifest's ``synthetic`` block (scene ``reflector``, seed, height, width, frames,
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

import json

from shadowcam._shared.atomic import atomic_directory
from shadowcam.io.capture_plan import capture_plan
from shadowcam.lightfield.stages import DESCRIPTION_FILE, describe_capture
from shadowcam.io.manifest import load_manifest
from shadowcam.synthetic.lightfield.capture import capture_from_plan, write_capture


def add_parser(subparsers, name):
    """Register ``render-lightfield`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="render or describe a light-field capture")
    parser.add_argument("--manifest", required=True, help="data_manifest/<ds>.yaml (kind lightfield, synthetic)")
    parser.add_argument("--out", required=True, help="output capture folder")
    return parser


def run(args):
    """Render or describe the capture the manifest gives."""
    manifest, plan = load_manifest(args.manifest), capture_plan(args.manifest)
    if not plan.is_lightfield:
        raise ValueError(f"manifest {args.manifest}: key 'kind' must be lightfield; got {plan.kind!r}")
    if plan.rendered:
        write_capture(args.out, capture_from_plan(plan, manifest["synthetic"]))
        return
    description = describe_capture(plan)
    with atomic_directory(args.out) as tmp:
        (tmp / DESCRIPTION_FILE).write_text(json.dumps(description, indent=1))
