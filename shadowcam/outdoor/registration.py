"""Sub-pixel registration of time-lapse frames to a reference frame.

Camera shake in a time-lapse is a small translation (about a pixel; a few
pixels at tens of megapixels). The shift is estimated by Lucas-Kanade
(Gauss-Newton) on band-passed log luminance, which removes exposure and slow shading changes; pixels whose
illumination state changed since the reference (the moving shadow: a large
log-ratio step) are left out, because a moving shadow edge would otherwise be
taken for camera motion (phase correlation fails on this: the shadow edge is
the strongest feature of the image).

Convention: a frame whose content moved by ``(shift_row, shift_col)``
satisfies ``frame(r, c) = reference(r - shift_row, c - shift_col)``;
:func:`shadowcam.outdoor.translation.translate` samples the frame at ``(r + shift_row,
c + shift_col)`` to align it with the reference.

Range: one Lucas-Kanade level converges from a start within a few pixels of
the band-pass scale and rejects a solution more than ``max_shift`` (5) pixels
from its start. :func:`shift_coarse_to_fine` first solves on ``2**levels``-times
reduced images (block means) and refines level by level, so the range grows
to about ``4 * 2**levels`` pixels (``docs/benchmarks.md``).

Offers
------
REGISTRATION_METHODS : method name -> estimator.
bandpass_log : band-passed log luminance used for matching.
soft_shadow : the shadow reached since the reference grown through its measured soft edge.
static_weight : weight mask of pixels whose illumination state did not change.
shift_lucas_kanade_LucasKanade1981 : translation by iterative least squares.
shift_coarse_to_fine : the same on a pyramid of block means, coarse levels first (large shifts).
pyramid_levels : number of coarser levels an image of a given shape supports.
reference_levels : the reference's band-pass and gradients at every level (once per sequence).
registration_factor : integer downsampling factor that brings a frame to a working size.
block_mean : mean over factor x factor blocks (area downsampling; a shift scales by 1/factor).
block_all : True where all pixels of a factor x factor block are (masks at the working size).
"""

import cv2
import numpy as np

from shadowcam._shared.validation import check_array, check_positive, check_same_shape
from shadowcam.outdoor.translation import translate

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
    check_array(luma, "luma", ndim=2)
    logl = np.log(np.maximum(luma, 0) + _EPS)
    smooth = cv2.GaussianBlur(logl, (0, 0), inner_sigma)
    return smooth - cv2.GaussianBlur(logl, (0, 0), outer_sigma)


def soft_shadow(luma, reference_luma, *, lit_reference, gain, valid=None, max_ratio=0.5):
    """The shadow reached since the reference, with its soft edge, measured from the data.

    A shadow cast by a disc sun has a penumbra ``L x 0.53 deg / sin(incidence)`` wide
    (``L`` the distance to the occluder), which varies along the edge and over the
    sequence. The core (ratio ``luma / (gain reference)`` below `max_ratio`) is grown
    through the connected pixels whose ratio is below the lit pixels' own spread
    (``1 - 3 sigma``, ``sigma`` the median absolute deviation of the ratio over the lit
    pixels, x 1.4826), so the band excluded follows the edge's measured width.

    Parameters
    ----------
    luma, reference_luma : (H, W) ndarray
    lit_reference : (H, W) bool ndarray
    gain : float
        Lit gain of the frame relative to the reference.
    valid : (H, W) bool ndarray, optional
    max_ratio : float, optional

    Returns
    -------
    shadow : (H, W) bool ndarray
        Core plus the soft edge connected to it (8-neighbourhood).
    width_px : float
        Mean width of the soft edge: soft pixels per pixel of the shadow's boundary with
        the lit pixels (NaN without a core).
    """
    luma = np.asarray(luma, dtype=np.float32)
    ref = np.asarray(reference_luma, dtype=np.float32)
    lit = np.asarray(lit_reference, dtype=bool)
    if not (luma.shape == ref.shape == lit.shape) or luma.ndim != 2:
        raise ValueError(f"luma {luma.shape}, reference_luma {ref.shape} and lit_reference {lit.shape} "
                         "must be the same (H, W) shape")
    check_positive(gain, "gain")
    if valid is not None:
        lit = lit & np.asarray(valid, dtype=bool)
    ratio = luma / (gain * np.maximum(ref, _EPS))
    core = lit & (ratio < max_ratio)
    if not core.any():
        return core, float("nan")
    rest = ratio[lit & ~core]
    spread = 1.4826 * float(np.median(np.abs(rest - np.median(rest)))) if rest.size else 0.0
    candidate = (core | (lit & (ratio < 1.0 - 3.0 * spread))).astype(np.uint8)
    count, labels = cv2.connectedComponents(candidate, connectivity=8)
    touching = np.zeros(count, dtype=bool)
    touching[np.unique(labels[core])] = True
    touching[0] = False
    shadow = touching[labels]
    # per pixel of the shadow's lit-facing boundary: while the edge has moved less than its own
    # width the core is a few pixels, and the soft band is as long as the edge itself
    boundary = shadow & (cv2.dilate((lit & ~shadow).astype(np.uint8), np.ones((3, 3), np.uint8)) > 0)
    return shadow, float((shadow & ~core).sum() / max(int(boundary.sum()), 1))


