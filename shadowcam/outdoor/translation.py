"""Sub-pixel translation of an image: one entry function, one table of methods.

Convention of every method: the result samples `image` at ``(r + shift_row, c +
shift_col)``, so content that moved by ``+shift`` is moved back (a frame whose
content moved by ``(shift_row, shift_col)`` satisfies ``frame(r, c) =
reference(r - shift_row, c - shift_col)``).

The methods are different resamplings, each kept for what its caller needs:

* ``"opencv_cubic"``: OpenCV ``warpAffine``, cubic (Keys, a = -0.75), edges
  replicated; any channel count, dtype kept. Registration and normalisation.
* ``"cubic_Keys1981"``: the same kernel as a weighted sum of whole shifted
  copies of the image, so each output pixel gets the same float32 operations in
  the same order wherever it lies in the array. A column window of an image
  (with a margin of ``ceil(|shift_col|) + 2`` columns) translates to the same
  bits as the same columns of the whole image, which lets column strips of the
  outdoor edge-tracking pass run as separate jobs and merge exactly
  (:mod:`shadowcam.outdoor.strips`); ``warpAffine`` computes each source
  coordinate from its absolute position and differs in the last bit.
* ``"spline"``: ``scipy.ndimage.shift``, cubic B-spline, edges replicated, per
  channel, dtype kept. The synthetic camera shake.
* ``"linear_nan"``: bilinear, NaN where a neighbour is NaN or outside the image,
  float64. Maps (with holes) moved into another camera's pixel grid.

Offers
------
TRANSLATION_METHODS : method name -> translation function ``(image, shift) -> image``.
translate : translate an image by a sub-pixel shift with a named method.
cubic_weights : the four cubic-convolution weights of a fractional offset.
translate_with_block_means : ``"cubic_Keys1981"`` and the block means of the result in one pass.
"""

import math

import cv2
import numpy as np

from shadowcam._shared.validation import check_array, check_in
from shadowcam.outdoor.frame_kernels import cubic_translate_rows

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


def _translate_opencv_cubic(image, shift):
    """``"opencv_cubic"``: (H, W) or (H, W, C) image, same shape and dtype."""
    image = np.asarray(image)
    check_array(image, "image", ndim=(2, 3))
    d_row, d_col = (float(s) for s in shift)
    if d_row == 0 and d_col == 0:
        return image.copy()
    matrix = np.float32([[1, 0, d_col], [0, 1, d_row]])
    height, width = image.shape[:2]
    return cv2.warpAffine(image, matrix, (width, height), flags=cv2.INTER_CUBIC | cv2.WARP_INVERSE_MAP,
                          borderMode=cv2.BORDER_REPLICATE)


def _translate_cubic_Keys1981(image, shift):
    """``"cubic_Keys1981"``: own code, not OpenCV, so that its bits do not depend on where the image is cut.

    Parameters
    ----------
    image : (H, W) ndarray
        float32 (other dtypes are converted to float32).
    shift : (2,) array_like
        ``(shift_row, shift_col)`` in pixels.

    Returns
    -------
    (H, W) float32 ndarray
        Within ~1e-6 relative of ``"opencv_cubic"`` (same cubic kernel, separable
        rounding); bit-identical for any column window of `image` at columns
        ``ceil(|shift_col|) + 2`` or more from the window's cut edges.
    """
    return translate_with_block_means(image, shift, factor=None)[0]


