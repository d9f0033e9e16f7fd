"""Sub-pixel registration of time-lapse frames to a reference frame.

Camera shake in a time-lapse is a small translation (about a pixel). The
shift is estimated by Lucas-Kanade (Gauss-Newton) on band-passed log
luminance, which removes exposure and slow shading changes; pixels whose
illumination state changed since the reference (the moving shadow: a large
log-ratio step) are left out, because a moving shadow edge would otherwise be
taken for camera motion (phase correlation fails on this: the shadow edge is
the strongest feature of the image).

Convention: a frame whose content moved by ``(shift_row, shift_col)``
satisfies ``frame(r, c) = reference(r - shift_row, c - shift_col)``;
:func:`apply_shift` samples the frame at ``(r + shift_row, c + shift_col)``
to align it with the reference.

Offers
------
REGISTRATION_METHODS : method name -> estimator.
bandpass_log : band-passed log luminance used for matching.
static_weight : weight mask of pixels whose illumination state did not change.
shift_lucas_kanade_LucasKanade1981 : translation by iterative least squares.
apply_shift : resample an image so that it aligns with the reference.
"""

import cv2
import numpy as np

_EPS = 1e-3


def bandpass_log(luma, *, inner_sigma=0.7, outer_sigma=3.0):
    """Return the band-pass (difference of Gaussians) of ``log(luma)``.

    Parameters
    ----------
    luma : (H, W) ndarray
    inner_sigma, outer_sigma : float, optional
        Gaussian scales in pixels.

    Returns
    -------
    (H, W) float32 ndarray
    """
    luma = np.asarray(luma, dtype=np.float32)
    if luma.ndim != 2:
        raise ValueError(f"luma must be 2-D (H, W); got shape {luma.shape}")
    logl = np.log(np.maximum(luma, 0) + _EPS)
    smooth = cv2.GaussianBlur(logl, (0, 0), inner_sigma)
    return smooth - cv2.GaussianBlur(logl, (0, 0), outer_sigma)


def static_weight(luma, reference_luma, *, lit_reference, gain, valid=None, max_ratio=0.5, margin=6):
    """Weights of the pixels whose illumination state did not change since the reference.

    Parameters
    ----------
    luma, reference_luma : (H, W) ndarray
    lit_reference : (H, W) bool ndarray
        Pixels sunlit in the reference (:func:`shadowcam.photometric.lit_at_start`).
    gain : float
        Lit gain of the frame relative to the reference
        (:func:`shadowcam.photometric.estimate_gain`; shift-insensitive).
    valid : (H, W) bool ndarray, optional
        Pixels that may be used; the others (the sky, whose brightness
        relative to the terrain changes at sunset, so that the skyline's
        band-pass response changes) are excluded with the same margin.
    max_ratio : float, optional
        A pixel lit in the reference whose ``luma / reference`` fell below
        ``max_ratio * gain`` has been reached by the shadow.
    margin : int, optional
        Changed pixels are dilated by this many pixels (about twice the outer
        scale of :func:`bandpass_log`, whose response to the moved edge
        spreads that far); the image border too.

    Returns
    -------
    (H, W) float32 ndarray of 0 / 1
        Zero on changed pixels (the moving shadow edge), on the reference's
        lit / shadow boundary, on invalid pixels and the border, each widened
        by `margin`; static shadows and static lit parts are kept.
    """
    luma = np.asarray(luma, dtype=np.float32)
    ref = np.asarray(reference_luma, dtype=np.float32)
    lit = np.asarray(lit_reference, dtype=bool)
    if not (luma.shape == ref.shape == lit.shape) or luma.ndim != 2:
        raise ValueError(f"luma {luma.shape}, reference_luma {ref.shape} and lit_reference {lit.shape} "
                         "must be the same (H, W) shape")
    if not gain > 0:
        raise ValueError(f"gain must be positive; got {gain}")
    changed = lit & (luma < max_ratio * gain * ref)
    # the reference's own shadow edge: a small move of it changes pixels less than max_ratio
    changed |= lit & (cv2.dilate((~lit).astype(np.uint8), np.ones((3, 3), np.uint8)) > 0)
    if valid is not None:
        changed |= ~np.asarray(valid, dtype=bool)
    size = 2 * int(margin) + 1
    changed = cv2.dilate(changed.astype(np.uint8), np.ones((size, size), np.uint8)) > 0
    weight = (~changed).astype(np.float32)
    weight[:margin + 1], weight[-margin - 1:] = 0, 0
    weight[:, :margin + 1], weight[:, -margin - 1:] = 0, 0
    return weight


