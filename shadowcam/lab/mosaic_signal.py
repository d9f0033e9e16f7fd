"""The dip tracker's signal straight from a Bayer mosaic, without demosaicking each frame.

The tracker follows the channel sum ``R + G + B`` of each pixel. With the
bilinear demosaic of :func:`shadowcam.io.decode.read_frame` that sum is a fixed
3x3 filter of the normalised mosaic ``(DN - black) / (white - black)``, which
depends only on whether the pixel is a green site:

* red or blue site: own value + 1/4 of the 4 edge neighbours + 1/4 of the 4
  corner neighbours;
* green site: own value + 1/2 of the 4 edge neighbours.

(Each channel of the bilinear demosaic is the channel's samples filtered by
``[[1, 2, 1], [2, 4, 2], [1, 2, 1]] / 4`` for red and blue, and by
``[[0, 1, 0], [1, 4, 1], [0, 1, 0]] / 4`` for green, with mirrored borders.)
So a RAW sweep is tracked from one float32 plane per frame computed in one
pass over the mosaic, instead of a demosaiced ``(H, W, 3)`` frame; and since
the demosaic is linear, the per-channel sums over the sweep (the pixels'
colour) are the demosaic of the per-site sums of the mosaic, computed once.

Offers
------
mosaic_signal : channel-sum signal of one mosaic frame (compiled, one pass), with saturation.
bilinear_channels : bilinear demosaic of a float mosaic (numpy; once per sweep).
"""

import numba as nb
import numpy as np
from scipy import ndimage

from shadowcam.io.cfa import site_constants

_RED_BLUE_KERNEL = np.array([[1, 2, 1], [2, 4, 2], [1, 2, 1]], np.float64) / 4
_GREEN_KERNEL = np.array([[0, 1, 0], [1, 4, 1], [0, 1, 0]], np.float64) / 4


def _check_pattern(pattern):
    if not isinstance(pattern, str) or sorted(pattern) != ["B", "G", "G", "R"]:
        raise ValueError(f"pattern must be a Bayer pattern such as 'RGGB'; got {pattern!r}")


@nb.njit(cache=True)
def _load_row(mosaic, r, scale, offset, level, norm, clip, site_sum):
    """Normalise mosaic row `r` into ``norm[1:-1]`` with mirrored ends; flag clipped sites in `clip`.

    The row is added to `site_sum` unless that is empty.
    """
    cols = mosaic.shape[1]
    sc, off = scale[r & 1], offset[r & 1]
    for j in range(cols):
        v = np.float32(mosaic[r, j]) * sc[j] + off[j]
        norm[j + 1] = v
        clip[j + 1] = v >= level
    if site_sum.shape[0]:
        for j in range(cols):
            site_sum[r, j] += mosaic[r, j]
    norm[0], norm[cols + 1] = norm[2], norm[cols - 1]  # OpenCV's BORDER_REFLECT_101
    clip[0], clip[cols + 1] = clip[2], clip[cols - 1]


@nb.njit(cache=True)
def _signal_kernel(mosaic, scale, offset, edge_weight, corner_weight, level, out, saturated, site_sum):
    """Fill `out` with the channel-sum signal of `mosaic`; OR clipped footprints into `saturated`.

    Rows are normalised once into a ring of three padded rows; per-column
    constants ``(2, N)`` (by row parity) keep the inner loops branch-free.
    """
    rows, cols = mosaic.shape
    norm = np.empty((3, cols + 2), np.float32)  # rows i - 1, i, i + 1 (slot row % 3), mirrored ends
    clip = np.empty((3, cols + 2), np.uint8)
    _load_row(mosaic, 0, scale, offset, level, norm[0], clip[0], site_sum)
    _load_row(mosaic, 1, scale, offset, level, norm[1], clip[1], site_sum)
    for i in range(rows):
        if 1 <= i < rows - 1:
            _load_row(mosaic, i + 1, scale, offset, level, norm[(i + 1) % 3], clip[(i + 1) % 3], site_sum)
        up = (i - 1) % 3 if i >= 1 else 1  # row -1 mirrors row 1, row M mirrors row M - 2
        down = (i + 1) % 3 if i + 1 < rows else up
        above, here, below = norm[up], norm[i % 3], norm[down]
        c_above, c_here, c_below = clip[up], clip[i % 3], clip[down]
        we, wc = edge_weight[i & 1], corner_weight[i & 1]
        for j in range(cols):
            edge = (above[j + 1] + below[j + 1]) + (here[j] + here[j + 2])
            corner = (above[j] + above[j + 2]) + (below[j] + below[j + 2])
            out[i, j] = here[j + 1] + we[j] * edge + wc[j] * corner
            edge_clip = c_here[j + 1] | c_above[j + 1] | c_below[j + 1] | c_here[j] | c_here[j + 2]
            corner_clip = c_above[j] | c_above[j + 2] | c_below[j] | c_below[j + 2]
            saturated[i, j] |= edge_clip | (corner_clip & (wc[j] > 0))


