"""Sky masks of outdoor views: automatic, or from a manifest polygon or mask image.

The sky is never shadowed by the ridge, but its slow dimming and bright
gradient would disturb edge tracking and gain estimation, so it is masked.
The automatic mask grows from the top image border over pixels that are
bluish (``B / (R + G + B)`` above a threshold) and smooth (no strong log-luminance
edge), within a factor of the sky's own median brightness, then closes small
holes. Shadowed terrain is also bluish (sky-lit) but several times darker and
separated from the sky by a strong edge.

Offers
------
auto_sky_mask : automatic sky mask of a (reference) frame.
polygon_mask : pixels whose centre lies inside a (row, col) polygon.
mask_from_image : boolean mask from a mask image (non-zero = sky).
"""

import cv2
import numpy as np
from scipy import ndimage

from shadowcam._shared.validation import check_array


def auto_sky_mask(image, *, min_blue_fraction=0.36, max_log_gradient=0.3, max_log_brightness=0.7,
                  close_radius=1):
    """Return the automatic sky mask of a frame.

    Parameters
    ----------
    image : (H, W, 3) ndarray
        Linear RGB frame (e.g. the registered first frame).
    min_blue_fraction : float, optional
        Minimum ``B / (R + G + B)`` of sky pixels.
    max_log_gradient : float, optional
        Maximum gradient magnitude of ``log Y`` (per pixel) inside the sky.
    max_log_brightness : float, optional
        Sky pixels are within ``exp(+-max_log_brightness)`` of the median
        brightness of the sky pixels of their row band (+-8 rows).
    close_radius : int, optional
        Radius of the morphological closing that fills small holes.

    Returns
    -------
    (H, W) bool ndarray
        True for sky. Empty when no top-border pixel qualifies.
    """
    image = np.asarray(image, dtype=np.float32)
    check_array(image, "image", shape=(None, None, 3))
    # channel by channel: the same sums as ``image.sum(axis=2)`` (bit for bit), without a
    # reduction over a short last axis
    total = image[..., 0] + image[..., 1]
    total += image[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        blue = np.where(total > 0, image[..., 2] / total, 0.0)
    log_y = np.log(np.maximum(total / 3.0, 1e-6))
    smooth = cv2.GaussianBlur(log_y, (0, 0), 0.7)
    grad = np.hypot(cv2.Sobel(smooth, cv2.CV_32F, 1, 0, ksize=3) / 8, cv2.Sobel(smooth, cv2.CV_32F, 0, 1, ksize=3) / 8)
    candidate = (blue >= min_blue_fraction) & (grad <= max_log_gradient)
    sky = _touching_top(candidate)
    if not sky.any():
        return sky
    # brightness consistency per row band (the sky has a vertical gradient)
    height = image.shape[0]
    keep = np.zeros_like(sky)
    for start in range(0, height, 8):
        band = slice(max(0, start - 8), min(height, start + 16))
        values = log_y[band][sky[band]]
        if values.size == 0:
            continue
        rows = slice(start, min(height, start + 8))
        keep[rows] = sky[rows] & (np.abs(log_y[rows] - np.median(values)) <= max_log_brightness)
    sky = _touching_top(keep)
    if close_radius > 0:
        structure = ndimage.generate_binary_structure(2, 1)
        sky = ndimage.binary_closing(sky, structure, iterations=close_radius, border_value=0) | sky
        sky = ndimage.binary_fill_holes(sky)
    return sky


def _touching_top(mask):
    """The connected components (4-neighbourhood) of `mask` that touch its top row."""
    labels, count = ndimage.label(mask)
    touching = np.zeros(count + 1, dtype=bool)
    touching[labels[0]] = True
    touching[0] = False
    return touching[labels]


def polygon_mask(polygon, shape):
    """Return the pixels whose centre lies inside a polygon.

    Parameters
    ----------
    polygon : (N, 2) array_like
        Vertices ``(row, col)`` in pixel-edge coordinates (pixel ``(r, c)``
        covers ``[r, r+1] x [c, c+1]``; its centre is ``(r + 0.5, c + 0.5)``).
    shape : tuple of int
        ``(H, W)``.

    Returns
    -------
    (H, W) bool ndarray
    """
    vertices = np.asarray(polygon, dtype=np.float64)
    if vertices.ndim != 2 or vertices.shape[1] != 2 or len(vertices) < 3:
        raise ValueError(f"polygon must be a list of at least 3 (row, col) vertices; got shape {vertices.shape}")
    height, width = (int(s) for s in shape)
    rows, cols = np.mgrid[0:height, 0:width] + 0.5
    inside = np.zeros((height, width), dtype=bool)
    r0, c0 = vertices[:, 0], vertices[:, 1]
    r1, c1 = np.roll(r0, -1), np.roll(c0, -1)
    for a_r, a_c, b_r, b_c in zip(r0, c0, r1, c1):  # even-odd rule, ray along +col
        crosses = (a_r > rows) != (b_r > rows)
        with np.errstate(divide="ignore", invalid="ignore"):
            at = a_c + (rows - a_r) * (b_c - a_c) / (b_r - a_r)
        inside ^= crosses & (cols < at)
    return inside


def mask_from_image(mask_image, shape):
    """Return a boolean sky mask from a mask image (non-zero = sky).

    Parameters
    ----------
    mask_image : (H, W) or (H, W, C) ndarray
    shape : tuple of int
        Expected ``(H, W)`` of the frames.

    Returns
    -------
    (H, W) bool ndarray
    """
    mask = np.asarray(mask_image)
    if mask.ndim == 3:
        mask = mask.max(axis=2)
    if mask.shape != tuple(shape):
        raise ValueError(f"sky mask image has shape {mask.shape} but the frames are {tuple(shape)}; "
                         "make the mask the size of the frames")
    return mask > 0
