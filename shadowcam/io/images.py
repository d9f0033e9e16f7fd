"""Image writers: linear EXR and 8-bit PNG previews, all atomic.

Every writer writes to a temporary file next to the target and renames it
into place, so a failure never leaves a half-written output behind.

Offers
------
write_exr : linear float32 OpenEXR via OpenImageIO (NaN kept).
read_image : any OpenImageIO-readable image as a float32 ``(rows, cols, channel)`` array.
white_point : the linear value shown as white (percentile of the brightest channel).
srgb_encode : linear [0, 1] -> sRGB-encoded [0, 1].
tone_map : linear colour image -> display RGB in [0, 1] (sRGB), holes in a neutral colour;
    the one tone map of the PNG previews and the report figures.
preview_rgb8 : `tone_map` quantised to 8 bits.
colormap_rgb8 : scalar map -> 8-bit colour-mapped preview, NaN in grey.
write_png : write an 8-bit image as PNG.
write_png_preview : `preview_rgb8` + `write_png`.
write_scalar_preview : `colormap_rgb8` + `write_png`.
"""

from pathlib import Path

import numpy as np

from shadowcam._shared.atomic import atomic_path
from shadowcam._shared.validation import check_array, check_in_interval, check_positive

#: display colour of holes (NaN) in previews, sRGB-encoded [0, 1] (mid grey)
HOLE_COLOUR = (0.5, 0.5, 0.5)


def _as_hwc(image, name="image"):
    arr = np.asarray(image)
    if arr.ndim == 2:
        arr = arr[..., None]
    if arr.ndim != 3 or arr.shape[2] < 1:
        raise ValueError(f"{name}: expected (rows, cols[, channel]), got shape {np.shape(image)}")
    return arr


def _write_oiio(path, pixels, typedesc, channel_names=None):
    import OpenImageIO as oiio

    rows, cols, n_ch = pixels.shape
    spec = oiio.ImageSpec(cols, rows, n_ch, typedesc)
    if channel_names is not None:
        spec.channelnames = tuple(channel_names)
    with atomic_path(path) as tmp:
        out = oiio.ImageOutput.create(str(tmp))
        if out is None:
            raise ValueError(f"path: no image writer for {path}: {oiio.geterror()}")
        ok = out.open(str(tmp), spec) and out.write_image(np.ascontiguousarray(pixels))
        err = out.geterror()
        out.close()
        if not ok:
            raise ValueError(f"path: could not write {path}: {err}")


def write_exr(path, image, *, channel_names=None):
    """Write a linear float image as OpenEXR (float32, NaN kept).

    Parameters
    ----------
    path : str or Path
    image : (rows, cols[, channel]) ndarray
    channel_names : sequence of str, optional
        Default ``R, G, B[, A]`` for 3/4 channels, ``Y`` for one.
    """
    arr = _as_hwc(image).astype(np.float32)
    if channel_names is None:
        channel_names = {1: ("Y",), 3: ("R", "G", "B"), 4: ("R", "G", "B", "A")}.get(arr.shape[2])
    _write_oiio(path, arr, "float", channel_names)


def read_image(path):
    """Read an image with OpenImageIO.

    Returns
    -------
    (rows, cols, channel) float32 ndarray
        Float formats as stored; integer formats scaled to [0, 1] by OpenImageIO.
    """
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise FileNotFoundError(f"cannot read image {path}: {oiio.geterror()}")
    try:
        pixels = inp.read_image(0, 0, 0, inp.spec().nchannels, "float")
    finally:
        inp.close()
    if pixels is None:
        raise ValueError(f"path: could not decode {path}")
    return np.asarray(pixels, dtype=np.float32).reshape(inp.spec().height, inp.spec().width, -1)


def white_point(image, *, percentile=99.0):
    """The linear value shown as white: the `percentile` of each finite pixel's brightest channel.

    Parameters
    ----------
    image : (rows, cols[, channel]) ndarray
        Linear values; NaN ignored.
    percentile : float, keyword-only

    Returns
    -------
    float
        Positive scale (1.0 if the image has no positive finite value).
    """
    check_in_interval(percentile, "percentile", 0, 100)
    arr = _as_hwc(image)
    finite = np.all(np.isfinite(arr), axis=2)
    peak = arr[finite].max(axis=1) if finite.any() else np.zeros(0)
    peak = peak[peak > 0]
    return float(np.percentile(peak, percentile)) if peak.size else 1.0


