"""``shadowcam render``: render a synthetic capture (frames, GT, capture.json): lab or outdoor.

Example::

    shadowcam render --manifest data_manifest/synthetic_lab.yaml --out results/synthetic_lab/capture

    shadowcam render --scene tabletop --seed 1 --height 192 --width 192 --frames 96 \\
        --format dng --bit-depth 12 --calibration --out /tmp/tabletop

The manifest's ``synthetic`` block (docs/contracts.md) gives the options; explicit flags
override it (:mod:`shadowcam.synthetic.capture_options`). Outdoor captures (manifest
``kind: outdoor`` or scene ``ridge``, options in ``synthetic.outdoor``) are sunset
time-lapses. The capture directory (:mod:`shadowcam.synthetic.capture_writer`) is written
beside ``--out`` and renamed into place at the end, so a killed run leaves no half capture.
"""

import argparse
from pathlib import Path

from shadowcam.synthetic.capture_options import BIT_DEPTHS, DEFAULTS, FORMATS, capture_options
from shadowcam.synthetic.capture_writer import write_capture


def add_parser(subparsers, name):
    """Register the ``render`` step and return its parser."""
    p = subparsers.add_parser(name, help="render a synthetic lab or outdoor capture")
    p.add_argument("--manifest", type=Path, help="data_manifest YAML with a 'synthetic' block")
    p.add_argument("--out", type=Path, required=True, help="output capture directory")
    p.add_argument("--name", help="capture name (default: manifest name or scene_seed)")
    p.add_argument("--scene", help=f"preset scene (default {DEFAULTS['scene']})")
    p.add_argument("--seed", type=int, help="scene and noise seed")
    p.add_argument("--height", type=int, help="image rows, pixels")
    p.add_argument("--width", type=int, help="image cols, pixels")
    p.add_argument("--frames", type=int, help="frames per sweep (= dual grid size)")
    p.add_argument("--format", choices=FORMATS, help="frame format")
    p.add_argument("--bit-depth", type=int, choices=BIT_DEPTHS, help="sensor bit depth, bits")
    p.add_argument("--no-noise", dest="noise", action="store_const", const=False,
                   help="noise-free frames (mean DN, rounded)")
    p.add_argument("--calibration", action=argparse.BooleanOptionalAction,
                   default=None, help="also render the calibration-plane sweeps cal_u, cal_v")
    p.add_argument("--light", choices=("point", "area", "distant"),
                   help="light type (default: the manifest's 'light', else point)")
    p.add_argument("--supersample", type=int, help="sub-samples per pixel side (default 4)")
    p.add_argument("--exposure", type=float,
                   help="fraction of the DN range reached by the 99.5th percentile of the "
                        "reference (default 0.8)")
    return p


def run(args):
    """Run the ``render`` step."""
    if args.manifest is None and args.scene is None:
        raise ValueError("give --manifest (with a 'synthetic' block) or --scene")
    overrides = {key: getattr(args, key, None) for key in DEFAULTS if key != "outdoor"}
    options = capture_options(args.manifest, name=args.name, **overrides)
    write_capture(options, args.out)
