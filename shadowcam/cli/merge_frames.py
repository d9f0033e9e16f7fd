"""``shadowcam merge-frames``: join the part stores of one sweep into its frame store.

The parts come from ``shadowcam decode --frames START:STOP`` (one job each);
their chunk files are hard-linked, not copied (``shadowcam.io.frame_store``), and
the provenance lists the checksums of every part's input files, so the store
equals a single-job decode of the whole sweep.

Example::

    shadowcam merge-frames --parts results/dev_spheres/frames/u.part0.zarr \\
        results/dev_spheres/frames/u.part1.zarr --out results/dev_spheres/frames/u.zarr

Offers
------
add_parser : register the step and its options.
run : merge the parts.
"""

import json

import xarray as xr

from shadowcam.io.datasets import merge_input_checksums
from shadowcam.io.frame_store import merge_frame_stores, open_frames
from shadowcam.io.provenance import attach_provenance


def add_parser(subparsers, name):
    """Register ``merge-frames`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="join part stores of a sweep into one frame store")
    parser.add_argument("--parts", nargs="+", required=True, help="part stores in time order")
    parser.add_argument("--out", required=True, help="output store, e.g. results/<ds>/frames/u.zarr")
    return parser


def run(args):
    """Merge ``args.parts`` into ``args.out`` with the provenance of the whole sweep."""
    attrs = [open_frames(path).attrs for path in args.parts]
    first = next((a for a in attrs if a), {})
    provenance = attach_provenance(xr.Dataset(), config=json.loads(first.get("config", "{}")),
                                   input_checksums=merge_input_checksums(*attrs), step=first.get("step", "decode")).attrs
    merge_frame_stores(args.parts, args.out, attrs=provenance)
