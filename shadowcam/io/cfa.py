"""Colour filter arrays (Bayer mosaics): patterns, per-site constants, bilinear demosaic.

Pure functions on arrays; the file readers are :mod:`shadowcam.io.raw_mosaic`
(rawpy) and :mod:`shadowcam.io.mosaic_reader` (direct DNG reads).

Offers
------
bayer_pattern : the 2x2 CFA pattern ("RGGB", ...) from rawpy's description.
site_constants : per-site constants of the top-left 2x2 block as a full-size mosaic map.
opencv_bayer_code : the OpenCV ``COLOR_Bayer*2RGB`` code for a CFA pattern.
demosaic_bilinear : bilinear demosaic of an integer Bayer mosaic with OpenCV.
"""

import cv2
import numpy as np

from shadowcam._shared.validation import check_in

_CHANNEL_OF_LETTER = {"R": 0, "G": 1, "B": 2}
_RGB = "RGB"

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
        raise ValueError(f"values must be (2, 2) per-site constants; got shape {values.shape}")
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
    check_in(pattern, "pattern", ("RGGB", "BGGR", "GRBG", "GBRG"))
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
    rgb, scale = demosaic_scaled(mosaic, pattern=pattern, max_value=max_value)
    out = rgb.astype(np.float32)
    if scale > 1:
        out /= np.float32(scale)
    return out


def demosaic_scaled(mosaic, *, pattern, max_value):
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


def site_map(values, shape, pattern, max_value):
    """Per-site constants (2x2 array) as a demosaiced (M, N, 3) map, or (3,) if uniform."""
    values = np.asarray(values, dtype=np.float64).reshape(2, 2)
    if np.all(values == values.flat[0]):
        return np.full(3, values.flat[0], dtype=np.float32)
    return demosaic_bilinear(site_constants(values, shape).astype(np.uint16), pattern=pattern, max_value=max_value)
