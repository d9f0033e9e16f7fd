"""A cloud's shade as a field over the frame: coarse blocks of the lit pixels' level, interpolated.

A lit pixel under a cloud of transmittance ``T`` reads ``(rho + T (1 - rho))`` times its lit
level times the frame's lit gain, with ``rho`` its sky share. A cloud's shadow is smooth over
many pixels, while the ridge's shadow and penumbra only ever lower a pixel below its lit level
and lie next to its core or to the ground shadowed from the start; so in a block of the frame
the ratios frame / reference of the lit pixels the ridge has not reached give the block's lit
level under the cloud there, ``gain_lit (rho + T (1 - rho))`` (:func:`block_levels`). Over a
grid of blocks that level, divided by the frame's lit gain, gives ``T = (q - rho) / (1 - rho)``.

Blocks clearly dimmed against the frame's brightest block (their level below
:data:`FULLY_LIT` of it) are under a cloud: the frame's lit gain is then the brightest block's
level (:mod:`shadowcam.outdoor.normalise`). A block with no level (sky, ground shadowed from
the start, or reached by the ridge) takes the value of the nearest block that has one. Each
pixel's ``T`` is the bilinear interpolation of the blocks' ``T`` at their centres (held constant
beyond the outer centres), computed column by column so that column strips of the frame get the
same values.

Offers
------
block_grid : the blocks of a reduced frame and their centres in full-frame pixels.
block_levels : each block's lit level (upper quartile of the lit ratios the ridge has not reached).
unclouded_blocks : the blocks that are not clearly dimmed against the brightest one.
shade_field : the blocks' transmittance ``T`` from their levels, the lit gain and ``rho``.
interpolate_field : ``T`` at every pixel ``(H, W)`` from a frame's block field.
"""

import cv2
import numpy as np

from shadowcam.outdoor.frame_kernels import block_upper_quartiles
from shadowcam.outdoor.shade import FULLY_LIT


def block_grid(shape, *, block, factor):
    """The blocks of a reduced frame.

    Parameters
    ----------
    shape : (2,) tuple of int
        ``(h, w)`` of the reduced frame (:func:`shadowcam.outdoor.registration.block_mean`).
    block : int
        Block side in reduced pixels (the last block of a row or column may be smaller).
    factor : int
        Reduction factor of the frame (full-frame pixels per reduced pixel).

    Returns
    -------
    row_edges : (By + 1,) int ndarray
        Block boundaries along rows, reduced pixels.
    col_edges : (Bx + 1,) int ndarray
    row_centres : (By,) float64 ndarray
        Block centres along rows in full-frame pixel coordinates (pixel centres at ``i + 0.5``).
    col_centres : (Bx,) float64 ndarray
    """
    block, factor = int(block), int(factor)
    if block < 1 or factor < 1:
        raise ValueError(f"block and factor must be >= 1; got {block}, {factor}")
    height, width = (int(n) for n in shape)
    row_edges = np.append(np.arange(0, height, block), height)
    col_edges = np.append(np.arange(0, width, block), width)
    row_centres = 0.5 * (row_edges[:-1] + row_edges[1:]) * factor
    col_centres = 0.5 * (col_edges[:-1] + col_edges[1:]) * factor
    return row_edges, col_edges, row_centres, col_centres


def block_levels(luma, reference_luma, *, pixels, row_edges, col_edges, reached_below, dark=None, reach=0):
    """Each block's lit level: the upper quartile of its ratios ``luma / reference_luma`` the ridge has not reached.

    The ridge's shadow core reads the sky share ``rho`` of the lit level, far below any
    cloud's ``rho + T (1 - rho)``: ratios below `reached_below` are the pixels it reached. Its
    penumbra lies within `reach` of the core and of the ground shadowed from the start
    (`dark`): those pixels are left out too. Of the rest, the upper quartile is on the lit
    pixels even where some penumbra is left (their noise moves it by two thirds of a standard
    deviation). A block whose reached pixels are a quarter or more of its lit ones, or whose
    lit pixels are fewer than a quarter of its pixels, may be mostly penumbra: no level.

    Parameters
    ----------
    luma, reference_luma : (h, w) ndarray
        The (registered, reduced) frame and the reference.
    pixels : (h, w) bool ndarray
        Pixels lit in the reference.
    row_edges, col_edges : ndarray
        :func:`block_grid`.
    reached_below : float, keyword-only
        Ratio below which a pixel counts as reached by the ridge's shadow.
    dark : (h, w) bool ndarray, optional
        Valid pixels not lit in the reference (the ground shadowed from the start).
    reach : int, optional
        Pixels within this many pixels (square) of a reached or `dark` pixel are left out.

    Returns
    -------
    (By, Bx) float64 ndarray
        NaN where the block has no level.
    """
    levels = np.full((row_edges.size - 1, col_edges.size - 1), np.nan)
    if reach > 0:  # the penumbra ahead of the core and of the ground shadowed from the start
        near = pixels & (luma < reached_below * reference_luma)
        if dark is not None:
            near |= dark
        near = near.astype(np.uint8)
        near = cv2.dilate(near, np.ones((2 * reach + 1, 2 * reach + 1), np.uint8)).astype(bool)
        pixels = pixels & ~near
    use = pixels & (reference_luma > 0)
    ratio = np.divide(luma, reference_luma, out=np.zeros(use.shape, np.result_type(luma, reference_luma)), where=use)
    above = use & (ratio >= reached_below)
    block_upper_quartiles(ratio, use, above, np.asarray(row_edges, dtype=np.int64),
                          np.asarray(col_edges, dtype=np.int64), levels)  # np.percentile(ratios, 75) per block
    return levels