def srgb_encode(linear):
    """sRGB transfer function (IEC 61966-2-1) of values clipped to [0, 1]."""
    x = np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def _to_uint8(display, holes=None, hole_colour=HOLE_COLOUR):
    out = np.round(np.clip(display, 0, 1) * 255).astype(np.uint8)
    if holes is not None:
        out[holes] = np.round(np.asarray(hole_colour) * 255).astype(np.uint8)
    return out


def tone_map(image, *, percentile=99.0, scale=None, hole_colour=HOLE_COLOUR):
    """Display RGB of a linear image: divided by its white point, sRGB-encoded.

    Parameters
    ----------
    image : (rows, cols[, channel]) ndarray
        Linear colour (1 channel -> grey, 3 -> RGB; extra channels dropped).
    percentile : float, keyword-only
        Exposure: this percentile of the brightest channel maps to white (:func:`white_point`).
    scale : float, optional
        Explicit white point (overrides `percentile`).
    hole_colour : (3,) sequence of float
        sRGB-encoded colour of pixels with a non-finite channel.

    Returns
    -------
    (rows, cols, 3) float64 ndarray
        Values in [0, 1].
    """
    arr = _as_hwc(image).astype(np.float64)
    arr = np.repeat(arr, 3, axis=2) if arr.shape[2] == 1 else arr[..., :3]
    if arr.shape[2] != 3:
        raise ValueError(f"image must have 1 or >= 3 channels; got {arr.shape[2]}")
    holes = ~np.all(np.isfinite(arr), axis=2)
    scale = white_point(arr, percentile=percentile) if scale is None else float(scale)
    check_positive(scale, "scale")
    display = srgb_encode(np.nan_to_num(arr / scale, nan=0.0))
    display[holes] = hole_colour
    return display


def preview_rgb8(image, **options):
    """8-bit sRGB preview of a linear image: :func:`tone_map` (same options) quantised.

    Returns
    -------
    (rows, cols, 3) uint8 ndarray
    """
    return _to_uint8(tone_map(image, **options))


def colormap_rgb8(values, *, cmap="viridis", vmin=None, vmax=None, nan_colour=HOLE_COLOUR):
    """8-bit colour-mapped preview of a scalar map (e.g. a shadow-time map).

    Parameters
    ----------
    values : (rows, cols) ndarray
    cmap : str, keyword-only
        Matplotlib colormap name.
    vmin, vmax : float, optional
        Colour range; default the 1st / 99th percentile of the finite values.
    nan_colour : (3,) sequence of float
        Colour of NaN pixels.

    Returns
    -------
    (rows, cols, 3) uint8 ndarray
    """
    from matplotlib import colormaps

    arr = np.asarray(values, dtype=np.float64)
    check_array(arr, "values", ndim=2)
    if cmap not in colormaps:
        raise ValueError(f"cmap: unknown colormap {cmap!r}")
    finite = np.isfinite(arr)
    if vmin is None or vmax is None:
        lo, hi = np.percentile(arr[finite], [1, 99]) if finite.any() else (0.0, 1.0)
        vmin = lo if vmin is None else vmin
        vmax = hi if vmax is None else vmax
    span = vmax - vmin if vmax > vmin else 1.0
    norm = np.clip((np.where(finite, arr, vmin) - vmin) / span, 0, 1)
    rgb = colormaps[cmap](norm)[..., :3]
    return _to_uint8(rgb, ~finite, nan_colour)


def write_png(path, rgb8):
    """Write an 8-bit ``(rows, cols, 3)`` (or single-channel) image as PNG."""
    arr = _as_hwc(rgb8, "rgb8")
    if arr.dtype != np.uint8:
        raise ValueError(f"rgb8 must be uint8; got {arr.dtype}")
    _write_oiio(path, arr, "uint8")


def write_png_preview(path, image, **options):
    """Write the `preview_rgb8` of a linear image as PNG (options as there)."""
    write_png(path, preview_rgb8(image, **options))


def write_scalar_preview(path, values, **options):
    """Write the `colormap_rgb8` of a scalar map as PNG (options as there)."""
    write_png(path, colormap_rgb8(values, **options))
