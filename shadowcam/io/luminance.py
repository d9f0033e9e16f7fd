"""Luminance of linear frames: the mean of R, G, B, from a colour image or straight from a Bayer mosaic.

The pipeline's luminance is the unweighted mean of the linear, non-white-balanced
R, G and B channels of the decoded frame. For a RAW sweep those channels are
the bilinear demosaic of the mosaic (:func:`shadowcam.io.decode.mosaic_image`:
OpenCV's bilinear interpolation of the mosaic scaled by ``k``, rounded to
integers, with the mosaic mirror-padded by two pixels, then ``(v - black) /
(white - black)`` per channel). :func:`mosaic_luminance` computes the same
value per pixel in one compiled pass over the mosaic (the interpolation's
integer sums and rounding, the per-channel normalisation and the channel mean,
in the same float32 operations in the same order), without the ``(M, N, 3)``
colour image: equal to ``channel_mean(mosaic_image(...))`` bit for bit
wherever each channel's black and white levels are the same at all its
sites (the usual case; otherwise per-site maps are demosaiced as well and
the colour path is taken).

Offers
------
channel_mean : mean over the channel axis, float32 (the pipeline's luminance).
mosaic_luminance : the luminance of a mosaic's bilinear demosaic, without the colour image.
"""

import numba as nb
import numpy as np

from shadowcam.io.cfa import _CHANNEL_OF_LETTER, site_map


def channel_mean(image):
    """Return the mean over the last (channel) axis.

    Parameters
    ----------
    image : (..., C) ndarray
        Linear colour image(s).

    Returns
    -------
    (...) float32 ndarray
    """
    image = np.asarray(image)
    if image.ndim < 3:
        raise ValueError(f"image must have a trailing channel axis (H, W, C); got shape {image.shape}")
    if image.dtype != np.float32:
        return image.mean(axis=-1, dtype=np.float32)
    # channel by channel in place: the same sums and division as ``mean`` (bit for bit)
    # at a third of the time of a reduction over a short last axis
    out = image[..., 0].copy()
    for channel in range(1, image.shape[-1]):
        out += image[..., channel]
    out /= np.float32(image.shape[-1])
    return out


@nb.njit(cache=True, inline="always")
def _reflect(i, n):
    """Index `i` in ``0 .. n-1`` by mirror reflection without repeating the edge (BORDER_REFLECT_101)."""
    if i < 0:
        return -i
    if i >= n:
        return 2 * n - 2 - i
    return i


@nb.njit(cache=True, inline="always")
def _pixel(mosaic, r, up, down, c, left, right, own, other, scale, black, span):
    """Normalised channel mean at (r, c): `own` its site's channel, `other` its row neighbours' (G sites)."""
    centre = np.int32(mosaic[r, c]) * scale
    if own != 1:  # R or B site: G from the 4 neighbours, the other from the 4 diagonals
        cross = (np.int32(mosaic[up, c]) + np.int32(mosaic[down, c]) + np.int32(mosaic[r, left])
                 + np.int32(mosaic[r, right])) * scale
        diagonal = (np.int32(mosaic[up, left]) + np.int32(mosaic[up, right]) + np.int32(mosaic[down, left])
                    + np.int32(mosaic[down, right])) * scale
        v_own, v_green, v_other = centre, (cross + 2) >> 2, (diagonal + 2) >> 2
        if own == 0:
            red, green, blue = v_own, v_green, v_other
        else:
            red, green, blue = v_other, v_green, v_own
    else:  # G site: the row neighbours' channel and the column neighbours' channel
        horizontal = ((np.int32(mosaic[r, left]) + np.int32(mosaic[r, right])) * scale + 1) >> 1
        vertical = ((np.int32(mosaic[up, c]) + np.int32(mosaic[down, c])) * scale + 1) >> 1
        green = centre
        if other == 0:
            red, blue = horizontal, vertical
        else:
            red, blue = vertical, horizontal
    total = (np.float32(red) - black[0]) / span[0]
    total += (np.float32(green) - black[1]) / span[1]
    total += (np.float32(blue) - black[2]) / span[2]
    return total / np.float32(3.0)


