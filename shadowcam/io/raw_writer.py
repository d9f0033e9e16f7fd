"""Writers for rendered frames: RGGB Bayer DNG and 16-bit linear RGB TIFF.

Offers
------
write_dng : write a Bayer CFA mosaic as a DNG (uncompressed or lossless JPEG) that rawpy decodes exactly.
write_tiff16 : write a (rows, cols, 3) uint16 linear RGB image as a TIFF.
format_capture_time : EXIF ``YYYY:MM:DD HH:MM:SS`` string of a ``datetime``.
format_subseconds : EXIF ``SubSecTimeOriginal`` digits of a ``datetime`` (ms or us).

Both writers take the destination path first-class (this is an I/O module) and do no maths.
The DNG is written with pidng: one uncompressed tile, ``BitsPerSample`` = the sensor bit
depth (8, 10 and 12 bit packed MSB-first as DNG requires; 14-bit data are stored in
16-bit samples because pidng's 14-bit packer is broken; WhiteLevel tells the depth),
``CFAPattern`` RGGB, ``BlackLevel``, ``WhiteLevel``, identity ``ColorMatrix1`` and unit
``AsShotNeutral`` (the data are linear renderer RGB, not a real sensor's colour space).
"""

import datetime
import sys
from pathlib import Path
from unittest import mock

import numpy as np

from shadowcam._shared.validation import check_in, check_positive

#: sensor bit depth -> stored BitsPerSample (pidng's 14-bit packer is broken, so 14-bit
#: data are stored in 16-bit samples; WhiteLevel still says 2**14 - 1)
_STORAGE_BITS = {8: 8, 10: 10, 12: 12, 14: 16, 16: 16}
_PACKABLE_BITS = tuple(_STORAGE_BITS)


def format_capture_time(when):
    """Return `when` (a ``datetime.datetime``) as an EXIF date-time string."""
    if not isinstance(when, datetime.datetime):
        raise ValueError(f"when must be a datetime.datetime; got {type(when).__name__}")
    return when.strftime("%Y:%m:%d %H:%M:%S")


def format_subseconds(when):
    """Return the sub-second part of `when` as EXIF SubSec digits: 3 digits (milliseconds)
    when that is exact, else 6 (microseconds)."""
    if not isinstance(when, datetime.datetime):
        raise ValueError(f"when must be a datetime.datetime; got {type(when).__name__}")
    us = when.microsecond
    return f"{us // 1000:03d}" if us % 1000 == 0 else f"{us:06d}"


def _lossless_jpeg_encoder():
    """pidng's lossless-JPEG encoder module, backed by imagecodecs.

    pidng imports ``ljpegCompress.pack16tolj`` when asked to compress; that C
    extension no longer works on current Pythons (``PY_SSIZE_T_CLEAN``), so the
    same function is provided from imagecodecs' LJ92 encoder: the mosaic as
    ``height`` rows of ``width`` samples (pidng passes two mosaic rows per
    JPEG row, as cameras do).
    """
    import types

    import imagecodecs

    def pack16tolj(frame, width, height, bits, *_):
        samples = np.ascontiguousarray(frame, np.uint16).reshape(int(height), int(width))
        return imagecodecs.ljpeg_encode(samples, bitspersample=int(bits))

    module = types.ModuleType("ljpegCompress")
    module.pack16tolj = pack16tolj
    return module


