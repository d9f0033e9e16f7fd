"""``shadowcam decode``: decode one sweep (or the reference) of a capture into a frame store.

Verifies the sha256 of the files it decodes first, then streams the frames
into ``results/<ds>/frames/<sweep>.zarr`` (:func:`shadowcam.io.sweep_store.decode_sweep`).
With ``--frames START:STOP`` it decodes only that range into a *part* store
(one job of a long sweep; ``shadowcam merge-frames`` joins the parts).

Example::

    shadowcam decode --manifest data_manifest/dev_spheres.yaml --sweep u \\
        --out results/dev_spheres/frames/u.zarr

Offers
------
add_parser : register the step and its options.
run : verify checksums and decode.
"""

from shadowcam.cli.options import parse_frame_range
from shadowcam.io.manifest import load_manifest
from shadowcam.io.sweep_store import decode_sweep


def add_parser(subparsers, name):
    """Register ``decode`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(
        name,
        help="decode a sweep (or the reference frame) into a zarr frame store",
    )
    parser.add_argument("--manifest", required=True, help="data_manifest/<name>.yaml or capture.json")
    parser.add_argument("--sweep", required=True, help="sweep name (u, v, cal_u, cal_v, ...) or 'reference'")
    parser.add_argument("--out", required=True, help="output store, e.g. results/<ds>/frames/u.zarr")
    parser.add_argument("--chunk-frames", type=int, default=None, help="frames per time chunk (default: ~64 MB)")
    parser.add_argument("--frames", default=None, metavar="START:STOP",
                        help="decode only frames START..STOP-1 of the sweep into a part store "
                             "(START a multiple of --chunk-frames; STOP may exceed the sweep)")
    return parser


def run(args):
    """Decode ``args.sweep`` of ``args.manifest`` into ``args.out``."""
    manifest = load_manifest(args.manifest)
    frames = None
    if args.frames and args.sweep in manifest["sweeps"]:
        n_frames = len(manifest["sweeps"][args.sweep]["paths"])
        frames = parse_frame_range(args.frames, n_frames, chunk_frames=args.chunk_frames)
    elif args.frames and args.sweep == "reference":
        raise ValueError("--frames applies to sweeps, not to the reference")
    decode_sweep(manifest, args.sweep, args.out, frames=frames, chunk_frames=args.chunk_frames)