@nb.njit(cache=True)
def _luminance_kernel(mosaic, scale, channel_of_site, black, span, out):
    """Mean of the normalised bilinear R, G, B of ``mosaic * scale`` (OpenCV's rounding) into `out`.

    Each row's interior is one loop over consecutive columns: every pixel's
    neighbour sums are formed and the site's values picked by its column
    parity (selects, not branches), so that the loop runs on vector
    registers; the integer sums, their rounding and the float32 operations
    are those of :func:`_pixel`, which computes the two mirrored border columns.
    """
    rows, cols = mosaic.shape
    scale = np.int32(scale)
    black_r, black_g, black_b = black[0], black[1], black[2]  # scalars: `out` cannot alias them
    span_r, span_g, span_b = span[0], span[1], span[2]
    three = np.float32(3.0)
    for r in range(rows):
        up, down = _reflect(r - 1, rows), _reflect(r + 1, rows)
        colour_parity = 0 if channel_of_site[r & 1, 0] != 1 else 1  # the row's R or B sites; G between
        red_row = channel_of_site[r & 1, colour_parity] == 0
        above, here, below, row = mosaic[up], mosaic[r], mosaic[down], out[r]
        for c in range(1, cols - 1):
            centre = np.int32(here[c]) * scale
            horizontal = np.int32(here[c - 1]) + np.int32(here[c + 1])
            vertical = np.int32(above[c]) + np.int32(below[c])
            diagonal = (np.int32(above[c - 1]) + np.int32(above[c + 1]) + np.int32(below[c - 1])
                        + np.int32(below[c + 1]))
            colour = (c & 1) == colour_parity
            # the row's colour (R in an R row), G, and the other colour (from the diagonals or the column)
            same = centre if colour else (horizontal * scale + 1) >> 1
            green = ((horizontal + vertical) * scale + 2) >> 2 if colour else centre
            opposite = (diagonal * scale + 2) >> 2 if colour else (vertical * scale + 1) >> 1
            red = same if red_row else opposite
            blue = opposite if red_row else same
            total = (np.float32(red) - black_r) / span_r
            total += (np.float32(green) - black_g) / span_g
            total += (np.float32(blue) - black_b) / span_b
            row[c] = total / three
        for c in (0, cols - 1):  # the mirrored border columns
            own, other = channel_of_site[r & 1, c & 1], channel_of_site[r & 1, (c + 1) & 1]
            out[r, c] = _pixel(mosaic, r, up, down, c, _reflect(c - 1, cols), _reflect(c + 1, cols), own, other,
                               scale, black, span)


def mosaic_luminance(mosaic, *, cfa_pattern, black_sites, white_sites):
    """Luminance (mean of R, G, B) of a Bayer mosaic's linear bilinear demosaic, without the colour image.

    Parameters
    ----------
    mosaic : (M, N) ndarray of unsigned int
    cfa_pattern, black_sites, white_sites
        As :func:`shadowcam.io.decode.mosaic_image` (the mosaic in DN, M, N >= 3,
        and the levels of its top-left 2x2 block's sites).

    Returns
    -------
    (M, N) float32 ndarray
        ``channel_mean(mosaic_image(mosaic, ...))`` (:func:`shadowcam.io.decode.mosaic_image`),
        bit for bit.
    """
    mosaic = np.asarray(mosaic)
    if mosaic.ndim != 2 or min(mosaic.shape) < 3:
        raise ValueError(f"mosaic must be a 2-D array of at least 3x3; got shape {mosaic.shape}")
    if mosaic.dtype.kind not in "ui":
        raise ValueError(f"mosaic must hold integers; got dtype {mosaic.dtype}")
    black_sites = np.asarray(black_sites, dtype=np.float64).reshape(2, 2)
    white_sites = np.asarray(white_sites, dtype=np.float64).reshape(2, 2)
    vmax = int(white_sites.max())
    channel_of_site = np.array([_CHANNEL_OF_LETTER[letter] for letter in cfa_pattern], dtype=np.int64).reshape(2, 2)
    per_channel = all(
        np.unique(sites[channel_of_site == c]).size == 1 for sites in (black_sites, white_sites) for c in range(3)
    )
    if not per_channel or vmax > 65535:
        from shadowcam.io.decode import mosaic_image  # levels differ between sites of a channel

        return channel_mean(mosaic_image(mosaic, cfa_pattern=cfa_pattern, black_sites=black_sites,
                                         white_sites=white_sites))
    scale = 65535 // max(vmax, 1)
    black = site_map(black_sites, (4, 4), cfa_pattern, vmax) * np.float32(scale)
    span = site_map(white_sites, (4, 4), cfa_pattern, vmax) * np.float32(scale) - black
    black, span = (np.asarray(a, dtype=np.float32).reshape(-1, 3)[0] * np.ones(3, np.float32) for a in (black, span))
    out = np.empty(mosaic.shape, dtype=np.float32)
    _luminance_kernel(mosaic, np.int64(scale), channel_of_site, black, span, out)
    return out
