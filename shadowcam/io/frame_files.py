"""What a frame file holds, read from its first bytes and header: format, decode path, size.

A sweep's files must share one format, one decode path and one frame size,
and every sweep and reference frame of a capture one frame size. The format
is decided by the file's content (its magic bytes; a TIFF with a DNGVersion
tag is DNG), never by its name: a file whose content and name disagree (a DNG
renamed ``.png``) is an error, because the name picks the decoder
(:func:`shadowcam.io.raw_mosaic.is_raw`). The frame size comes from the header
(a PNG's IHDR chunk; OpenImageIO's spec for other images; for camera RAW,
LibRaw's size fields, read without unpacking the data).

These checks read a few bytes and one header per file, and are run where the
files are read anyway: :func:`check_capture_frames` (the first file of each
sweep and the reference) by the capture plan and the decode step,
:func:`check_frame_files` (every file a decode job reads, against its sweep's
first file) by the decode step before it writes anything.

Offers
------
RAW_FORMATS : formats decoded as camera RAW (rawpy).
file_format : a frame file's format from its magic bytes.
header_size : ``(rows, cols)`` of a frame from its header only.
check_frame_files : frame files share the first one's format, decode path and size.
check_capture_frames : the sweeps and reference of a manifest share one frame size.
"""

import struct
from pathlib import Path

from shadowcam.io.raw_mosaic import check_frame_path, is_raw

#: formats (as :func:`file_format` names them) that only camera RAW decoding reads
RAW_FORMATS = frozenset({"DNG", "Canon CR2", "Canon CR3", "Olympus ORF", "Panasonic RW2",
                         "Fujifilm RAF", "Sigma X3F", "Minolta MRW"})
#: formats that only OpenImageIO reads
_IMAGE_FORMATS = frozenset({"PNG", "JPEG", "OpenEXR"})
_MAGIC = (
    (0, b"\x89PNG\r\n\x1a\n", "PNG"),
    (0, b"\xff\xd8\xff", "JPEG"),
    (0, b"v/1\x01", "OpenEXR"),
    (0, b"IIRO", "Olympus ORF"), (0, b"IIRS", "Olympus ORF"), (0, b"MMOR", "Olympus ORF"),
    (0, b"IIU\x00", "Panasonic RW2"),
    (0, b"FUJIFILM", "Fujifilm RAF"),
    (0, b"FOVb", "Sigma X3F"),
    (0, b"\x00MRM", "Minolta MRW"),
    (4, b"ftypcrx ", "Canon CR3"),
)
_DNG_VERSION_TAG = 50706


def _tiff_format(handle, head):
    """``DNG``, ``Canon CR2`` or ``TIFF`` for a file starting with a TIFF header."""
    if head[8:10] == b"CR":
        return "Canon CR2"
    order = "<" if head[:2] == b"II" else ">"
    (offset,) = struct.unpack(order + "I", head[4:8])
    handle.seek(offset)
    raw = handle.read(2)
    if len(raw) < 2:
        return "TIFF"
    (count,) = struct.unpack(order + "H", raw)
    entries = handle.read(12 * count)
    tags = {struct.unpack(order + "H", entries[k:k + 2])[0] for k in range(0, len(entries) - 1, 12)}
    return "DNG" if _DNG_VERSION_TAG in tags else "TIFF"


def file_format(path):
    """Return the format of a frame file from its content (magic bytes).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    str
        ``PNG``, ``JPEG``, ``OpenEXR``, ``TIFF``, ``DNG`` (a TIFF with a
        DNGVersion tag), a camera RAW format (see :data:`RAW_FORMATS`), or
        ``unknown (<first 4 bytes in hex>)``.
    """
    path = check_frame_path(path)
    with open(path, "rb") as handle:
        head = handle.read(16)
        for offset, magic, name in _MAGIC:
            if head[offset:offset + len(magic)] == magic:
                return name
        if head[:4] in (b"II*\x00", b"MM\x00*"):
            return _tiff_format(handle, head)
    return f"unknown ({head[:4].hex()})"


def _decode_path(path):
    return "camera RAW (rawpy)" if is_raw(path) else "OpenImageIO"