def mosaic_signal(mosaic, *, pattern, black, white, saturation_level=0.999, out=None, saturated=None,
                  site_sum=None):
    """Channel sum ``R + G + B`` of the bilinear demosaic of one mosaic frame, in one pass.

    Equals ``read_frame(path).sum(axis=2)`` for the file's mosaic up to
    float32 rounding (and, where the sites' white levels differ, up to
    normalising each site before rather than after interpolation).

    Parameters
    ----------
    mosaic : (M, N) ndarray of unsigned int
        Raw mosaic in file units (DN); M, N >= 2.
    pattern : str
        CFA pattern of the top-left 2x2 block, e.g. ``"RGGB"``.
    black, white : (2, 2) array_like
        Black and white level of each site of the top-left 2x2 block.
    saturation_level : float, optional
        Normalised site value at or above which a site is clipped.
    out : (M, N) float32 ndarray, optional
        Where to write the signal (e.g. a row of the tracker's block).
    saturated : (M, N) bool ndarray, optional
        OR-ed in place with whether any site the pixel's interpolation uses
        is clipped (a new array if not given).
    site_sum : (M, N) int64 ndarray, optional
        The mosaic (DN) is added to it in place: exact per-site sums over
        frames, whatever their order.

    Returns
    -------
    signal : (M, N) float32 ndarray
        Linear, black 0, each channel's white 1 (so up to 3).
    saturated : (M, N) bool ndarray
    """
    mosaic = np.asarray(mosaic)
    if mosaic.ndim != 2 or min(mosaic.shape) < 2 or mosaic.dtype.kind != "u":
        raise ValueError(f"mosaic must be a 2-D unsigned-integer array of at least 2x2, got "
                         f"{mosaic.dtype} {mosaic.shape}")
    _check_pattern(pattern)
    black = np.asarray(black, np.float64).reshape(2, 2)
    span = np.asarray(white, np.float64).reshape(2, 2) - black
    if np.any(span <= 0):
        raise ValueError(f"white {np.asarray(white).tolist()} must be above black {black.tolist()} at every site")
    out = np.empty(mosaic.shape, np.float32) if out is None else out
    saturated = np.zeros(mosaic.shape, bool) if saturated is None else saturated
    checks = [("out", out, np.float32), ("saturated", saturated, np.bool_)]
    if site_sum is not None:
        checks.append(("site_sum", site_sum, np.int64))
    for name, array, dtype in checks:
        if array.shape != mosaic.shape or array.dtype != dtype or not array.flags.c_contiguous:
            raise ValueError(f"{name} must be a C-contiguous {np.dtype(dtype)} array of shape {mosaic.shape}")
    cols = mosaic.shape[1]
    scale = site_constants((1.0 / span), (2, cols)).astype(np.float32)
    offset = site_constants(-black / span, (2, cols)).astype(np.float32)
    green = site_constants(np.array([ch == "G" for ch in pattern]).reshape(2, 2), (2, cols)) > 0
    edge_weight = np.where(green, 0.5, 0.25).astype(np.float32)
    corner_weight = np.where(green, 0.0, 0.25).astype(np.float32)
    _signal_kernel(np.ascontiguousarray(mosaic), scale, offset, edge_weight, corner_weight,
                   np.float32(saturation_level), out, saturated.view(np.uint8),
                   np.zeros((0, 0), np.int64) if site_sum is None else site_sum)
    return out, saturated


def bilinear_channels(values, *, pattern):
    """Bilinear demosaic of a float mosaic (same weights and borders as the RAW decoder).

    Parameters
    ----------
    values : (M, N) float ndarray
        One value per site, e.g. normalised per-site sums over a sweep.
    pattern : str
        CFA pattern of the top-left 2x2 block.

    Returns
    -------
    (M, N, 3) float64 ndarray
        R, G, B.
    """
    values = np.asarray(values, np.float64)
    if values.ndim != 2 or min(values.shape) < 2:
        raise ValueError(f"values must be a 2-D mosaic of at least 2x2; got shape {values.shape}")
    _check_pattern(pattern)
    letters = site_constants(np.arange(4).reshape(2, 2), values.shape).astype(int)
    out = np.empty(values.shape + (3,))
    for channel, letter in enumerate("RGB"):
        sites = np.isin(letters, [k for k, ch in enumerate(pattern) if ch == letter])
        kernel = _GREEN_KERNEL if letter == "G" else _RED_BLUE_KERNEL
        out[..., channel] = ndimage.correlate(np.where(sites, values, 0.0), kernel, mode="mirror")
    return out