def apply_shift(image, shift, *, interpolation=cv2.INTER_CUBIC):
    """Resample `image` at ``(r + shift_row, c + shift_col)`` (edges replicated).

    Parameters
    ----------
    image : (H, W) or (H, W, C) ndarray
    shift : (2,) array_like
        ``(shift_row, shift_col)`` in pixels.

    Returns
    -------
    ndarray
        Same shape and dtype (float32 stays float32).
    """
    image = np.asarray(image)
    if image.ndim not in (2, 3):
        raise ValueError(f"image must be (H, W) or (H, W, C); got shape {image.shape}")
    d_row, d_col = (float(s) for s in shift)
    if d_row == 0 and d_col == 0:
        return image.copy()
    matrix = np.float32([[1, 0, d_col], [0, 1, d_row]])
    height, width = image.shape[:2]
    return cv2.warpAffine(image, matrix, (width, height), flags=interpolation | cv2.WARP_INVERSE_MAP,
                          borderMode=cv2.BORDER_REPLICATE)


def shift_lucas_kanade_LucasKanade1981(luma, reference_luma, *, weight=None, initial=(0.0, 0.0),
                                       max_iter=10, tol=1e-3, min_weight=200.0, max_shift=5.0):
    """Estimate the translation of a frame relative to the reference.

    Lucas & Kanade (1981), "An iterative image registration technique",
    translation only, Gauss-Newton on band-passed log luminance.

    Parameters
    ----------
    luma, reference_luma : (H, W) ndarray
    weight : (H, W) ndarray, optional
        Per-pixel weights, e.g. :func:`static_weight` (default: all pixels
        but a 4-pixel border).
    initial : (2,) array_like, optional
        Starting ``(shift_row, shift_col)``.
    max_iter : int, optional
    tol : float, optional
        Stop when the update is below `tol` pixels.
    min_weight : float, optional
        With less total weight (about: usable pixels) the problem is
        ill-posed and `initial` is returned unchanged.
    max_shift : float, optional
        A solution further than this from `initial` (pixels) is rejected
        (divergence) and `initial` is returned.

    Returns
    -------
    shift : (2,) float64 ndarray
        ``(shift_row, shift_col)``; `initial` when the estimate failed.
    residual : float
        Weighted RMS of the band-passed difference after alignment; NaN when
        the estimate failed.
    """
    luma = np.asarray(luma, dtype=np.float32)
    ref = np.asarray(reference_luma, dtype=np.float32)
    if weight is None:
        weight = np.zeros(luma.shape)
        weight[4:-4, 4:-4] = 1.0
    weight = np.asarray(weight, dtype=np.float64)
    if not (luma.shape == ref.shape == weight.shape):
        raise ValueError(f"luma {luma.shape}, reference_luma {ref.shape} and weight {weight.shape} must match")
    target = bandpass_log(ref).astype(np.float64)
    grad_row, grad_col = np.gradient(target)
    normal = np.array([[np.sum(weight * grad_row**2), np.sum(weight * grad_row * grad_col)],
                       [np.sum(weight * grad_row * grad_col), np.sum(weight * grad_col**2)]])
    start = np.asarray(initial, dtype=np.float64).copy()
    shift = start.copy()
    if weight.sum() < min_weight or np.linalg.cond(normal) > 1e8:
        return start, float("nan")
    error = None
    for _ in range(max_iter):
        error = bandpass_log(apply_shift(luma, shift)).astype(np.float64) - target
        rhs = -np.array([np.sum(weight * grad_row * error), np.sum(weight * grad_col * error)])
        step = np.linalg.solve(normal, rhs)
        shift += step
        if np.max(np.abs(shift - start)) > max_shift:
            return start, float("nan")
        if np.max(np.abs(step)) < tol:
            break
    error = bandpass_log(apply_shift(luma, shift)).astype(np.float64) - target
    residual = float(np.sqrt(np.sum(weight * error**2) / max(np.sum(weight), 1.0)))
    return shift, residual


#: method name -> estimator(luma, reference_luma, **options) -> (shift, residual)
REGISTRATION_METHODS = {"lucas_kanade": shift_lucas_kanade_LucasKanade1981}
