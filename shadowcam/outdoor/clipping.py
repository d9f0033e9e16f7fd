"""Samples clipped at the sensor's white level, and the lit level of a pixel whose lit samples clip.

A decoded frame store holds ``(value - black) / (white - black)`` (:mod:`shadowcam.io.frame_store`),
so the RAW white level after black subtraction decodes to :data:`WHITE_LEVEL`; a sample at or above
it in any channel is clipped: its reading is a lower bound of its light, never a level. A pixel
whose lit samples clip has no lit level of its own. Fully lit it reads ``a (E cos i + sky)``,
fully shadowed ``a sky`` (``a`` its albedo): its lit-to-shadow ratio depends on the surface's
orientation and the light, not on the albedo, so its unclipped neighbours on the same surface that
reached their shadow give that ratio ``R`` and its own shadow level ``S`` (never clipped) gives
``S R``, at least its clipped reading.

Offers
------
WHITE_LEVEL : the decoded value of the RAW white level.
store_white_level : the decoded white level of a frame store (None: its values carry none).
CLIPPED_SHARE : a clipped sample's share in a registered sample that makes its reading no level.
OWN_SHARE : a clipped sample's share in a registered sample that makes it the sample's own.
LIT_RATIO_RADIUS : pixels each side whose lit-to-shadow ratios give a clipped pixel's.
clipped_samples : the samples of a frame clipped in any channel.
registered_clipped : the clipped samples' share in each sample of a frame registered to the reference.
clipped_lit_levels : the lit level of the pixels whose lit sample clips, from their neighbours' ratio.
"""

import numpy as np

from shadowcam.outdoor.penumbra import neighbour_median
from shadowcam.outdoor.translation import translate

#: decoded value of the RAW white level (after black subtraction, over the white-black span)
WHITE_LEVEL = 1.0
#: share of a clipped sample in a registered sample (the cubic kernel's) below which it is left out
CLIPPED_SHARE = 1e-6
#: share at or above which the registered sample is the clipped one (the nearest of the kernel's taps)
OWN_SHARE = 0.5
#: pixels each side whose unclipped lit-to-shadow ratios give a clipped pixel's
LIT_RATIO_RADIUS = 6


def store_white_level(frames):
    """The decoded value of a frame store's white level.

    Parameters
    ----------
    frames : xarray.Dataset
        Frame store; a decode from RAW (or any file with a white level) has attrs ``white_level``
        and ``normalisation`` ``"linear; (value - black_level) / (white_level - black_level)"``
        (:mod:`shadowcam.io.frame_store`).

    Returns
    -------
    float or None
        :data:`WHITE_LEVEL`, or None when the store's values are not normalised to a white level
        (nothing is known to clip).
    """
    normalisation = str(frames.attrs.get("normalisation", ""))
    known = "white_level" in frames.attrs and normalisation.startswith("linear; (value - black_level) / (white_level")
    return WHITE_LEVEL if known else None


def clipped_samples(frame, *, white_level=WHITE_LEVEL):
    """The samples of a decoded frame that reach the white level in any channel.

    Parameters
    ----------
    frame : (H, W, C) or (H, W) ndarray
        Decoded values (white level :data:`WHITE_LEVEL`).
    white_level : float, keyword-only

    Returns
    -------
    (H, W) bool ndarray
    """
    frame = np.asarray(frame)
    clipped = frame >= np.float32(white_level)
    return clipped.any(axis=-1) if frame.ndim == 3 else clipped


def registered_clipped(frame, shift, *, white_level=WHITE_LEVEL):
    """The clipped samples' share in each sample of a frame translated to the reference.

    Parameters
    ----------
    frame : (H, W, C) or (H, W) ndarray
        Decoded values, before the translation.
    shift : (2,) array_like
        ``(shift_row, shift_col)`` (:func:`shadowcam.outdoor.translation.translate`).
    white_level : float, keyword-only

    Returns
    -------
    (H, W) float32 ndarray or None
        The clipped mask translated like the frame (``"cubic_Keys1981"``): non-zero where a
        clipped sample enters the registered sample, at least 0.5 where its own is the clipped
        one. None when no sample of the frame clips.
    """
    clipped = clipped_samples(frame, white_level=white_level)
    if not clipped.any():
        return None
    return translate(clipped.astype(np.float32), shift, method="cubic_Keys1981")


def clipped_lit_levels(lit_level, shadow_level, *, clipped, trusted, fallback_ratio, radius=LIT_RATIO_RADIUS):
    """Lit levels with those of the clipped pixels taken from their neighbours' lit-to-shadow ratio.

    Parameters
    ----------
    lit_level : (H, W) ndarray
        Each pixel's lit level (of a clipped pixel: its clipped reading, a lower bound).
    shadow_level : (H, W) ndarray
        Each pixel's shadow level on the same scale.
    clipped : (H, W) bool ndarray
        Pixels whose lit sample clipped.
    trusted : (H, W) bool ndarray
        Pixels whose two levels are both measured (lit and later shadowed); only the unclipped
        ones give a ratio.
    fallback_ratio : float
        Lit-to-shadow ratio of a clipped pixel without unclipped trusted neighbours (the capture's).
    radius : int, keyword-only
        Pixels each side of the neighbourhood.

    Returns
    -------
    (H, W) float32 ndarray
        `lit_level`, at the clipped pixels ``max(reading, S R)``.
    """
    lit = np.array(lit_level, dtype=np.float32)
    clipped = np.asarray(clipped, dtype=bool)
    if not clipped.any():
        return lit
    shadow = np.asarray(shadow_level, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(shadow > 0, lit / shadow, np.nan)
    rows, cols = np.nonzero(clipped)
    nbr = neighbour_median(ratio, np.asarray(trusted, dtype=bool) & ~clipped & np.isfinite(ratio), radius=radius,
                           at=(rows, cols))
    nbr = np.where(np.isfinite(nbr), nbr, float(fallback_ratio))
    lit[rows, cols] = np.maximum(lit[rows, cols], shadow[rows, cols] * nbr)
    return lit