def header_size(path):
    """Return ``(rows, cols)`` of a frame from its header, without decoding pixels.

    Parameters
    ----------
    path : str or Path
        Camera RAW (the visible mosaic's size) or any image OpenImageIO reads.

    Returns
    -------
    (2,) tuple of int
        The size :func:`shadowcam.io.decode.read_frame` returns.
    """
    path = check_frame_path(path)
    if is_raw(path):
        import rawpy

        try:
            with rawpy.imread(str(path)) as raw:
                return int(raw.sizes.height), int(raw.sizes.width)
        except (rawpy.LibRawError, OSError) as exc:
            raise ValueError(f"cannot read camera RAW file {path}: {exc}") from None
    with open(path, "rb") as handle:
        head = handle.read(24)
    if head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR":  # width, height: big-endian uint32
        width, height = struct.unpack(">II", head[16:24])
        return int(height), int(width)
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    if not inp:
        raise ValueError(f"cannot read image file {path}: {oiio.geterror()}")
    spec = inp.spec()
    inp.close()
    return int(spec.height), int(spec.width)


def _format(path):
    """Format and decode path of one file; ValueError if its content and name disagree."""
    fmt = file_format(path)
    raw = is_raw(path)
    if (fmt in RAW_FORMATS and not raw) or (fmt in _IMAGE_FORMATS and raw):
        raise ValueError(
            f"frame file {path} holds {fmt} data but its name ends in {Path(path).suffix!r}, which is "
            f"decoded with {_decode_path(path)}; rename it with the suffix of its format "
            "(and run `shadowcam checksum` again)"
        )
    return fmt, _decode_path(path)


def _size_text(size):
    return f"{size[0]}x{size[1]}"


def _raise_odd(odd, *, what, first, facts, fix):
    shown = "; ".join(odd[:5]) + (f"; and {len(odd) - 5} more" if len(odd) > 5 else "")
    raise ValueError(
        f"{what}: {shown}, but the first file {first} is {facts}; frame files must share one {fix[0]}. "
        f"{fix[1]}"
    )


def check_frame_files(paths, *, what, first=None):
    """Check that frame files share one format, decode path and size.

    Parameters
    ----------
    paths : sequence of str or Path
        Files to check.
    what : str, keyword-only
        What the files are (e.g. ``"manifest M, sweep 'u'"``), for messages.
    first : str or Path, optional, keyword-only
        File the others must match (default ``paths[0]``; e.g. the sweep's
        first file when `paths` are one part of it).

    Returns
    -------
    dict
        ``format``, ``decode`` (decode path) and ``size`` (``(rows, cols)``)
        of `first`.

    Raises
    ------
    ValueError
        Naming every odd file with its format or size and those of `first`,
        or a file whose content and name disagree (a DNG named ``.png``).
    """
    paths = [Path(p) for p in paths]
    first = Path(first) if first is not None else paths[0]
    fmt, decode = _format(first)
    formats = [(path, _format(path)) for path in paths]
    odd = [f"{path} is {f} ({d})" for path, (f, d) in formats if (f, d) != (fmt, decode)]
    if odd:
        _raise_odd(odd, what=what, first=first, facts=f"{fmt} ({decode})", fix=(
            "format and decode path", "Remove or convert the odd files (mixed formats decode at "
            "different brightness)"))
    size = header_size(first)
    odd = [f"{path} is {_size_text(s)}" for path in paths if (s := header_size(path)) != size]
    if odd:
        _raise_odd(odd, what=what, first=first, facts=f"{_size_text(size)} (rows x cols)", fix=(
            "frame size", "Remove or crop the odd files"))
    return {"format": fmt, "decode": decode, "size": size}


def _first_sweep(manifest):
    sweeps = list(manifest["sweeps"])
    return next((name for name in ("u", "timelapse") if name in sweeps), sweeps[0])


def check_capture_frames(manifest):
    """Check that the sweeps and reference of a capture share one frame size.

    Reads the header of the first file of each sweep and of each reference
    frame (a few files, whatever the length of the sweeps).

    Parameters
    ----------
    manifest : mapping
        Loaded manifest with sweeps (:func:`shadowcam.io.manifest.load_manifest`).

    Returns
    -------
    (2,) tuple of int
        ``(rows, cols)`` of the frames: that of the first file of sweep ``u``
        (else ``timelapse``, else the first sweep).

    Raises
    ------
    ValueError
        Naming the manifest, the odd file, its size and the expected size.
    """
    first = manifest["sweeps"][_first_sweep(manifest)]["paths"][0]
    size = header_size(first)
    odd = [f"{path} is {_size_text(s)}"
           for path in [entry["paths"][0] for entry in manifest["sweeps"].values()] + manifest["reference_paths"]
           if (s := header_size(path)) != size]
    if odd:
        _raise_odd(odd, what=f"manifest {manifest['manifest_path']}", first=first,
                   facts=f"{_size_text(size)} (rows x cols)", fix=(
                       "frame size across its sweeps and reference",
                       "Every sweep and the reference must come from one camera at one size: "
                       "remove or crop the odd files"))
    return size
