"""Each RAW pixel's own mosaic site in its dip window: the samples that see only its footprint.

The tracker follows the channel sum of the bilinear demosaic
(:mod:`shadowcam.lab.mosaic_signal`): one third of it is the site's own value and
two thirds come from its neighbours (the 8 around a red or blue site, the 4 edge
ones of a green site), each shadowed at its own time. The dip's window is found
on that sum (its noise is the lowest), and the pixel is then timed from the site's
own samples where their noise allows (:func:`shadowcam.lab.shadow_time_methods.time_edge_fit`).
The demosaic keeps a site's own value in its own channel, so those samples are
read from the demosaiced frames without the mosaic, or from the mosaic without a
demosaic (:func:`mosaic_own_site`, the same values bit for bit), and the neighbours'
part is the tracked signal less them. Under several lights each minimum's
window carries its own :class:`SiteWindow`, in the units of its normalised window
(:func:`shadowcam.lab.minima.find_minima` with ``site_colour``).

Offers
------
SiteWindow : own-site samples at the window's frames, and the site's lit level and noise.
own_site_samples : each site's own channel of a demosaiced block.
track_site_window : one pass over a sweep's demosaiced frames -> the :class:`SiteWindow`.
site_window_sums, SiteSums : one pass over a range of frames' own samples and signal (time chunks).
site_window_of_sums : the :class:`SiteWindow` from the sums of consecutive frame ranges.
tracked_site_window : the :class:`SiteWindow` the dip tracker kept in its pass (RAW tracked with ``own_site``).
mosaic_own_site : each site's own value straight from a mosaic, bit for bit the demosaic's.
blend_variance : per-axis second moment of the channel sum's (or its neighbours' part's) demosaic taps.
cfa_site_colours : the CFA channel measured at each pixel of a Bayer mosaic.
"""

from dataclasses import dataclass, replace

import numba as nb
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


@dataclass
class SiteSums:
    """Own-site sums of a range of a sweep's frames (:func:`site_window_sums`); add them with
    :func:`site_window_of_sums`.

    Attributes
    ----------
    window : (K, H, W) float32 ndarray
        Own-site samples at the window's frames within the range (NaN elsewhere).
    total, square : (H, W) float64 ndarray
        Sum and sum of squares of the own samples outside the window.
    rest_total, rest_square : (H, W) float64 ndarray
        The same of the neighbours' part (signal less own).
    count : (H, W) int64 ndarray
        Number of those frames.
    n_frames : int
        Frames of the range.
    """

    window: np.ndarray
    total: np.ndarray
    square: np.ndarray
    rest_total: np.ndarray
    rest_square: np.ndarray
    count: np.ndarray
    n_frames: int


def site_window_sums(samples, window_start, k, *, first=0):
    """One pass over own-site samples and the tracked signal: the :class:`SiteSums` of their frames.

    Parameters
    ----------
    samples : iterable of ((T, H, W) ndarray, (T, H, W) float32 ndarray)
        Each site's own value and the tracked signal (channel sum) of consecutive
        frames, from frame `first`, in time order (any block sizes).
    window_start : (H, W) int ndarray
        First frame of each pixel's dip window (the summary's ``window_start``).
    k : int
        Frames of the window.
    first : int, optional
        Frame of the first sample.

    Returns
    -------
    SiteSums
    """
    start = np.ascontiguousarray(window_start, np.int64)
    shape = start.shape
    window = np.full((k,) + shape, np.nan, np.float32)
    total, square = np.zeros(shape), np.zeros(shape)
    rest_total, rest_square = np.zeros(shape), np.zeros(shape)
    count = np.zeros(shape, np.int64)
    frame = int(first)
    for own, signal in samples:
        n = own.shape[0]
        if own.shape[1:] != shape or signal.shape != own.shape:
            raise ValueError(f"samples must be two (T, {shape[0]}, {shape[1]}) arrays; got {own.shape} "
                             f"and {signal.shape}")
        _accumulate_block(np.ascontiguousarray(own, np.float32).reshape(n, -1),
                          np.ascontiguousarray(signal, np.float32).reshape(n, -1), frame, start.ravel(), int(k),
                          window.reshape(k, -1), total.ravel(), square.ravel(), rest_total.ravel(),
                          rest_square.ravel(), count.ravel())
        frame += n
    return SiteSums(window=window, total=total, square=square, rest_total=rest_total, rest_square=rest_square,
                    count=count, n_frames=frame - int(first))


@nb.njit(cache=True)
def _accumulate_block(own, signal, first, start, k, window, total, square, rest_total, rest_square, count):
    """Add one block of frames ``(T, P)`` to the per-pixel window and lit sums (in place).

    Each pixel's samples of the block are summed first and the block's sums then added
    (the order of numpy's sums over a block's time axis).
    """
    n, pixels = own.shape
    for p in range(pixels):
        block_total = block_square = block_rest = block_rest_square = 0.0
        block_count = 0
        for t in range(n):
            value = own[t, p]
            slot = first + t - start[p]
            if 0 <= slot < k:
                window[slot, p] = value
            elif np.isfinite(value):
                own64 = np.float64(value)
                rest = np.float64(signal[t, p] - value)
                block_total += own64
                block_square += own64 * own64
                block_rest += rest
                block_rest_square += rest * rest
                block_count += 1
        total[p] += block_total
        square[p] += block_square
        rest_total[p] += block_rest
        rest_square[p] += block_rest_square
        count[p] += block_count


