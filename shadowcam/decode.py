"""Frame decoding: camera RAW, TIFF, PNG and EXR to linear float32 RGB.

Every frame comes out as a ``(H, W, 3)`` float32 array, linear, with black = 0
and the sensor's (or file format's) white level = 1. Nothing else is done: no
gamma, no auto-brightness, no white balance, no colour matrix (the as-shot
white balance is *reported* by :func:`frame_info`, never applied).

* Camera RAW (``.dng``, ``.cr2``, ``.nef``, ...) is read with rawpy:
  ``raw_image_visible`` minus ``black_level_per_channel`` at each CFA site,
  divided by ``white_level - black``, demosaiced bilinearly with OpenCV.
  :func:`iter_frames` reads a sequence's DNG mosaics directly where that is
  verified equal to rawpy (:mod:`shadowcam.mosaic_reader`).
* TIFF / PNG / EXR / ... are read with OpenImageIO in their native type;
  integer types are divided by the type's maximum (a 16-bit PNG by 65535),
  floating-point data are taken as they are.

Offers
------
RAW_EXTENSIONS : file-name suffixes decoded with rawpy.
is_raw : whether a path is decoded as camera RAW.
read_frame : one frame as a (H, W, 3) float32 array (optionally with its info).
read_mosaic : a RAW frame's Bayer mosaic (uint16) and per-site black / white levels.
header_metadata : exposure and capture time from the file header only.
frame_info : size, bit depth, black/white levels, white balance, exposure and
    capture time of a frame, without decoding more than needed.
iter_frames : decode several frames one at a time, checking they share a size.
bayer_pattern : the 2x2 CFA pattern ("RGGB", ...) from rawpy's description.
site_constants : per-site constants of the top-left 2x2 block as a full-size mosaic map.
opencv_bayer_code : the OpenCV ``COLOR_Bayer*2RGB`` code for a CFA pattern.
demosaic_bilinear : bilinear demosaic of an integer Bayer mosaic with OpenCV.
"""

import datetime as _dt
import logging
import math
from pathlib import Path

import cv2
import numpy as np

log = logging.getLogger(__name__)

#: file-name suffixes (lower case) decoded as camera RAW with rawpy
RAW_EXTENSIONS = frozenset(
    ".dng .cr2 .cr3 .crw .nef .nrw .arw .srf .sr2 .raf .orf .rw2 .rwl .pef "
    ".srw .3fr .iiq .erf .kdc .dcr .mef .mos .mrw .x3f .raw".split()
)

_CHANNEL_OF_LETTER = {"R": 0, "G": 1, "B": 2}
_RGB = "RGB"


def is_raw(path):
    """Return True if `path` is decoded as camera RAW (by its suffix)."""
    return Path(path).suffix.lower() in RAW_EXTENSIONS


# ---------------------------------------------------------------------------
# Bayer helpers (pure functions)


def bayer_pattern(raw_pattern, color_desc):
    """Return the 2x2 CFA pattern as a 4-letter string such as ``"RGGB"``.

    Parameters
    ----------
    raw_pattern : (2, 2) array_like of int
        Colour index at (row 0, col 0), (0, 1), (1, 0), (1, 1) of the mosaic, as
        rawpy's ``raw_pattern`` or ``raw_colors_visible[:2, :2]``.
    color_desc : bytes or str
        rawpy's ``color_desc``: the letter of each colour index, e.g. ``b"RGBG"``.

    Returns
    -------
    str
        Letters in reading order: row 0 col 0, row 0 col 1, row 1 col 0, row 1 col 1.
    """
    pattern = np.asarray(raw_pattern)
    if pattern.shape != (2, 2):
        raise ValueError(
            f"raw_pattern must be 2x2 (a Bayer CFA); got shape {pattern.shape} "
            "(X-Trans and other CFAs are not supported)"
        )
    desc = color_desc.decode() if isinstance(color_desc, bytes) else str(color_desc)
    try:
        letters = "".join(desc[int(i)] for i in pattern.ravel())
    except IndexError:
        raise ValueError(
            f"raw_pattern {pattern.tolist()} refers to colours missing from color_desc {desc!r}"
        ) from None
    if sorted(letters) != ["B", "G", "G", "R"]:
        raise ValueError(
            f"CFA pattern {letters!r} is not a Bayer pattern of R, G, G, B "
            f"(raw_pattern {pattern.tolist()}, color_desc {desc!r})"
        )
    return letters