def unclouded_blocks(levels):
    """Blocks whose level is at least :data:`FULLY_LIT` of the brightest block's.

    Parameters
    ----------
    levels : (By, Bx) ndarray
        :func:`block_levels` (NaN: no level).

    Returns
    -------
    (By, Bx) bool ndarray
        False where the level is NaN; all False when no block has a level.
    """
    levels = np.asarray(levels, dtype=np.float64)
    known = np.isfinite(levels)
    if not known.any():
        return known
    return known & (levels >= FULLY_LIT * np.max(levels[known]))


def _fill_nearest(values):
    """NaN blocks take the value of the nearest finite block (grid distance; the first on ties)."""
    known = np.isfinite(values)
    if known.all() or not known.any():
        return values
    rows, cols = np.indices(values.shape)
    kr, kc = rows[known], cols[known]
    missing = np.flatnonzero(~known.ravel())
    distance = (rows.ravel()[missing, None] - kr[None, :]) ** 2 + (cols.ravel()[missing, None] - kc[None, :]) ** 2
    out = values.copy()
    out.ravel()[missing] = values[known][np.argmin(distance, axis=1)]
    return out


def shade_field(levels, gain_lit, *, shadow_ratio):
    """The blocks' cloud transmittance ``T`` per frame.

    Parameters
    ----------
    levels : (T, By, Bx) ndarray
        :func:`block_levels` of every frame (NaN: no level).
    gain_lit : (T,) ndarray
        The frames' lit gains.
    shadow_ratio : float, keyword-only
        The lit pixels' sky share ``rho`` (the first pass's median shadow-to-lit ratio).

    Returns
    -------
    (T, By, Bx) float32 ndarray
        ``(levels / gain_lit - rho) / (1 - rho)`` clipped to ``[0.05, 1]`` where below
        :data:`FULLY_LIT` (a clear cloud), else 1; blocks without a level take the nearest
        block's value in the frame, 1 where no block of the frame has one.
    """
    levels = np.asarray(levels, dtype=np.float64)
    gain = np.asarray(gain_lit, dtype=np.float64)
    if levels.ndim != 3 or gain.shape != levels.shape[:1]:
        raise ValueError(f"levels {levels.shape} must be (T, By, Bx) and gain_lit {gain.shape} (T,)")
    rho = float(np.clip(shadow_ratio, 0.0, 0.99))
    with np.errstate(divide="ignore", invalid="ignore"):
        shade = (levels / gain[:, None, None] - rho) / (1.0 - rho)
    shade = np.where(shade < FULLY_LIT, np.clip(shade, 0.05, 1.0), np.where(np.isfinite(shade), 1.0, np.nan))
    out = np.ones(levels.shape, dtype=np.float32)
    for k in range(levels.shape[0]):
        out[k] = np.nan_to_num(_fill_nearest(shade[k]), nan=1.0)
    return out


def _linear_weights(centres, coords):
    """Indices ``i`` and weights ``w`` with ``value = f[i] (1 - w) + f[i + 1] w`` (held beyond the ends)."""
    if centres.size == 1:
        return np.zeros(coords.size, dtype=np.int64), np.zeros(coords.size, dtype=np.float32)
    index = np.clip(np.searchsorted(centres, coords, side="right") - 1, 0, centres.size - 2)
    weight = np.clip((coords - centres[index]) / (centres[index + 1] - centres[index]), 0.0, 1.0)
    return index, weight.astype(np.float32)


def interpolate_field(field, *, row_centres, col_centres, shape, col_offset=0):
    """One frame's ``T`` at every pixel.

    Parameters
    ----------
    field : (By, Bx) ndarray
        :func:`shade_field` of the frame.
    row_centres, col_centres : (By,), (Bx,) ndarray
        The blocks' centres in full-frame pixel coordinates (:func:`block_grid`).
    shape : (2,) tuple of int
        ``(H, W)`` of the (part of the) frame wanted.
    col_offset : int, optional
        Full-frame column of the first column wanted (a column strip).

    Returns
    -------
    (H, W) float32 ndarray
        Bilinear in the blocks' centres, held constant beyond the outer ones; each column's
        values depend on its own full-frame coordinate only.
    """
    field = np.asarray(field, dtype=np.float32)
    rows, cols = np.asarray(row_centres, dtype=np.float64), np.asarray(col_centres, dtype=np.float64)
    if field.shape != (rows.size, cols.size):
        raise ValueError(f"field {field.shape} does not match the centres ({rows.size}, {cols.size})")
    height, width = (int(n) for n in shape)
    ri, rw = _linear_weights(rows, np.arange(height) + 0.5)
    ci, cw = _linear_weights(cols, np.arange(width) + 0.5 + int(col_offset))
    upper = field[np.minimum(ri + 1, rows.size - 1)]
    by_row = field[ri] * (1 - rw)[:, None] + upper * rw[:, None]
    right = by_row[:, np.minimum(ci + 1, cols.size - 1)]
    return by_row[:, ci] * (1 - cw)[None, :] + right * cw[None, :]
