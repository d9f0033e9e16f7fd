"""``shadowcam decode``: decode one sweep (or the reference) of a capture into a frame store.

Verifies the sha256 of the files it decodes first, then streams the frames
into ``results/<ds>/frames/<sweep>.zarr`` (see ``shadowcam.frame_store``).

Offers
------
add_parser : register the step and its options.
run : verify checksums and decode.
"""

import xarray as xr

from shadowcam.frame_store import write_frames, write_reference
from shadowcam.manifest import load_manifest, verify_checksums
from shadowcam.provenance import attach_provenance


def add_parser(subparsers, name):
    """Register ``decode`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(
        name,
        help="decode a sweep (or the reference frame) into a zarr frame store",
        description=__doc__.split("\n\n")[0].strip("`"),
    )
    parser.add_argument("--manifest", required=True, help="data_manifest/<name>.yaml or capture.json")
    parser.add_argument("--sweep", required=True, help="sweep name (u, v, cal_u, cal_v, ...) or 'reference'")
    parser.add_argument("--out", required=True, help="output store, e.g. results/<ds>/frames/u.zarr")
    parser.add_argument("--chunk-frames", type=int, default=None, help="frames per time chunk (default: ~64 MB)")
    return parser


def run(args):
    """Decode ``args.sweep`` of ``args.manifest`` into ``args.out``."""
    manifest = load_manifest(args.manifest)
    sweep = args.sweep
    if sweep != "reference" and sweep not in manifest["sweeps"]:
        raise ValueError(
            f"--sweep {sweep!r} is not a sweep of {args.manifest}; "
            f"available: {sorted(manifest['sweeps']) + (['reference'] if manifest['reference_paths'] else [])}"
        )
    if sweep == "reference" and not manifest["reference_paths"]:
        raise ValueError(f"manifest {args.manifest} has no reference frame (key reference)")
    checksums = verify_checksums(manifest, [sweep])
    config = {"manifest": manifest["name"], "sweep": sweep, "chunk_frames": args.chunk_frames}
    attrs = dict(attach_provenance(xr.Dataset(), config=config, input_checksums=checksums, step="decode").attrs)
    attrs.update(dataset=manifest["name"], sweep=sweep)
    if sweep == "reference":
        write_reference(manifest["reference_paths"], args.out, attrs=attrs)
        return
    entry = manifest["sweeps"][sweep]
    if "axis" in entry:
        attrs["axis"] = entry["axis"]
    write_frames(entry["paths"], args.out, times_s=entry["times_s"], attrs=attrs, chunk_frames=args.chunk_frames)