def write_dng(path, raw, *, bit_depth, black_level, white_level=None, capture_time=None,
              exposure_time=None, compression="none"):
    """Write a Bayer RGGB mosaic as a DNG, uncompressed or lossless-JPEG compressed.

    Parameters
    ----------
    path : str or Path
        Destination file (its name should end in ``.dng``).
    raw : (rows, cols) uint16 ndarray
        Sensor values in DN, RGGB: R at (even row, even col), B at (odd row, odd col).
        Rows and cols must be even (LibRaw refuses images narrower than about 22 pixels).
    bit_depth : int
        Stored bits per sample, one of 8, 10, 12, 14, 16; every value must fit.
    black_level : int
        Black level in DN (same for the four CFA channels).
    white_level : int, optional
        Saturation level in DN; default ``2**bit_depth - 1``.
    capture_time : datetime.datetime, optional
        Written as ``DateTimeOriginal`` and ``DateTime``, its sub-seconds as
        ``SubsecTimeOriginal`` (when not zero).
    exposure_time : float, optional
        Seconds, written as ``ExposureTime`` (a rational with denominator 10**6).
    compression : {"none", "ljpeg"}, optional
        ``ljpeg``: one lossless-JPEG (LJ92) tile, as cameras write their DNGs
        (``BitsPerSample`` is then `bit_depth`).

    Returns
    -------
    Path
        The written file.
    """
    from pidng.core import RAW2DNG, DNGTags, Tag
    from pidng.defs import CFAPattern, DNGVersion, PhotometricInterpretation

    raw = np.asarray(raw)
    if raw.ndim != 2 or raw.dtype != np.uint16:
        raise ValueError(f"raw: expected a 2-D uint16 array, got {raw.dtype} {raw.shape}")
    rows, cols = raw.shape
    if rows % 2 or cols % 2 or rows == 0:
        raise ValueError(f"raw: rows and cols must be even and positive, got {raw.shape}")
    check_in(compression, "compression", ("none", "ljpeg"))
    check_in(bit_depth, "bit_depth", _PACKABLE_BITS)
    max_value = 2**bit_depth - 1
    white_level = max_value if white_level is None else int(white_level)
    if not 0 < white_level <= max_value:
        raise ValueError(f"white_level: must be in (0, {max_value}], got {white_level}")
    if not 0 <= int(black_level) < white_level:
        raise ValueError(f"black_level must be in [0, white_level); got {black_level}")
    if int(raw.max()) > max_value:
        raise ValueError(f"raw: maximum {int(raw.max())} does not fit in {bit_depth} bits")

    tags = DNGTags()
    tags.set(Tag.ImageWidth, cols)
    tags.set(Tag.ImageLength, rows)
    tags.set(Tag.TileWidth, cols)
    tags.set(Tag.TileLength, rows)
    tags.set(Tag.Orientation, 1)
    tags.set(Tag.PhotometricInterpretation, PhotometricInterpretation.Color_Filter_Array)
    tags.set(Tag.SamplesPerPixel, 1)
    tags.set(Tag.BitsPerSample, bit_depth if compression == "ljpeg" else _STORAGE_BITS[bit_depth])
    tags.set(Tag.CFARepeatPatternDim, [2, 2])
    tags.set(Tag.CFAPattern, CFAPattern.RGGB)
    tags.set(Tag.BlackLevelRepeatDim, [1, 1])
    tags.set(Tag.BlackLevel, int(black_level))
    tags.set(Tag.WhiteLevel, white_level)
    identity = [[1, 1], [0, 1], [0, 1], [0, 1], [1, 1], [0, 1], [0, 1], [0, 1], [1, 1]]
    tags.set(Tag.ColorMatrix1, identity)
    tags.set(Tag.CalibrationIlluminant1, 21)  # D65
    tags.set(Tag.AsShotNeutral, [[1, 1], [1, 1], [1, 1]])
    tags.set(Tag.Make, "shadowcam")
    tags.set(Tag.Model, "synthetic")
    tags.set(Tag.UniqueCameraModel, "shadowcam synthetic")
    tags.set(Tag.DNGVersion, DNGVersion.V1_4)
    tags.set(Tag.DNGBackwardVersion, DNGVersion.V1_0)
    if capture_time is not None:
        stamp = format_capture_time(capture_time)
        tags.set(Tag.DateTimeOriginal, stamp)
        tags.set(Tag.DateTime, stamp)
        if capture_time.microsecond:
            tags.set(Tag.SubsecTimeOriginal, format_subseconds(capture_time))
    if exposure_time is not None:
        check_positive(exposure_time, "exposure_time")
        tags.set(Tag.ExposureTime, [[int(round(exposure_time * 1e6)), 1000000]])

    path = Path(path)
    converter = RAW2DNG()
    converter.options(tags, path=str(path.parent), compress=compression == "ljpeg")
    with mock.patch.dict(sys.modules, {"ljpegCompress": _lossless_jpeg_encoder()} if compression == "ljpeg" else {}):
        buffer = converter.convert(np.ascontiguousarray(raw))  # in memory: pidng appends .dng
    path.write_bytes(bytes(buffer))
    return path


def write_tiff16(path, image):
    """Write a linear RGB image as an uncompressed 16-bit TIFF.

    Parameters
    ----------
    path : str or Path
        Destination file.
    image : (rows, cols, 3) uint16 ndarray
        Linear values (0 = black, 65535 = white level).

    Returns
    -------
    Path
        The written file.
    """
    import tifffile

    image = np.asarray(image)
    if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint16:
        raise ValueError(
            f"image: expected a (rows, cols, 3) uint16 array, got {image.dtype} {image.shape}"
        )
    path = Path(path)
    tifffile.imwrite(path, image, photometric="rgb", compression=None, metadata=None)
    return path