def site_constants(values, shape):
    """Per-site constants of the top-left 2x2 block, tiled to `shape`.

    Parameters
    ----------
    values : (2, 2) array_like
    shape : tuple of int
        ``(M, N)`` of the mosaic.

    Returns
    -------
    (M, N) float64 ndarray
    """
    values = np.asarray(values, np.float64)
    if values.shape != (2, 2):
        raise ValueError(f"values must be (2, 2) per-site constants, got shape {values.shape}")
    rows, cols = int(shape[0]), int(shape[1])
    return np.tile(values, (rows // 2 + 1, cols // 2 + 1))[:rows, :cols]


def opencv_bayer_code(pattern):
    """Return the OpenCV ``cvtColor`` code demosaicing `pattern` to RGB.

    Parameters
    ----------
    pattern : {"RGGB", "BGGR", "GRBG", "GBRG"}
        CFA letters in reading order (see :func:`bayer_pattern`).

    Returns
    -------
    int
        ``cv2.COLOR_Bayer<pattern>2RGB``. OpenCV's historic two-letter names
        (``COLOR_BayerBG2RGB`` ...) name the pattern from the second row; the
        four-letter aliases used here name it from the top-left pixel.
    """
    if pattern not in ("RGGB", "BGGR", "GRBG", "GBRG"):
        raise ValueError(f"pattern must be one of RGGB, BGGR, GRBG, GBRG; got {pattern!r}")
    return getattr(cv2, f"COLOR_Bayer{pattern}2RGB")


def demosaic_bilinear(mosaic, *, pattern, max_value):
    """Bilinearly demosaic an integer Bayer mosaic with OpenCV.

    OpenCV demosaics only 8/16-bit integers and rounds interpolated values,
    so the mosaic is multiplied by the largest integer ``k`` with
    ``k * max_value <= 65535`` first (1/16 DN resolution for 12-bit data) and
    the result divided by ``k``. The image is padded by two pixels (mirror,
    which keeps the CFA phase) so that border pixels are interpolated like
    inner ones. At every CFA site its own channel is the site's value exactly.

    Parameters
    ----------
    mosaic : (M, N) ndarray of unsigned int
        Raw mosaic, rows x cols, values in ``0 .. max_value``; M, N >= 3.
    pattern : {"RGGB", "BGGR", "GRBG", "GBRG"}
        CFA pattern of the mosaic's top-left 2x2 block.
    max_value : int
        Largest value the mosaic can hold (e.g. 4095 for 12-bit data).

    Returns
    -------
    (M, N, 3) float32 ndarray
        R, G, B in the units of `mosaic`.
    """
    rgb, scale = _demosaic_scaled(mosaic, pattern=pattern, max_value=max_value)
    out = rgb.astype(np.float32)
    if scale > 1:
        out /= np.float32(scale)
    return out


def _demosaic_scaled(mosaic, *, pattern, max_value):
    """OpenCV demosaic of ``mosaic * k``: return ((M, N, 3) uint16 view, k)."""
    mosaic = np.asarray(mosaic)
    if mosaic.ndim != 2 or min(mosaic.shape) < 3:
        raise ValueError(f"mosaic must be a 2-D array of at least 3x3; got shape {mosaic.shape}")
    if mosaic.dtype.kind not in "ui":
        raise ValueError(f"mosaic must hold integers; got dtype {mosaic.dtype}")
    max_value = int(max_value)
    if not 1 <= max_value <= 65535:
        raise ValueError(f"max_value must be in 1..65535; got {max_value}")
    code = opencv_bayer_code(pattern)
    scale = 65535 // max_value
    scaled = mosaic.astype(np.uint16) * np.uint16(scale) if scale > 1 else mosaic.astype(np.uint16)
    padded = cv2.copyMakeBorder(scaled, 2, 2, 2, 2, cv2.BORDER_REFLECT_101)
    return cv2.cvtColor(padded, code)[2:-2, 2:-2], scale


def _site_map(values, shape, pattern, max_value):
    """Per-site constants (2x2 array) as a demosaiced (M, N, 3) map, or (3,) if uniform."""
    values = np.asarray(values, dtype=np.float64).reshape(2, 2)
    if np.all(values == values.flat[0]):
        return np.full(3, values.flat[0], dtype=np.float32)
    return demosaic_bilinear(site_constants(values, shape).astype(np.uint16), pattern=pattern, max_value=max_value)


# ---------------------------------------------------------------------------
# metadata


def _parse_exif_datetime(text, subsec=None):
    """EXIF "YYYY:MM:DD HH:MM:SS" (+ sub-second digits) -> naive datetime, or None."""
    if not text:
        return None
    text = str(text).strip().rstrip("\x00")
    for fmt in ("%Y:%m:%d %H:%M:%S", "%Y-%m-%d %H:%M:%S", "%Y-%m-%dT%H:%M:%S"):
        try:
            stamp = _dt.datetime.strptime(text[:19], fmt)
            break
        except ValueError:
            continue
    else:
        return None
    digits = "".join(ch for ch in str(subsec or "") if ch.isdigit())
    if digits:
        stamp += _dt.timedelta(seconds=float("0." + digits))
    return stamp


def header_metadata(path):
    """Read exposure and capture time from a file header only (OpenImageIO).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    dict
        ``exposure_s`` (float or None), ``capture_time`` (ISO 8601 string from
        EXIF DateTimeOriginal plus SubsecTimeOriginal, or None) and
        ``bits_per_sample`` (int or None). All None if OpenImageIO cannot
        open the file (e.g. a non-TIFF camera RAW).
    """
    import OpenImageIO as oiio

    out = {"exposure_s": None, "capture_time": None, "bits_per_sample": None}
    inp = oiio.ImageInput.open(str(path))
    if not inp:
        oiio.geterror()  # clear the error state; RAW formats may be unknown to OIIO
        return out
    try:
        spec = inp.spec()
        exposure = spec.getattribute("ExposureTime")
        if exposure is not None and float(exposure) > 0:
            out["exposure_s"] = float(f"{float(exposure):.7g}")  # OIIO holds it as float32
        stamp = _parse_exif_datetime(
            spec.getattribute("Exif:DateTimeOriginal") or spec.getattribute("DateTimeOriginal"),
            spec.getattribute("Exif:SubsecTimeOriginal"),
        )
        if stamp is not None:
            out["capture_time"] = stamp.isoformat()
        bits = spec.getattribute("oiio:BitsPerSample")
        out["bits_per_sample"] = int(bits) if bits else None
    finally:
        inp.close()
    return out


# ---------------------------------------------------------------------------
# decoders


def _white_balance_rgb(multipliers):
    """rawpy 4-entry multipliers (R, G, B, G2; 0 = same as G) -> [R, G, B] with G = 1."""
    mult = [float(m) for m in multipliers]
    if len(mult) < 3 or mult[1] <= 0:
        return None
    return [mult[0] / mult[1], 1.0, mult[2] / mult[1]]


def _normalise_in_place(image, black, span):
    """``image = (image - black) / span`` in place; per-channel (3,) constants as scalars.

    numpy broadcasts a (3,) operand over the last axis with a slow inner loop
    of length 3 (~40x slower than a scalar), so equal constants are applied as
    scalars and different ones channel by channel on strided views; full
    (M, N, 3) maps are used as they are.
    """
    if black.ndim == 1 and span.ndim == 1 and np.all(black == black[0]) and np.all(span == span[0]):
        np.subtract(image, black[0], out=image)  # the same constants for every channel
        np.divide(image, span[0], out=image)
    elif black.ndim == 1 and span.ndim == 1:
        for c in range(image.shape[2]):
            channel = image[..., c]
            np.subtract(channel, black[c], out=channel)
            np.divide(channel, span[c], out=channel)
    else:
        image -= black
        np.divide(image, span, out=image)


def read_mosaic(path):
    """Read a camera RAW file's visible Bayer mosaic and its levels, undemosaiced.

    Parameters
    ----------
    path : str or Path
        Camera RAW file (see :data:`RAW_EXTENSIONS`).

    Returns
    -------
    mosaic : (M, N) uint16 ndarray
        ``raw_image_visible``, in file units (DN).
    levels : dict
        ``cfa_pattern`` (e.g. ``"RGGB"``), ``black_sites`` and ``white_sites``
        ((2, 2) float64 arrays: the black and white level of each site of the
        top-left 2x2 block), ``white_balance`` (as :func:`frame_info`) and
        ``decoder`` (what read the mosaic).
    """
    import rawpy

    path = _check_path(path)
    try:
        raw = rawpy.imread(str(path))
    except (rawpy.LibRawError, OSError) as exc:
        raise ValueError(f"cannot read camera RAW file {path}: {exc}") from None
    with raw:
        if raw.raw_type != rawpy.RawType.Flat:
            raise ValueError(
                f"{path}: RAW type {raw.raw_type.name} is not a single-plane Bayer mosaic; "
                "convert it to TIFF or a Bayer DNG first"
            )
        mosaic = raw.raw_image_visible.copy()
        colours = raw.raw_colors_visible[:2, :2]  # CFA phase at the visible origin
        pattern = bayer_pattern(colours, raw.color_desc)
        black_sites = np.asarray(raw.black_level_per_channel, dtype=np.float64)[colours]
        white_per = raw.camera_white_level_per_channel
        white_sites = (
            np.asarray(white_per, dtype=np.float64)[colours] if white_per is not None
            else np.full((2, 2), float(raw.white_level))
        )
        wb = _white_balance_rgb(raw.camera_whitebalance)
    if np.any(white_sites <= black_sites):
        raise ValueError(f"{path}: white level {white_sites.tolist()} not above black {black_sites.tolist()}")
    return mosaic, {"cfa_pattern": pattern, "black_sites": black_sites, "white_sites": white_sites,
                    "white_balance": wb, "decoder": "rawpy raw_image_visible"}


def _decode_raw(path, mosaics=None):
    mosaic, levels = read_mosaic(path) if mosaics is None else mosaics.read(path)
    shape = mosaic.shape
    pattern, black_sites, white_sites = levels["cfa_pattern"], levels["black_sites"], levels["white_sites"]
    vmax = int(white_sites.max())
    rgb, k = _demosaic_scaled(mosaic, pattern=pattern, max_value=vmax)
    # (k * DN - k * black) / (k * (white - black)): exact at each CFA site's own
    # channel (integers below 2**24), computed in place on one float32 buffer
    black = _site_map(black_sites, shape, pattern, vmax) * np.float32(k)
    span = _site_map(white_sites, shape, pattern, vmax) * np.float32(k) - black
    image = rgb.astype(np.float32)
    _normalise_in_place(image, black, span)
    header = header_metadata(path)
    bits = header["bits_per_sample"] or int(math.ceil(math.log2(white_sites.max() + 1)))
    info = {
        "path": str(path),
        "decoder": f"{levels['decoder']} + OpenCV bilinear demosaic (linear, no white balance)",
        "height": int(shape[0]),
        "width": int(shape[1]),
        "bit_depth": int(bits),
        "cfa_pattern": pattern,
        "black_level": [float(np.mean(black_sites[np.array(list(pattern)).reshape(2, 2) == c])) for c in _RGB],
        "white_level": float(white_sites.max()),
        "white_balance": levels["white_balance"],
        "exposure_s": header["exposure_s"],
        "capture_time": header["capture_time"],
    }
    return image, info


def _oiio_info(path, spec):
    """Metadata dict of a non-RAW frame from its OpenImageIO spec and header."""
    import OpenImageIO as oiio

    header = header_metadata(path)
    integer = spec.format.basetype not in (oiio.HALF, oiio.FLOAT, oiio.DOUBLE)
    white = float(np.iinfo(np.dtype(str(spec.format))).max) if integer else 1.0
    return {
        "path": str(path),
        "decoder": f"OpenImageIO {oiio.__version__} ({spec.format}, divided by {white:g})",
        "height": int(spec.height),
        "width": int(spec.width),
        "bit_depth": int(header["bits_per_sample"] or spec.format.size() * 8),
        "cfa_pattern": None,
        "black_level": [0.0, 0.0, 0.0],
        "white_level": white,
        "white_balance": None,
        "exposure_s": header["exposure_s"],
        "capture_time": header["capture_time"],
    }


def _decode_oiio(path):
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    if not inp:
        raise ValueError(f"cannot read image file {path}: {oiio.geterror()}")
    try:
        spec = inp.spec()
        data = inp.read_image(0, 0, 0, spec.nchannels, spec.format)
        if data is None:
            raise ValueError(f"cannot read pixels of {path}: {inp.geterror()}")
    finally:
        inp.close()
    data = np.asarray(data)
    if data.ndim == 2:
        data = data[:, :, None]
    if data.dtype.kind in "ui":
        white = float(np.iinfo(data.dtype).max)
        image = data.astype(np.float32) / np.float32(white)
    elif data.dtype.kind == "f":
        white = 1.0
        image = data.astype(np.float32, copy=False)
    else:
        raise ValueError(f"{path}: unsupported pixel type {data.dtype}")
    nch = image.shape[2]
    if nch in (1, 2):  # grey (+ alpha)
        image = np.repeat(image[:, :, :1], 3, axis=2)
    elif nch > 3:  # drop alpha / extra channels
        image = np.ascontiguousarray(image[:, :, :3])
    info = _oiio_info(path, spec)
    return image, info


def _check_path(path):
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"frame file {path} does not exist (check the manifest's root and file globs)")
    return path


def read_frame(path, *, return_info=False, mosaics=None):
    """Decode one frame to linear float32 RGB (black = 0, white level = 1).

    Parameters
    ----------
    path : str or Path
        Camera RAW (see :data:`RAW_EXTENSIONS`) or any image OpenImageIO reads.
    return_info : bool, optional
        Also return the frame's metadata (as :func:`frame_info`).
    mosaics : shadowcam.mosaic_reader.MosaicReader, optional
        Reads RAW mosaics of the frame's sweep (directly where verified
        exact); default: rawpy.

    Returns
    -------
    image : (H, W, 3) float32 ndarray
        Rows x cols x (R, G, B). RAW noise may make values slightly negative;
        they are kept (clipping would bias dark pixels).
    info : dict
        Only if `return_info`.
    """
    path = _check_path(path)
    image, info = _decode_raw(path, mosaics) if is_raw(path) else _decode_oiio(path)
    return (image, info) if return_info else image


def frame_info(path):
    """Return metadata of a frame.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    dict
        ``path``, ``decoder``, ``height``, ``width``, ``bit_depth``,
        ``cfa_pattern`` (RAW, else None), ``black_level`` ([R, G, B] in file
        units), ``white_level`` (file units), ``white_balance`` (as-shot
        [R, G, B] multipliers with G = 1, not applied; None if unknown),
        ``exposure_s`` and ``capture_time`` (ISO 8601 with sub-seconds if the
        file has them; None if absent).
    """
    path = _check_path(path)
    if is_raw(path):
        return _decode_raw(path)[1]  # rawpy unpacks the data anyway
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    if not inp:
        raise ValueError(f"cannot read image file {path}: {oiio.geterror()}")
    spec = inp.spec()
    inp.close()
    return _oiio_info(path, spec)


def iter_frames(paths):
    """Decode frames one at a time, checking they all have the first one's size.

    RAW mosaics are read through one :class:`~shadowcam.mosaic_reader.MosaicReader`
    for the sequence (directly from the DNG data when that is verified exact).

    Parameters
    ----------
    paths : sequence of str or Path

    Yields
    ------
    path : Path
    image : (H, W, 3) float32 ndarray
    info : dict
        As :func:`frame_info`.

    Raises
    ------
    ValueError
        If a frame's size differs from the first frame's (naming both files).
    """
    first = None
    mosaics = None
    for path in paths:
        if mosaics is None and is_raw(path):
            from shadowcam.mosaic_reader import MosaicReader

            mosaics = MosaicReader(_check_path(path))
        image, info = read_frame(path, return_info=True, mosaics=mosaics)
        if first is None:
            first = (Path(path), image.shape)
        elif image.shape != first[1]:
            raise ValueError(
                f"frame {path} has size {image.shape[0]}x{image.shape[1]} (rows x cols) but the "
                f"first frame {first[0]} has {first[1][0]}x{first[1][1]}; all frames of a sweep "
                "must have the same size (remove or crop the odd file)"
            )
        yield Path(path), image, info
