"""Each RAW pixel's own mosaic site in its dip window: the samples that see only its footprint.

The tracker follows the channel sum of the bilinear demosaic
(:mod:`shadowcam.lab.mosaic_signal`): one third of it is the site's own value and
two thirds come from its neighbours (the 8 around a red or blue site, the 4 edge
ones of a green site), each shadowed at its own time. The dip's window is found
on that sum (its noise is the lowest), and the pixel is then timed from the site's
own samples where their noise allows (:func:`shadowcam.lab.shadow_time_methods.time_edge_fit`).
The demosaic keeps a site's own value in its own channel, so those samples are
read from the demosaiced frames without the mosaic. Under several lights each minimum's
window carries its own :class:`SiteWindow`, in the units of its normalised window
(:func:`shadowcam.lab.minima.find_minima` with ``site_colour``).

Offers
------
SiteWindow : own-site samples at the window's frames, and the site's lit level and noise.
own_site_samples : each site's own channel of a demosaiced block.
track_site_window : one pass over a sweep's demosaiced frames -> the :class:`SiteWindow`.
blend_variance : per-axis second moment of the channel sum's (or its neighbours' part's) demosaic taps.
cfa_site_colours : the CFA channel measured at each pixel of a Bayer mosaic.
"""

from dataclasses import dataclass

import numpy as np

from shadowcam._shared.validation import check_array

#: per-axis second moment (px^2) of the channel sum's taps, (with the own site, without it):
#: red / blue site (own 1, the 4 edge and 4 corner neighbours 1/4 each), green site (own 1,
#: the 4 edge neighbours 1/2)
_BLEND_VARIANCE = {"red_blue": (0.5, 0.75), "green": (1.0 / 3.0, 0.5)}
_GREEN = 1


@dataclass
class SiteWindow:
    """A sweep's own-site samples, aligned with a :class:`~shadowcam.lab.dip_tracker.DipSummary`.

    Attributes
    ----------
    window : (K, H, W) float32 ndarray
        The site's own channel at frame ``window_start + k`` of the summary (NaN outside
        the sweep or not finite).
    level : (H, W) float64 ndarray
        Mean of the site's channel over the valid frames outside the window.
    noise : (H, W) float64 ndarray
        Standard deviation of those frames.
    count : (H, W) int64 ndarray
        Number of those frames.
    neighbour_level, neighbour_noise : (H, W) float64 ndarray
        The same of the neighbours' part of the tracked signal (channel sum less the
        site's own value), over the same frames.
    colour : (H, W) int8 ndarray
        CFA channel of each site (0 R, 1 G, 2 B).
    """

    window: np.ndarray
    level: np.ndarray
    noise: np.ndarray
    count: np.ndarray
    neighbour_level: np.ndarray
    neighbour_noise: np.ndarray
    colour: np.ndarray


def own_site_samples(block, site_colour):
    """Each site's own channel of a demosaiced block.

    Parameters
    ----------
    block : (T, H, W, C) ndarray
        Demosaiced frames.
    site_colour : (H, W) intp ndarray
        CFA channel of each site.

    Returns
    -------
    (T, H, W) ndarray
        ``block[t, r, c, site_colour[r, c]]``, in `block`'s dtype.
    """
    block = np.asarray(block)
    shape = site_colour.shape
    if block.ndim != 4 or block.shape[1:3] != shape:
        raise ValueError(f"blocks must be (T, {shape[0]}, {shape[1]}, C) with site_colour; got {block.shape}")
    rows, cols = np.indices(shape)
    return block[:, rows, cols, site_colour]