def static_weight(luma, reference_luma, *, lit_reference, gain, valid=None, max_ratio=0.5, margin=6):
    """Weights of the pixels whose illumination state did not change since the reference.

    Parameters
    ----------
    luma, reference_luma : (H, W) ndarray
    lit_reference : (H, W) bool ndarray
        Pixels sunlit in the reference (:func:`shadowcam.outdoor.photometric.lit_at_start`).
    gain : float
        Lit gain of the frame relative to the reference
        (:func:`shadowcam.outdoor.photometric.estimate_gain`; shift-insensitive).
    valid : (H, W) bool ndarray, optional
        Pixels that may be used; the others (the sky, whose brightness
        relative to the terrain changes at sunset, so that the skyline's
        band-pass response changes) are excluded with the same margin.
    max_ratio : float, optional
        A pixel lit in the reference whose ``luma / reference`` fell below
        ``max_ratio * gain`` has been reached by the shadow; the soft edge connected
        to it is measured and left out with it (:func:`soft_shadow`).
    margin : int, optional
        Changed pixels are dilated by this many pixels: the reach of
        :func:`bandpass_log`'s response to a moved edge beyond the edge itself,
        about twice its outer scale; the image border too. The edge's own width
        is measured, not part of the margin.

    Returns
    -------
    (H, W) float32 ndarray of 0 / 1
        Zero on changed pixels (the moving shadow edge with its penumbra), on the
        reference's lit / shadow boundary with a penumbra on either side (twice the
        soft-edge width :func:`soft_shadow` measures in this frame), on invalid pixels
        and the border, each widened by `margin`; static shadows and static lit parts
        are kept.
    """
    luma = np.asarray(luma, dtype=np.float32)
    ref = np.asarray(reference_luma, dtype=np.float32)
    lit = np.asarray(lit_reference, dtype=bool)
    changed, width = soft_shadow(luma, ref, lit_reference=lit, gain=gain, max_ratio=max_ratio)
    # the reference's own shadow edge and its soft edge, whose shadow-side half is not lit in the
    # reference (not seen by the ratio test) and changes as the shadow moves on: the penumbra
    # spans about twice the lit-side width measured in this frame (the same sun), on either side
    reach = 1 + 2 * int(np.ceil(2 * width)) if np.isfinite(width) else 3
    kernel = np.ones((reach, reach), np.uint8)
    changed |= cv2.dilate((lit & (cv2.dilate((~lit).astype(np.uint8), np.ones((3, 3), np.uint8)) > 0))
                          .astype(np.uint8), kernel) > 0
    if valid is not None:
        changed |= ~np.asarray(valid, dtype=bool)
    size = 2 * int(margin) + 1
    changed = cv2.dilate(changed.astype(np.uint8), np.ones((size, size), np.uint8)) > 0
    weight = (~changed).astype(np.float32)
    weight[:margin + 1], weight[-margin - 1:] = 0, 0
    weight[:, :margin + 1], weight[:, -margin - 1:] = 0, 0
    return weight


