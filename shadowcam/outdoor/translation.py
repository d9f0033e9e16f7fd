"""Sub-pixel translation of an image whose result does not depend on where the image is cut.

A pure translation resamples every pixel with the same interpolation weights,
so it can be computed as a weighted sum of whole shifted copies of the image:
each output pixel then gets exactly the same float32 operations in the same
order wherever it lies in the array. A column window of an image (with a
margin of ``ceil(|shift_col|) + 2`` columns) therefore translates to the same
bits as the same columns of the whole image, which lets column strips of the
outdoor edge-tracking pass run as separate jobs and merge exactly
(:mod:`shadowcam.outdoor.strips`). OpenCV's ``warpAffine``
(:func:`shadowcam.outdoor.registration.apply_shift`) computes the source coordinate of
each pixel in floating point from its absolute position, so its results
differ in the last bit between a window and the whole image.

Offers
------
translate_cubic_Keys1981 : translate by cubic convolution, edges replicated.
cubic_weights : the four cubic-convolution weights of a fractional offset.
"""

import math

import numpy as np

#: Keys' free parameter, as OpenCV's INTER_CUBIC
KEYS_A = -0.75


def cubic_weights(fraction, *, a=KEYS_A):
    """Return the weights ``(4,)`` float32 of samples ``i - 1 .. i + 2`` at ``i + fraction``.

    Keys (1981), "Cubic convolution interpolation for digital image processing".
    """
    if not 0 <= fraction < 1:
        raise ValueError(f"fraction must be in [0, 1); got {fraction}")
    x = np.array([1 + fraction, fraction, 1 - fraction, 2 - fraction])
    near = ((a + 2) * x - (a + 3)) * x * x + 1
    far = ((a * x - 5 * a) * x + 8 * a) * x - 4 * a
    return np.where(x <= 1, near, far).astype(np.float32)


def translate_cubic_Keys1981(image, shift):
    """Resample `image` at ``(r + shift_row, c + shift_col)``, separably, edges replicated.

    Parameters
    ----------
    image : (H, W) ndarray
        float32 (other dtypes are converted to float32).
    shift : (2,) array_like
        ``(shift_row, shift_col)`` in pixels (content moved by +shift is moved back).

    Returns
    -------
    (H, W) float32 ndarray
        Within ~1e-6 relative of :func:`shadowcam.outdoor.registration.apply_shift`
        (same cubic kernel, separable rounding); bit-identical for any column
        window of `image` at columns ``ceil(|shift_col|) + 2`` or more from the
        window's cut edges.
    """
    out = np.asarray(image, dtype=np.float32)
    if out.ndim != 2:
        raise ValueError(f"image must be (H, W); got shape {out.shape}")
    shift = np.asarray(shift, dtype=np.float64)
    if shift.shape != (2,) or not np.all(np.isfinite(shift)):
        raise ValueError(f"shift must be two finite numbers (row, col); got {shift}")
    for axis, offset in enumerate(shift):
        if offset == 0:
            continue
        whole = math.floor(offset)
        weights = cubic_weights(offset - whole)
        before, after = max(0, 1 - whole), max(0, whole + 2)
        pad = [(0, 0), (0, 0)]
        pad[axis] = (before, after)
        padded = np.pad(out, pad, mode="edge")
        size = out.shape[axis]
        total, term = np.empty_like(out), np.empty_like(out)
        for tap, weight in enumerate(weights):
            start = whole - 1 + tap + before
            window = [slice(None), slice(None)]
            window[axis] = slice(start, start + size)
            if tap == 0:
                np.multiply(padded[tuple(window)], weight, out=total)
            else:
                np.multiply(padded[tuple(window)], weight, out=term)
                total += term
        out = total
    return out if out is not image else out.copy()
