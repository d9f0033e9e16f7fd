"""Screen geometry: camera pixels to metric screen coordinates, screen positions along the axis.

The camera films the translucent screen from the far side; a plane-to-plane
homography maps camera pixel ``(row, col)`` to screen ``(x, y)`` mm (from four or
more markers, or given in the manifest). The screen plane is ``z = position`` mm
along the source's optical axis.

Offers
------
homography_from_markers : 3x3 homography from marker pixels to their screen coordinates (normalised DLT).
screen_coordinates : ``(H, W, 2)`` screen ``x, y`` of every pixel centre and ``(H, W)`` pixel areas.
flux_centroids : the screen point each pixel's flux is centred on (its footprint weighted by the irradiance).
screen_positions : the validated screen entries of a light-field capture description.
"""

import numpy as np

from shadowcam._shared.flux_centroid import flux_centroid_shift
from shadowcam._shared.validation import check_array


def _normaliser(points):
    centre = points.mean(axis=0)
    scale = np.sqrt(2) / max(np.mean(np.linalg.norm(points - centre, axis=1)), 1e-12)
    return np.array([[scale, 0, -scale * centre[0]], [0, scale, -scale * centre[1]], [0, 0, 1]])


def homography_from_markers(pixels, points):
    """Homography from camera pixels to screen coordinates.

    Parameters
    ----------
    pixels : (N, 2) array_like
        Marker ``(row, col)`` in the camera image, N >= 4, not three on a line.
    points : (N, 2) array_like
        The markers' screen ``(x, y)`` mm.

    Returns
    -------
    (3, 3) ndarray
        ``H`` with ``[x, y, 1] ~ H @ [row, col, 1]``.
    """
    pixels = check_array(pixels, "pixels", shape=(None, 2), dtype_kind="iuf").astype(np.float64)
    points = check_array(points, "points", shape=(pixels.shape[0], 2), dtype_kind="iuf").astype(np.float64)
    if pixels.shape[0] < 4:
        raise ValueError(f"pixels must hold at least 4 markers; got {pixels.shape[0]}")
    tp, tq = _normaliser(pixels), _normaliser(points)
    p = (tp @ np.c_[pixels, np.ones(len(pixels))].T).T
    q = (tq @ np.c_[points, np.ones(len(points))].T).T
    rows = []
    for (r, c, _), (x, y, _) in zip(p, q):
        rows.append([r, c, 1, 0, 0, 0, -x * r, -x * c, -x])
        rows.append([0, 0, 0, r, c, 1, -y * r, -y * c, -y])
    _, sv, vt = np.linalg.svd(np.asarray(rows))
    if sv[-2] < 1e-9 * sv[0]:
        raise ValueError("pixels must not be degenerate (three or more markers on one line); got a rank-deficient set")
    h = np.linalg.inv(tq) @ vt[-1].reshape(3, 3) @ tp
    return h / h[2, 2]


def _apply(h, rows, cols):
    w = h[2, 0] * rows + h[2, 1] * cols + h[2, 2]
    return (h[0, 0] * rows + h[0, 1] * cols + h[0, 2]) / w, (h[1, 0] * rows + h[1, 1] * cols + h[1, 2]) / w


def screen_coordinates(homography, shape):
    """Screen coordinates of every pixel centre and the screen area each pixel sees.

    Parameters
    ----------
    homography : (3, 3) array_like
        Pixel ``(row, col, 1)`` to screen ``(x, y, 1)``.
    shape : (H, W)

    Returns
    -------
    xy : (H, W, 2) float64 ndarray
        Screen ``x, y`` mm.
    area : (H, W) float64 ndarray
        mm^2 per pixel (the homography's Jacobian determinant).
    """
    h = check_array(homography, "homography", shape=(3, 3), dtype_kind="iuf").astype(np.float64)
    rows, cols = np.meshgrid(np.arange(shape[0], dtype=np.float64), np.arange(shape[1], dtype=np.float64),
                             indexing="ij")
    x, y = _apply(h, rows, cols)
    eps = 0.5
    xr1, yr1 = _apply(h, rows + eps, cols)
    xr0, yr0 = _apply(h, rows - eps, cols)
    xc1, yc1 = _apply(h, rows, cols + eps)
    xc0, yc0 = _apply(h, rows, cols - eps)
    area = np.abs((xr1 - xr0) * (yc1 - yc0) - (yr1 - yr0) * (xc1 - xc0))
    return np.stack([x, y], -1), area