def registration_factor(shape, *, max_size=1536):
    """Integer factor that brings the longer side of `shape` to at most `max_size` pixels.

    Registration and the frame gains work at this reduced size (the shift is
    scaled back); at 24 MP (6000 x 4000) and the default this is 4 (1500 x 1000).

    Parameters
    ----------
    shape : tuple of int
        ``(H, W)`` of the frames.
    max_size : int, optional
        Longest side of the working image, pixels (>= 64).

    Returns
    -------
    int
        >= 1 (1 = full resolution).
    """
    if int(max_size) < 64:
        raise ValueError(f"max_size (registration_size) must be >= 64 pixels; got {max_size}")
    return max(1, -(-max(int(s) for s in shape[:2]) // int(max_size)))


def block_mean(image, factor):
    """Mean over non-overlapping ``factor x factor`` blocks.

    Parameters
    ----------
    image : (H, W) ndarray
    factor : int
        1 returns `image` itself (no copy).

    Returns
    -------
    (H // factor, W // factor) float32 ndarray
        Block ``(i, j)`` averages rows ``factor i .. factor i + factor - 1`` (and
        likewise columns); the remainder rows / columns are dropped. A
        translation ``d`` of `image` is a translation ``d / factor`` of the result.
    """
    image = np.asarray(image)
    check_array(image, "image", ndim=2)
    factor = int(factor)
    if factor < 1:
        raise ValueError(f"factor must be >= 1; got {factor}")
    if factor == 1:
        return image
    height, width = (image.shape[0] // factor) * factor, (image.shape[1] // factor) * factor
    cropped = np.ascontiguousarray(image[:height, :width], dtype=np.float32)
    return cv2.resize(cropped, (width // factor, height // factor), interpolation=cv2.INTER_AREA)


def block_all(mask, factor):
    """True where every pixel of a ``factor x factor`` block is True (see :func:`block_mean`)."""
    mask = np.asarray(mask, dtype=bool)
    if int(factor) == 1:
        return mask
    return block_mean(mask.astype(np.float32), factor) >= np.float32(1.0)


def shift_lucas_kanade_LucasKanade1981(luma, reference_luma, *, weight=None, initial=(0.0, 0.0),
                                       max_iter=10, tol=1e-3, min_weight=200.0, max_shift=5.0, prepared=None):
    """Estimate the translation of a frame relative to the reference.

    Lucas & Kanade (1981), "An iterative image registration technique",
    translation only, Gauss-Newton on band-passed log luminance (the frame is band-passed once
    and its band-pass resampled at each step).

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
    prepared : dict, optional
        `reference_luma`'s band-pass and its gradients (a level of :func:`reference_levels`),
        computed once for every frame registered to it; default: computed here.

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
        weight = np.zeros(luma.shape, dtype=np.float32)
        weight[4:-4, 4:-4] = 1.0
    weight = np.asarray(weight, dtype=np.float32)
    check_same_shape({"luma": luma, "reference_luma": ref, "weight": weight})
    if prepared is None:
        prepared = reference_levels(ref, levels=0)[0]
    elif prepared["luma"].shape != ref.shape:
        raise ValueError(f"prepared reference {prepared['luma'].shape} does not match reference_luma {ref.shape}")
    target, grad_row, grad_col = prepared["target"], prepared["grad_row"], prepared["grad_col"]
    flat = weight.ravel()
    weighted = (flat * grad_row, flat * grad_col)
    normal = np.array([[_dot(weighted[0], grad_row), _dot(weighted[0], grad_col)],
                       [_dot(weighted[1], grad_row), _dot(weighted[1], grad_col)]])
    start = np.asarray(initial, dtype=np.float64).copy()
    shift = start.copy()
    if float(flat.sum(dtype=np.float64)) < min_weight or np.linalg.cond(normal) > 1e8:
        return start, float("nan")
    # the band-pass and the cubic resampling are both convolutions and commute: the frame is
    # band-passed once and its band-pass resampled at every step (resampling log luminance)
    moving = bandpass_log(luma)
    for _ in range(max_iter):
        error = translate(moving, shift, method="cubic_Keys1981").ravel() - target
        step = np.linalg.solve(normal, -np.array([_dot(weighted[0], error), _dot(weighted[1], error)]))
        shift += step
        if np.max(np.abs(shift - start)) > max_shift:
            return start, float("nan")
        if np.max(np.abs(step)) < tol:
            break
    error = translate(moving, shift, method="cubic_Keys1981").ravel() - target
    residual = float(np.sqrt(_dot(flat * error, error) / max(float(flat.sum(dtype=np.float64)), 1.0)))
    return shift, residual


def reference_levels(reference_luma, *, levels):
    """The reference prepared for Lucas-Kanade at every level of :func:`shift_coarse_to_fine`.

    Parameters
    ----------
    reference_luma : (H, W) ndarray
    levels : int
        Coarser levels (each :func:`block_mean` by 2 of the one before).

    Returns
    -------
    list of dict
        Full size first, then each coarser level: ``luma (h, w)`` float32, ``target (h w,)`` its
        :func:`bandpass_log` flattened, ``grad_row``, ``grad_col (h w,)`` the band-pass's
        ``np.gradient``.
    """
    reference = np.asarray(reference_luma, dtype=np.float32)
    check_array(reference, "reference_luma", ndim=2)
    prepared = []
    for level in range(int(levels) + 1):
        if level:
            reference = block_mean(reference, 2)
        target = bandpass_log(reference)
        grad_row, grad_col = (np.ascontiguousarray(g).ravel() for g in np.gradient(target))
        prepared.append({"luma": reference, "target": target.ravel(), "grad_row": grad_row, "grad_col": grad_col})
    return prepared


def _dot(a, b):
    """Sum of ``a * b`` over float32 vectors (BLAS: blocked partial sums)."""
    return float(np.dot(a, b))


def pyramid_levels(shape, *, levels, min_size=64):
    """Number of coarser levels (factor 2 each) of :func:`shift_coarse_to_fine` for `shape`.

    Parameters
    ----------
    shape : tuple of int
        ``(H, W)`` of the images.
    levels : int
        Coarser levels wanted (>= 0).
    min_size : int, optional
        A level is used only if its shorter side keeps at least this many pixels
        (enough texture outside the masked shadow edge and border).

    Returns
    -------
    int
        ``0 .. levels``.
    """
    if int(levels) < 0:
        raise ValueError(f"levels (registration_levels) must be >= 0; got {levels}")
    shorter = min(int(s) for s in shape[:2])
    used = 0
    while used < int(levels) and shorter // 2 ** (used + 1) >= int(min_size):
        used += 1
    return used


def _border(shift):
    """Border, pixels, where an image resampled at `shift` replicates its edge (plus 4)."""
    return int(np.ceil(np.max(np.abs(shift)))) + 4


def _border_weight(weight, border):
    """`weight` with a border of `border` pixels set to zero (a copy)."""
    weight = np.array(weight, dtype=np.float32)
    weight[:border], weight[weight.shape[0] - border:] = 0, 0
    weight[:, :border], weight[:, weight.shape[1] - border:] = 0, 0
    return weight


def shift_coarse_to_fine(luma, reference_luma, *, weight=None, initial=(0.0, 0.0), levels=2, min_size=64,
                         agree=0.5, prepared=None, **options):
    """Estimate a translation that may be large, coarse levels first.

    Each coarser level halves the images (:func:`block_mean`; the weight is kept
    where the whole 2 x 2 block is weighted, :func:`block_all`). Lucas-Kanade
    runs on the coarsest level from ``initial / 2**levels``; its result, doubled,
    starts the next coarser-but-one level, and so on (a level whose estimate
    fails passes its own start on). On the full images Lucas-Kanade runs from
    `initial` and, if the coarse levels ended more than `agree` pixels away,
    also from their estimate; that second solution is kept only if it is
    another one (more than `agree` pixels away) with a lower residual
    (a coarse level with few usable pixels, e.g. when the shadow covers most
    of a small frame, can drift, and must not override a good start). Pixels
    within ``ceil(|start|) + 4`` of the border are left out at every level (the
    resampled frame replicates its edge there).

    Parameters
    ----------
    luma, reference_luma : (H, W) ndarray
    weight : (H, W) ndarray, optional
        Per-pixel weights (e.g. :func:`static_weight`); default: all pixels.
    initial : (2,) array_like, optional
        Starting ``(shift_row, shift_col)`` in pixels of the full images.
    levels : int, optional
        Coarser levels (0: plain :func:`shift_lucas_kanade_LucasKanade1981`);
        fewer where an image would become smaller than `min_size`
        (:func:`pyramid_levels`).
    min_size : int, optional
        Shorter side, pixels, of the coarsest level.
    agree : float, optional
        Pixels (full images): a coarse estimate this close to `initial` is
        within reach of the search from `initial`, which is then the only one;
        solutions this close are the same.
    prepared : list of dict, optional
        :func:`reference_levels` of `reference_luma` with at least the levels used (computed once
        for a sequence registered to one reference); default: computed here.
    **options
        Keyword options of :func:`shift_lucas_kanade_LucasKanade1981` (``max_iter``,
        ``tol``, ``min_weight``, ``max_shift``), used at every level.

    Returns
    -------
    shift : (2,) float64 ndarray
        ``(shift_row, shift_col)`` in pixels of the full images; `initial`
        when every search on the full images failed.
    residual : float
        Of the full images (see :func:`shift_lucas_kanade_LucasKanade1981`); NaN on failure.
    """
    luma = np.asarray(luma, dtype=np.float32)
    ref = np.asarray(reference_luma, dtype=np.float32)
    if luma.ndim != 2 or luma.shape != ref.shape:
        raise ValueError(f"luma {luma.shape} and reference_luma {ref.shape} must be the same (H, W) shape")
    if weight is None:
        weight = np.ones(luma.shape, dtype=np.float32)
    weight = np.asarray(weight, dtype=np.float32)
    check_same_shape({"weight": weight, "luma": luma})
    n_levels = pyramid_levels(luma.shape, levels=levels, min_size=min_size)
    if prepared is None:
        prepared = reference_levels(ref, levels=n_levels)
    elif len(prepared) <= n_levels:
        raise ValueError(f"prepared reference has {len(prepared)} levels; {n_levels + 1} are used")
    start = np.asarray(initial, dtype=np.float64).copy()
    coarse = start
    if n_levels:
        frame, mask = luma, weight
        pyramid = []
        for level in range(1, n_levels + 1):
            frame = block_mean(frame, 2)
            mask = block_all(mask > 0, 2).astype(np.float32)
            pyramid.append((frame, prepared[level], mask))
        coarse = start / 2 ** n_levels
        for frame, reference, mask in pyramid[::-1]:
            coarse, _ = shift_lucas_kanade_LucasKanade1981(frame, reference["luma"], prepared=reference,
                                                           weight=_border_weight(mask, _border(coarse)),
                                                           initial=coarse, **options)
            coarse = coarse * 2
    shift, residual = shift_lucas_kanade_LucasKanade1981(luma, ref, weight=_border_weight(weight, _border(start)),
                                                         initial=start, prepared=prepared[0], **options)
    if np.max(np.abs(coarse - start)) > agree:
        guided, guided_residual = shift_lucas_kanade_LucasKanade1981(
            luma, ref, weight=_border_weight(weight, _border(coarse)), initial=coarse, prepared=prepared[0],
            **options)
        # the guided search counts only if it found another solution, and a better one
        other = not np.isfinite(residual) or np.max(np.abs(guided - shift)) > agree
        if np.isfinite(guided_residual) and other and not guided_residual >= residual:
            shift, residual = guided, guided_residual
    return shift, residual


#: method name -> estimator(luma, reference_luma, **options) -> (shift, residual)
REGISTRATION_METHODS = {"lucas_kanade": shift_lucas_kanade_LucasKanade1981, "coarse_to_fine": shift_coarse_to_fine}
