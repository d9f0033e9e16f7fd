"""Frame decoding: camera RAW, TIFF, PNG and EXR to linear float32 RGB.

Every frame comes out as a ``(H, W, 3)`` float32 array, linear, with black = 0
and the sensor's (or file format's) white level = 1. Nothing else is done: no
gamma, no auto-brightness, no white balance, no colour matrix (the as-shot
white balance is *reported* by :func:`frame_info`, never applied).

* Camera RAW (``.dng``, ``.cr2``, ``.nef``, ...) is read with rawpy:
  ``raw_image_visible`` minus ``black_level_per_channel`` at each CFA site,
  divided by ``white_level - black``, demosaiced bilinearly with OpenCV.
  :func:`iter_frames` reads a sequence's DNG mosaics directly where that is
  verified equal to rawpy (:mod:`shadowcam.io.mosaic_reader`).
* TIFF / PNG / EXR / ... are read with OpenImageIO in their native type;
  integer types are divided by the type's maximum (a 16-bit PNG by 65535),
  floating-point data are taken as they are.

Offers
------
read_frame : one frame as a (H, W, 3) float32 array (optionally with its info).
header_metadata : exposure and capture time from the file header only
    (:mod:`shadowcam.io.file_header`).
frame_info : size, bit depth, black/white levels, white balance, exposure and
    capture time of a frame, without decoding more than needed.
iter_frames : decode several frames one at a time, checking they share a size.
frame_blocks : a callable streaming decoded frames in blocks of bounded size, anew on each call.
read_stack : decode frame files into one (N, H, W, 3) float32 stack.
BLOCK_BYTES : the most decoded frames one block of :func:`frame_blocks` holds, in bytes.
mosaic_image : linear float32 RGB of a Bayer mosaic and its levels (demosaic + levels).
iter_mosaics : read several RAW frames' mosaics one at a time, checking they share a size and CFA.

The Bayer maths are in :mod:`shadowcam.io.cfa`, the rawpy mosaic read in
:mod:`shadowcam.io.raw_mosaic`.
"""

import logging
import math
from pathlib import Path

import numpy as np

from shadowcam.io.cfa import demosaic_scaled, site_map
from shadowcam.io.file_header import header_metadata
from shadowcam.io.mosaic_reader import MosaicReader
from shadowcam.io.raw_mosaic import check_frame_path, is_raw, read_mosaic

log = logging.getLogger(__name__)


# ---------------------------------------------------------------------------
# decoders