def flux_centroids(xy, irradiance, *, footprint_variance):
    """Screen point of each pixel's flux: the centroid of its footprint weighted by the irradiance.

    A pixel integrates the screen irradiance ``E`` over its footprint ``w`` (centred on the
    pixel, second moment `footprint_variance` px^2 per axis). A wire's shadow darkens it at
    the flux-weighted mean of the mask coordinates over that footprint, the mask point of
    the ray through the flux-weighted centroid of the footprint, not through the pixel
    centre: the pixel-unit shift of :func:`shadowcam._shared.flux_centroid.flux_centroid_shift`
    (first order, clipped to the footprint), mapped to screen mm by the pixel grid's Jacobian.

    Parameters
    ----------
    xy : (H, W, 2) ndarray
        Screen ``x, y`` mm of each pixel centre (:func:`screen_coordinates`), H, W >= 2.
    irradiance : (H, W) ndarray
        The pixels' irradiance (any positive scale); not finite or <= 0: no shift.
    footprint_variance : float, keyword-only
        Per-axis second moment of a pixel's footprint on the screen, px^2 (>= 0; 1/12 for a
        box pixel, 1/6 for a bilinear (tent) one).

    Returns
    -------
    (H, W, 2) float64 ndarray
        Screen ``x, y`` mm of each pixel's flux centroid.
    """
    xy = check_array(xy, "xy", ndim=3, dtype_kind="f")
    irradiance = check_array(irradiance, "irradiance", shape=xy.shape[:2], dtype_kind="iuf").astype(np.float64)
    if xy.shape[2] != 2 or min(xy.shape[:2]) < 2:
        raise ValueError(f"xy must have shape (H, W, 2) with H, W >= 2; got {xy.shape}")
    shift, _ = flux_centroid_shift(irradiance, footprint_variance=footprint_variance)
    shift = (shift[..., 0], shift[..., 1])
    return xy + shift[0][..., None] * np.gradient(xy, axis=0) + shift[1][..., None] * np.gradient(xy, axis=1)


def screen_positions(capture):
    """The screen entries of a light-field capture description, validated.

    Parameters
    ----------
    capture : dict
        ``{"screens": [{"name": str, "position_mm": float, "homography": 3x3}, ...]}`` as in
        a ``kind: lightfield`` manifest entry.

    Returns
    -------
    list of dict
        The screens sorted by position (nearest first), with ``homography`` as an array.
    """
    screens = capture.get("screens") if isinstance(capture, dict) else None
    if not isinstance(screens, list) or len(screens) < 2:
        raise ValueError("screens must list at least two screen positions; got "
                         f"{screens!r}: add a 'screens' entry per screen position to the manifest")
    out = []
    for i, screen in enumerate(screens):
        for key in ("name", "position_mm", "homography"):
            if key not in screen:
                raise ValueError(f"screens[{i}].{key} must be given; got the keys {sorted(screen)}: "
                                 f"add it to the manifest")
        position = screen["position_mm"]
        if not isinstance(position, (int, float)) or not np.isfinite(position) or position <= 0:
            raise ValueError(f"screens[{i}].position_mm must be a number > 0; got {position!r}")
        out.append({**screen, "position_mm": float(position),
                    "homography": check_array(screen["homography"], f"screens[{i}].homography",
                                              shape=(3, 3), dtype_kind="iuf").astype(np.float64)})
    positions = [s["position_mm"] for s in out]
    if len(set(positions)) != len(positions):
        raise ValueError(f"screens position_mm must differ; got {positions}")
    return sorted(out, key=lambda s: s["position_mm"])