def site_window_of_sums(parts, summary, *, site_colour):
    """The :class:`SiteWindow` of a sweep from the :class:`SiteSums` of its consecutive frame ranges.

    Parameters
    ----------
    parts : sequence of SiteSums
        Covering the sweep's frames once, in time order (one part: a single pass).
    summary : DipSummary
        The tracked sweep.
    site_colour : (H, W) int ndarray
        CFA channel of each site.

    Returns
    -------
    SiteWindow
    """
    shape = summary.lit_level.shape
    colour = check_array(site_colour, "site_colour", shape=shape, dtype_kind="iu")
    n = sum(part.n_frames for part in parts)
    if n != summary.n_frames:
        raise ValueError(f"blocks hold {n} frames but the summary was tracked over {summary.n_frames}")
    window = parts[0].window
    sums = [getattr(parts[0], name) for name in ("total", "square", "rest_total", "rest_square", "count")]
    for part in parts[1:]:
        window = np.where(np.isnan(window), part.window, window)
        sums = [a + getattr(part, name) for a, name in
                zip(sums, ("total", "square", "rest_total", "rest_square", "count"))]
    total, square, rest_total, rest_square, count = sums
    window[~np.isfinite(window)] = np.nan
    level, noise = _mean_std(total, square, count)
    rest_level, rest_noise = _mean_std(rest_total, rest_square, count)
    return SiteWindow(window=window, level=level, noise=noise, count=count, neighbour_level=rest_level,
                      neighbour_noise=rest_noise, colour=colour.astype(np.int8))


def tracked_site_window(summary, site_colour):
    """The :class:`SiteWindow` of a summary tracked with each site's own value (no pass over the frames).

    Parameters
    ----------
    summary : DipSummary
        From a :class:`~shadowcam.lab.dip_tracker.DipTracker` built with ``own_site``
        (its ``tracked_site``: lit statistics from exact running sums).
    site_colour : (H, W) int ndarray
        CFA channel of each site.

    Returns
    -------
    SiteWindow
    """
    if summary.tracked_site is None:
        raise ValueError("summary has no tracked_site: track the sweep with DipTracker(..., own_site=True)")
    shape = summary.lit_level.shape
    colour = check_array(site_colour, "site_colour", shape=shape, dtype_kind="iu")
    return replace(summary.tracked_site, colour=colour.astype(np.int8))


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
    shape = summary.lit_level.shape
    colour = check_array(site_colour, "site_colour", shape=shape, dtype_kind="iu").astype(np.intp)

    def samples():
        for block in blocks:
            block = np.asarray(block)
            yield own_site_samples(block, colour), block.sum(axis=3, dtype=np.float32)

    sums = site_window_sums(samples(), summary.window_start, summary.window.shape[0])
    return site_window_of_sums([sums], summary, site_colour=colour)


def mosaic_own_site(mosaic, *, pattern, black, white, out=None):
    """Each site's own value straight from a Bayer mosaic, as the RAW decode's demosaic gives it.

    :func:`shadowcam.io.decode.mosaic_image` keeps a site's own channel as
    ``(k DN - k black) / (k white - k black)`` in float32 (``k = 65535 // max(white)``,
    every term an exact integer); this is the same arithmetic without the other
    channels: equal to ``own_site_samples(mosaic_image(...))`` bit for bit where the
    levels are integers (as a DNG's usually are).

    Parameters
    ----------
    mosaic : (M, N) ndarray of unsigned int
        In DN.
    pattern : str
        CFA pattern of the top-left 2x2 block (unused by the arithmetic; checked).
    black, white : (2, 2) array_like
        Levels of the top-left 2x2 block's sites, DN.
    out : (M, N) float32 ndarray, optional
        Where to write the values (C-contiguous).

    Returns
    -------
    (M, N) float32 ndarray
    """
    cfa_site_colours((2, 2), pattern)
    mosaic = np.asarray(mosaic)
    if mosaic.ndim != 2 or mosaic.dtype.kind != "u":
        raise ValueError(f"mosaic must be a 2-D unsigned-integer array; got {mosaic.dtype} {mosaic.shape}")
    white = np.asarray(white, np.float64).reshape(2, 2)
    scale = np.float32(65535 // int(white.max()))
    black = np.asarray(black, np.float64).reshape(2, 2).astype(np.float32) * scale
    span = white.astype(np.float32) * scale - black
    own = np.empty(mosaic.shape, np.float32) if out is None else out
    if own.shape != mosaic.shape or own.dtype != np.float32 or not own.flags.c_contiguous:
        raise ValueError(f"out must be a C-contiguous float32 array of shape {mosaic.shape}")
    _own_site_kernel(np.ascontiguousarray(mosaic), scale, black, span, own)
    return own


@nb.njit(cache=True)
def _own_site_kernel(mosaic, scale, black, span, out):
    """``(DN * scale - black) / span`` per site in float32, the constants by CFA phase ``(2, 2)``."""
    rows, cols = mosaic.shape
    for r in range(rows):
        for c in range(cols):
            out[r, c] = (np.float32(mosaic[r, c]) * scale - black[r & 1, c & 1]) / span[r & 1, c & 1]


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
