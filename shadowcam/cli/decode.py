"""``shadowcam decode``: decode one sweep (or the reference) of a capture into a frame store.

Verifies the sha256 of the files it decodes first, then streams the frames
into ``results/<ds>/frames/<sweep>.zarr`` (see ``shadowcam.io.frame_store``).
With ``--frames START:STOP`` it decodes only that range into a *part* store
(one job of a long sweep; ``shadowcam merge-frames`` joins the parts).

Offers
------
add_parser : register the step and its options.
run : verify checksums and decode.
"""

import xarray as xr

from shadowcam.cli.options import parse_frame_range
from shadowcam.io.frame_store import write_frames, write_reference
from shadowcam.io.manifest import load_manifest, manifest_files, verify_checksums
from shadowcam.io.provenance import attach_provenance


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
    parser.add_argument("--frames", default=None, metavar="START:STOP",
                        help="decode only frames START..STOP-1 of the sweep into a part store "
                             "(START a multiple of --chunk-frames; STOP may exceed the sweep)")
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
    if sweep == "reference" and args.frames:
        raise ValueError("--frames applies to sweeps, not to the reference")
    if sweep == "reference":
        checksums = verify_checksums(manifest, [sweep])
    else:
        entry = manifest["sweeps"][sweep]
        start, stop = (0, len(entry["paths"]))
        if args.frames:
            start, stop = parse_frame_range(args.frames, stop, chunk_frames=args.chunk_frames)
        checksums = verify_checksums(_only_files(manifest, sweep, entry["paths"][start:stop]), [sweep])
    config = {"manifest": manifest["name"], "sweep": sweep, "chunk_frames": args.chunk_frames}
    attrs = dict(attach_provenance(xr.Dataset(), config=config, input_checksums=checksums, step="decode").attrs)
    attrs.update(dataset=manifest["name"], sweep=sweep)
    if sweep == "reference":
        write_reference(manifest["reference_paths"], args.out, attrs=attrs)
        return
    if "axis" in entry:
        attrs["axis"] = entry["axis"]
    write_frames(entry["paths"][start:stop], args.out, times_s=entry["times_s"][start:stop],
                 attrs=attrs, chunk_frames=args.chunk_frames, first_frame=start)


def _only_files(manifest, group, paths):
    """`manifest` whose file group `group` lists only `paths` (what one part job reads)."""
    wanted = {str(p) for p in paths}
    files = [rel for rel, path in manifest_files(manifest, [group]).items() if path in wanted]
    return {**manifest, "files": {**manifest["files"], group: files}}