def _normalise_in_place(image, black, span):
    """``image = (image - black) / span`` in place; per-channel (3,) constants as scalars.

    numpy broadcasts a (3,) operand over the last axis with a slow inner loop
    of length 3 (far slower than a scalar; ``docs/benchmarks.md``), so equal constants are applied as
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




def mosaic_image(mosaic, *, cfa_pattern, black_sites, white_sites):
    """Linear float32 RGB of a Bayer mosaic: bilinear demosaic, then black = 0, white level = 1.

    Parameters
    ----------
    mosaic : (M, N) ndarray of unsigned int
        Raw mosaic in DN (M, N >= 3), its top-left 2x2 block of pattern `cfa_pattern`.
    cfa_pattern : {"RGGB", "BGGR", "GRBG", "GBRG"}
    black_sites, white_sites : (2, 2) array_like
        Black and white levels of the top-left 2x2 block's sites, DN.

    Returns
    -------
    (M, N, 3) float32 ndarray
        ``(DN - black) / (white - black)`` at each CFA site's own channel (exact:
        integers below 2**24), bilinear in between. Each output pixel depends
        only on the mosaic's 3x3 neighbourhood, so a window of the mosaic that
        starts on even rows and cols and extends one pixel beyond the pixels
        wanted (or reaches the mosaic's border) gives them exactly.
    """
    black_sites = np.asarray(black_sites, dtype=np.float64).reshape(2, 2)
    white_sites = np.asarray(white_sites, dtype=np.float64).reshape(2, 2)
    vmax = int(white_sites.max())
    rgb, k = demosaic_scaled(mosaic, pattern=cfa_pattern, max_value=vmax)
    # (k * DN - k * black) / (k * (white - black)): exact at each CFA site's own
    # channel (integers below 2**24), computed in place on one float32 buffer
    shape = mosaic.shape
    black = site_map(black_sites, shape, cfa_pattern, vmax) * np.float32(k)
    span = site_map(white_sites, shape, cfa_pattern, vmax) * np.float32(k) - black
    image = rgb.astype(np.float32)
    _normalise_in_place(image, black, span)
    return image


def _raw_info(path, shape, levels):
    """Metadata of a RAW frame (as :func:`frame_info`) from its mosaic shape and levels."""
    pattern, black_sites, white_sites = levels["cfa_pattern"], levels["black_sites"], levels["white_sites"]
    header = header_metadata(path)
    bits = header["bits_per_sample"] or int(math.ceil(math.log2(white_sites.max() + 1)))
    return {
        "path": str(path),
        "decoder": f"{levels['decoder']} + OpenCV bilinear demosaic (linear, no white balance)",
        "height": int(shape[0]),
        "width": int(shape[1]),
        "bit_depth": int(bits),
        "cfa_pattern": pattern,
        "black_level": [float(np.mean(black_sites[np.array(list(pattern)).reshape(2, 2) == c])) for c in "RGB"],
        "white_level": float(white_sites.max()),
        "white_balance": levels["white_balance"],
        "exposure_s": header["exposure_s"],
        "capture_time": header["capture_time"],
    }


def _decode_raw(path, mosaics=None):
    mosaic, levels = read_mosaic(path) if mosaics is None else mosaics.read(path)
    image = mosaic_image(mosaic, cfa_pattern=levels["cfa_pattern"], black_sites=levels["black_sites"],
                         white_sites=levels["white_sites"])
    return image, _raw_info(path, mosaic.shape, levels)


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




def read_frame(path, *, return_info=False, mosaics=None):
    """Decode one frame to linear float32 RGB (black = 0, white level = 1).

    Parameters
    ----------
    path : str or Path
        Camera RAW (see :data:`RAW_EXTENSIONS`) or any image OpenImageIO reads.
    return_info : bool, optional
        Also return the frame's metadata (as :func:`frame_info`).
    mosaics : shadowcam.io.mosaic_reader.MosaicReader, optional
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
    path = check_frame_path(path)
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
    path = check_frame_path(path)
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

    RAW mosaics are read through one :class:`~shadowcam.io.mosaic_reader.MosaicReader`
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
            mosaics = MosaicReader(check_frame_path(path))
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


#: the most decoded frames (float32 RGB) one block of :func:`frame_blocks` holds, in bytes
BLOCK_BYTES = 16 * 2 ** 20


def _check_frame_size(path, image, shape):
    """Raise ValueError naming `path` if `image` is not ``shape`` (rows, cols)."""
    if tuple(image.shape[:2]) != tuple(shape):
        raise ValueError(f"frame {path} has size {image.shape[0]}x{image.shape[1]} (rows x cols) but the "
                         f"capture's frames are {shape[0]}x{shape[1]}; every frame must come from one "
                         "camera at one size (remove or crop the odd file)")


def frame_blocks(paths, shape, *, block_bytes=BLOCK_BYTES):
    """A callable streaming the files' decoded frames anew on each call, in blocks.

    For passes over a sweep whose whole stack need not be held (e.g. the two passes of
    :func:`shadowcam.lab.minima.find_minima`): memory follows the frame size, not the
    number of frames.

    Parameters
    ----------
    paths : sequence of str or Path
        Files in order (decoded by :func:`iter_frames`).
    shape : (2,) tuple of int
        ``(rows, cols)`` every file must have.
    block_bytes : int
        The most bytes of decoded frames one block holds (at least one frame).

    Returns
    -------
    callable
        Each call returns an iterator of consecutive ``(t, H, W, 3)`` float32 blocks; it
        raises (when iterated) ValueError for a frame of another size than `shape`.
    """
    paths = list(paths)
    per_block = max(1, int(block_bytes) // (int(shape[0]) * int(shape[1]) * 3 * 4))

    def blocks():
        block = []
        for path, image, _ in iter_frames(paths):
            _check_frame_size(path, image, shape)
            block.append(image)
            if len(block) == per_block:
                yield np.stack(block)
                block = []
        if block:
            yield np.stack(block)

    return blocks


def read_stack(paths, *, shape=None):
    """Decode frame files into one stack, one file at a time.

    Parameters
    ----------
    paths : sequence of str or Path
        Files in order.
    shape : (2,) tuple of int, optional
        ``(rows, cols)`` every file must have (default: the first file's).

    Returns
    -------
    (N, H, W, 3) float32 ndarray
        Linear RGB (black 0, white level 1).

    Raises
    ------
    ValueError
        No paths, or a file of another size than `shape` or the first file (naming both).
    """
    paths = list(paths)
    if not paths:
        raise ValueError("paths: no frame files to read")
    stack = None
    for k, (path, image, _) in enumerate(iter_frames(paths)):
        if stack is None:
            if shape is not None:
                _check_frame_size(path, image, shape)
            stack = np.empty((len(paths), *image.shape), np.float32)
        stack[k] = image
    return stack


def iter_mosaics(paths):
    """Read RAW frames' mosaics one at a time (as :func:`iter_frames` reads them), without demosaicing.

    Parameters
    ----------
    paths : sequence of str or Path
        Camera RAW frames of one sweep.

    Yields
    ------
    path : Path
    mosaic : (M, N) uint16 ndarray
    levels : dict
        ``cfa_pattern``, ``black_sites``, ``white_sites`` (2x2, DN) ... of
        :func:`shadowcam.io.raw_mosaic.read_mosaic`.
    info : dict
        As :func:`frame_info`.

    Raises
    ------
    ValueError
        If a file is not a camera RAW, or its mosaic's size or CFA pattern differs from the first frame's.
    """
    mosaics = None
    for path in paths:
        path = check_frame_path(path)
        if not is_raw(path):
            raise ValueError(f"frame {path} is not a camera RAW file; a mosaic store needs RAW frames")
        mosaics = mosaics or MosaicReader(path)
        mosaic, levels = mosaics.read(path)
        yield path, mosaic, levels, _raw_info(path, mosaic.shape, levels)