def track_site_window(blocks, summary, *, site_colour):
    """Own-site samples of every pixel in its dip window, and its own lit statistics.

    Parameters
    ----------
    blocks : iterable of (T, H, W, C) ndarray
        The sweep's demosaiced frames in time order (any block sizes), the same as
        fed to the tracker.
    summary : DipSummary
        The tracked sweep (its ``window_start`` and window length).
    site_colour : (H, W) int ndarray
        CFA channel of each site (:func:`cfa_site_colours`).

    Returns
    -------
    SiteWindow
    """
    k = summary.window.shape[0]
    shape = summary.lit_level.shape
    colour = check_array(site_colour, "site_colour", shape=shape, dtype_kind="iu").astype(np.intp)
    start = np.asarray(summary.window_start)
    window = np.full((k,) + shape, np.nan, np.float32)
    total, square = np.zeros(shape), np.zeros(shape)
    rest_total, rest_square = np.zeros(shape), np.zeros(shape)
    count = np.zeros(shape, np.int64)
    first = 0
    for block in blocks:
        block = np.asarray(block)
        own = own_site_samples(block, colour)
        slot = first + np.arange(own.shape[0])[:, None, None] - start[None]
        inside = (slot >= 0) & (slot < k)
        t, r, c = np.nonzero(inside)
        window[slot[t, r, c], r, c] = own[t, r, c]
        lit = ~inside & np.isfinite(own)
        values = np.where(lit, own, 0.0).astype(np.float64)
        total += values.sum(axis=0)
        square += (values**2).sum(axis=0)
        rest = np.where(lit, block.sum(axis=3, dtype=np.float32) - own, 0.0).astype(np.float64)
        rest_total += rest.sum(axis=0)
        rest_square += (rest**2).sum(axis=0)
        count += lit.sum(axis=0)
        first += own.shape[0]
    if first != summary.n_frames:
        raise ValueError(f"blocks hold {first} frames but the summary was tracked over {summary.n_frames}")
    window[~np.isfinite(window)] = np.nan
    level, noise = _mean_std(total, square, count)
    rest_level, rest_noise = _mean_std(rest_total, rest_square, count)
    return SiteWindow(window=window, level=level, noise=noise, count=count, neighbour_level=rest_level,
                      neighbour_noise=rest_noise, colour=colour.astype(np.int8))


def _mean_std(total, square, count):
    """Mean and sample standard deviation from sums over `count` values (NaN where none)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = total / count
        variance = np.maximum(square / count - mean**2, 0.0) * count / np.maximum(count - 1, 1)
    return mean, np.sqrt(variance)


def blend_variance(site_colour, *, own=True):
    """Per-axis second moment of the channel sum's demosaic taps at each site, px^2.

    The channel sum of a bilinear demosaic sees the site's footprint convolved with
    its taps (1/2 at red and blue sites, 1/3 at green ones), so its footprint's second
    moment is the site's plus this; without the own site (the neighbours' part), 3/4 and
    1/2.

    Parameters
    ----------
    site_colour : (H, W) int ndarray
        CFA channel of each site (0 R, 1 G, 2 B).
    own : bool, optional
        Whether the taps include the site's own value.

    Returns
    -------
    (H, W) float64 ndarray
    """
    colour = check_array(site_colour, "site_colour", ndim=2, dtype_kind="iu")
    which = 0 if own else 1
    return np.where(colour == _GREEN, _BLEND_VARIANCE["green"][which], _BLEND_VARIANCE["red_blue"][which])


def cfa_site_colours(shape, pattern):
    """Channel index (0 R, 1 G, 2 B) measured at each pixel of a Bayer mosaic.

    Parameters
    ----------
    shape : tuple of int
        ``(H, W)``.
    pattern : str
        CFA letters of the top-left 2x2 block in reading order, e.g. ``"RGGB"``.

    Returns
    -------
    (H, W) int8 ndarray
    """
    if len(pattern) != 4 or set(pattern) - set("RGB"):
        raise ValueError(f"pattern must be four letters of R, G, B such as 'RGGB'; got {pattern!r}")
    tile = np.array(["RGB".index(ch) for ch in pattern], np.int8).reshape(2, 2)
    rows = np.arange(shape[0])[:, None] % 2
    cols = np.arange(shape[1])[None, :] % 2
    return tile[rows, cols]