def translate_with_block_means(image, shift, *, factor, out=None):
    """``"cubic_Keys1981"`` translation and the block means of its result, in one pass (compiled).

    Parameters
    ----------
    image : (H, W) ndarray
        float32 (other dtypes are converted to float32).
    shift : (2,) array_like
        ``(shift_row, shift_col)`` in pixels.
    factor : int or None, keyword-only
        Block side (>= 1); ``None``: no block means.
    out : (H, W) float32 ndarray, optional
        Written with the translated image (a buffer reused from frame to frame); must not
        be `image`.

    Returns
    -------
    translated : (H, W) float32 ndarray
        Row pass then column pass, each the four cubic taps
        (:func:`cubic_weights`) added in order in float32, edges replicated; an axis
        with zero shift is copied.
    block_means : (H // factor, W // factor) float32 ndarray or None
        :func:`shadowcam.outdoor.registration.block_mean` of `translated` (to float32
        rounding: the sums are float64); ``None`` without `factor`.
    """
    image = np.ascontiguousarray(image, dtype=np.float32)
    check_array(image, "image", ndim=2)
    shift = np.asarray(shift, dtype=np.float64)
    if shift.shape != (2,) or not np.all(np.isfinite(shift)):
        raise ValueError(f"shift must be two finite numbers (row, col); got {shift}")
    if factor is not None and int(factor) < 1:
        raise ValueError(f"factor must be >= 1 or None; got {factor}")
    if out is None:
        out = np.empty_like(image)
    elif out.shape != image.shape or out.dtype != np.float32 or not out.flags.c_contiguous or out is image:
        raise ValueError(f"out must be a C-contiguous float32 array of shape {image.shape}, other than image")
    taps = []
    for offset in shift:
        whole = math.floor(offset)
        taps += [None, 0] if offset == 0 else [cubic_weights(offset - whole), whole - 1]
    side = 1 if factor is None else int(factor)
    sums = np.zeros((0, 0) if factor is None else (image.shape[0] // side, image.shape[1] // side), dtype=np.float64)
    cubic_translate_rows(image, taps[0], taps[1], taps[2], taps[3], out, side, sums)
    return out, None if factor is None else (sums / float(side * side)).astype(np.float32)


def _translate_spline(image, shift):
    """``"spline"``: (H, W) or (H, W, C) image, same shape and dtype; ``scipy.ndimage.shift`` per channel."""
    from scipy.ndimage import shift as ndimage_shift

    image = np.asarray(image)
    check_array(image, "image", ndim=(2, 3))
    d_row, d_col = (float(s) for s in shift)
    moved_by = (-d_row, -d_col)  # scipy: out(r) = in(r - moved_by)
    out = np.empty_like(image)
    if image.ndim == 2:
        ndimage_shift(image, moved_by, output=out, order=3, mode="nearest")
        return out
    for c in range(image.shape[2]):
        ndimage_shift(image[:, :, c], moved_by, output=out[:, :, c], order=3, mode="nearest")
    return out


def _translate_linear_nan(image, shift):
    """``"linear_nan"``: own NaN handling around ``scipy.ndimage.map_coordinates``, which has no NaN-aware mode.

    (H, W) image -> (H, W) float64; NaN where a neighbour is NaN or outside the image.
    """
    from scipy.ndimage import map_coordinates

    values = np.asarray(image, dtype=np.float64)
    check_array(values, "image", ndim=2)
    d_row, d_col = (float(s) for s in shift)
    if d_row == 0 and d_col == 0:
        return values.copy()
    rows, cols = np.indices(values.shape, dtype=np.float64)
    coords = np.stack([rows + d_row, cols + d_col])
    missing = ~np.isfinite(values)
    sampled = map_coordinates(np.where(missing, 0.0, values), coords, order=1, mode="constant", cval=np.nan)
    touched = map_coordinates(missing.astype(np.float64), coords, order=1, mode="constant", cval=1.0)
    return np.where(touched > 0, np.nan, sampled)


#: method name -> translation function ``(image, shift) -> image`` (see the module docstring)
TRANSLATION_METHODS = {
    "opencv_cubic": _translate_opencv_cubic,
    "cubic_Keys1981": _translate_cubic_Keys1981,
    "spline": _translate_spline,
    "linear_nan": _translate_linear_nan,
}


def translate(image, shift, *, method):
    """Resample `image` at ``(r + shift_row, c + shift_col)`` with a method of :data:`TRANSLATION_METHODS`.

    Parameters
    ----------
    image : (H, W) or (H, W, C) ndarray
        ``"cubic_Keys1981"`` and ``"linear_nan"`` take (H, W) only.
    shift : (2,) array_like
        ``(shift_row, shift_col)`` in pixels (content moved by +shift is moved back).
    method : str, keyword-only
        A key of :data:`TRANSLATION_METHODS`.

    Returns
    -------
    ndarray
        Shape of `image`; dtype as the method says (module docstring).
    """
    check_in(method, "method", TRANSLATION_METHODS)
    if np.shape(shift) != (2,):
        raise ValueError(f"shift must be two numbers (row, col); got {shift!r}")
    return TRANSLATION_METHODS[method](image, shift)
