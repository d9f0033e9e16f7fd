"""Decode one sweep (or the reference) of a capture into a frame store, its files verified first.

Offers
------
decode_sweep : verify the sha256 of a sweep's files and stream them into a frame store (whole or a part).
"""

import xarray as xr

from shadowcam.io.frame_files import check_capture_frames, check_frame_files
from shadowcam.io.frame_store import write_frames, write_reference
from shadowcam.io.manifest import manifest_files, verify_checksums
from shadowcam.io.provenance import attach_provenance


def _only_files(manifest, group, paths):
    """`manifest` whose file group `group` lists only `paths` (what one part job reads)."""
    wanted = {str(p) for p in paths}
    files = [rel for rel, path in manifest_files(manifest, [group]).items() if path in wanted]
    return {**manifest, "files": {**manifest["files"], group: files}}


def decode_sweep(manifest, sweep, out, *, frames=None, chunk_frames=None):
    """Decode `sweep` of `manifest` into the frame store `out`.

    Checks first, before anything is written, that the capture's sweeps and
    reference share one frame size and that the files it decodes share their
    sweep's first file's format, decode path and size
    (:mod:`shadowcam.io.frame_files`), then verifies their sha256 (only those
    of the part).

    Parameters
    ----------
    manifest : mapping
        Loaded manifest (:func:`shadowcam.io.manifest.load_manifest`).
    sweep : str
        Sweep name, or ``reference`` for the reference frame(s).
    out : str or Path
        Frame store to write.
    frames : (int, int), optional
        ``(start, stop)``: decode only these frames into a part store.
    chunk_frames : int, optional
        Frames per time chunk (default about 64 MB).

    Returns
    -------
    dict
        The provenance attrs of the store.

    Raises
    ------
    ValueError
        Naming the odd file and the expected format or size, or the file whose
        checksum differs.
    """
    available = sorted(manifest["sweeps"]) + (["reference"] if manifest["reference_paths"] else [])
    if sweep != "reference" and sweep not in manifest["sweeps"]:
        raise ValueError(f"sweep {sweep!r} is not a sweep of manifest {manifest['name']}; available: {available}")
    if sweep == "reference" and not manifest["reference_paths"]:
        raise ValueError(f"manifest {manifest['name']} has no reference frame (key reference)")
    if sweep == "reference" and frames:
        raise ValueError("frames: a frame range applies to sweeps, not to the reference")
    check_capture_frames(manifest)
    what = f"manifest {manifest['manifest_path']}, {'reference' if sweep == 'reference' else f'sweep {sweep!r}'}"
    if sweep == "reference":
        check_frame_files(manifest["reference_paths"], what=what)
        checksums = verify_checksums(manifest, [sweep])
    else:
        entry = manifest["sweeps"][sweep]
        start, stop = frames or (0, len(entry["paths"]))
        check_frame_files(entry["paths"][start:stop], what=what, first=entry["paths"][0])
        checksums = verify_checksums(_only_files(manifest, sweep, entry["paths"][start:stop]), [sweep])
    config = {"manifest": manifest["name"], "sweep": sweep, "chunk_frames": chunk_frames}
    attrs = dict(attach_provenance(xr.Dataset(), config=config, input_checksums=checksums, step="decode").attrs)
    attrs.update(dataset=manifest["name"], sweep=sweep)
    if sweep == "reference":
        write_reference(manifest["reference_paths"], out, attrs=attrs)
        return attrs
    if "axis" in entry:
        attrs["axis"] = entry["axis"]
    write_frames(entry["paths"][start:stop], out, times_s=entry["times_s"][start:stop],
                 attrs=attrs, chunk_frames=chunk_frames, first_frame=start)
    return attrs
