"""Virtual intrinsics of a shadow camera (paper Fig. 12): skew, aspect and size of the output.

The dual coordinates ``(u, v)`` of the linear camera are metric (one dual pixel per mask
step in both directions, perpendicular axes). The user chooses the virtual intrinsics of the
output image: a skew angle (the angle by which the output's column axis leans from
perpendicular to its row axis), an aspect ratio (row scale / column scale), a scale and a
size. They form the 2 x 3 affine ``K`` from ``(u, v, 1)`` to output pixel-centre
coordinates ``(x, y)``; the dual view is resampled onto it with
:func:`shadowcam.cameras.dual_view.resample_dual_view` on the transformed coordinates.

The same geometry is measured from data: the virtual image of two sweeps a, b has the pixel
coordinates ``(t_a, t_b)``; fitted against the metric dual coordinates of known scene points,
``(t_a, t_b) = J (u, v) + c``, its skew is ``90 deg`` minus the angle between the rows of
``J`` (the two sweeps' motion directions; the slant of one wire against the other) and its
stretch is ``|J_a| / |J_b|`` (the speed ratio ``sigma_b / sigma_a``).

Offers
------
intrinsics_affine : the 2 x 3 affine ``(u, v, 1) -> (x, y)`` and output shape of chosen intrinsics.
apply_affine : apply a 2 x 3 affine to coordinate maps.
resample_to_intrinsics : the dual view resampled onto the chosen intrinsics.
measure_skew_stretch : skew angle and stretch of virtual coordinates against metric ones.
INTRINSICS_OPTIONS : keys of the virtual intrinsics (config ``dual_view.intrinsics``).
coords_to_intrinsics : dual coordinates moved onto the output grid of chosen intrinsics.
"""

import math

import numpy as np

from shadowcam._shared.validation import check_array, check_in_interval, check_positive
from shadowcam.cameras.dual_view import resample_dual_view

#: keys of the virtual intrinsics of the dual view (config ``dual_view.intrinsics``)
INTRINSICS_OPTIONS = ("skew_deg", "aspect", "size")


def intrinsics_affine(dual_shape, *, skew_deg=0.0, aspect=1.0, scale=1.0, shape=None):
    """The affine of chosen virtual intrinsics and the output size.

    ``x = scale (u' + tan(skew) v') + x0``, ``y = scale aspect v' + y0`` with
    ``(u', v') = (u - (N_u-1)/2, v - (N_v-1)/2)``; ``(x0, y0)`` centres the dual grid in the
    output.

    Parameters
    ----------
    dual_shape : (int, int)
        ``(N_v, N_u)`` of the metric dual grid.
    skew_deg : float, keyword-only
        Skew angle in (-80, 80) degrees.
    aspect : float
        Row scale / column scale, > 0.
    scale : float
        Output pixels per dual pixel along the columns, > 0.
    shape : (int, int), optional
        ``(height, width)`` of the output; default the bounding box of the mapped grid.

    Returns
    -------
    affine : (2, 3) float64 ndarray
    shape : (int, int)
    """
    n_v, n_u = (int(n) for n in dual_shape)
    if n_v < 1 or n_u < 1:
        raise ValueError(f"dual_shape must be two positive sizes; got {dual_shape}")
    check_in_interval(skew_deg, "skew_deg", -80.0, 80.0, closed="neither")
    check_positive(aspect, "aspect", finite=True)
    check_positive(scale, "scale", finite=True)
    linear = scale * np.array([[1.0, math.tan(math.radians(skew_deg))], [0.0, aspect]])
    half = np.array([(n_u - 1) / 2, (n_v - 1) / 2])
    corners = np.array([[-1, -1], [1, -1], [-1, 1], [1, 1]]) * (half + 0.5) @ linear.T
    extent = corners.max(axis=0) - corners.min(axis=0)
    if shape is None:
        shape = (max(1, math.ceil(extent[1] - 1e-9)), max(1, math.ceil(extent[0] - 1e-9)))
    height, width = (int(n) for n in shape)
    if height < 1 or width < 1:
        raise ValueError(f"shape must be two positive sizes; got {shape}")
    offset = np.array([(width - 1) / 2, (height - 1) / 2]) - linear @ half
    return np.column_stack([linear, offset]), (height, width)


def apply_affine(affine, u, v):
    """``(x, y) = affine @ (u, v, 1)`` elementwise; NaN stays NaN.

    Parameters
    ----------
    affine : (2, 3) array_like
    u, v : ndarray of one shape

    Returns
    -------
    x, y : float64 ndarrays of that shape
    """
    k = check_array(np.asarray(affine, dtype=np.float64), "affine", shape=(2, 3))
    u, v = np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64)
    if u.shape != v.shape:
        raise ValueError(f"u and v must have one shape; got {u.shape} and {v.shape}")
    return k[0, 0] * u + k[0, 1] * v + k[0, 2], k[1, 0] * u + k[1, 1] * v + k[1, 2]


def resample_to_intrinsics(colours, u, v, *, affine, shape, valid=None, method="mesh", **params):
    """The dual view on the output grid of chosen virtual intrinsics.

    Parameters
    ----------
    colours : (rows, cols, C) ndarray
        Camera colours.
    u, v : (rows, cols) ndarray
        Metric dual coordinates of each camera pixel.
    affine, shape
        From :func:`intrinsics_affine`.
    valid, method, **params
        As :func:`shadowcam.cameras.dual_view.resample_dual_view`.

    Returns
    -------
    image : (height, width, C) float32 ndarray
    coverage : (height, width) float32 ndarray
    """
    x, y = apply_affine(affine, u, v)
    return resample_dual_view(colours, x, y, shape=tuple(shape), valid=valid, method=method,
                              **params)


def measure_skew_stretch(t_a, t_b, u, v, *, min_points=10):
    """Skew angle and stretch of virtual coordinates against the metric dual coordinates.

    Parameters
    ----------
    t_a, t_b : ndarray
        Virtual coordinates (e.g. two sweeps' shadow times, or an output grid's x, y) of
        known scene points.
    u, v : ndarray
        Their metric dual coordinates (same shape; NaN = unknown).
    min_points : int
        Points with all four values needed.

    Returns
    -------
    dict
        ``skew_deg`` (90 minus the angle between the two coordinates' gradients in the
        (u, v) plane), ``stretch`` (``|grad t_a| / |grad t_b|``), ``jacobian`` (2 x 2),
        ``residual_rms`` (virtual pixels), ``n_points``.
    """
    arrays = [np.asarray(x, dtype=np.float64).ravel() for x in (t_a, t_b, u, v)]
    if len({a.size for a in arrays}) != 1:
        raise ValueError(f"t_a, t_b, u, v must have one size; got {[a.size for a in arrays]}")
    ok = np.all(np.isfinite(np.stack(arrays)), axis=0)
    if ok.sum() < int(min_points):
        raise ValueError(f"t_a: only {int(ok.sum())} points have all four coordinates; "
                         f"at least min_points = {min_points} are needed")
    t_a, t_b, u, v = (a[ok] for a in arrays)
    design = np.column_stack([u, v, np.ones(u.size)])
    coef, *_ = np.linalg.lstsq(design, np.column_stack([t_a, t_b]), rcond=None)
    jac = coef[:2].T  # rows: gradients of t_a and t_b
    residual = design @ coef - np.column_stack([t_a, t_b])
    norm_a, norm_b = np.linalg.norm(jac, axis=1)
    cosine = np.clip(jac[0] @ jac[1] / (norm_a * norm_b), -1.0, 1.0)
    return {"skew_deg": 90.0 - math.degrees(math.acos(abs(cosine))), "stretch": norm_a / norm_b,
            "jacobian": jac, "residual_rms": float(np.sqrt(np.mean(residual**2))),
            "n_points": int(u.size)}


def coords_to_intrinsics(coords, *, skew_deg=0.0, aspect=1.0, size=None):
    """Dual coordinates moved onto the output grid of chosen virtual intrinsics.

    The dual view resampled from the returned coordinates
    (:func:`shadowcam.cameras.dual_view.dual_view_from_coords`) is the view of the chosen
    intrinsics (:func:`intrinsics_affine` with ``scale`` 1).

    Parameters
    ----------
    coords : xarray.Dataset
        ``u``, ``v``, ``valid`` over ``(row, col)`` (metric dual pixels); attrs
        ``dual_height``, ``dual_width``.
    skew_deg, aspect : float, keyword-only
        As :func:`intrinsics_affine`.
    size : (int, int), optional
        ``(height, width)`` of the output; default the bounding box of the mapped grid.

    Returns
    -------
    xarray.Dataset
        A copy with ``u``, ``v`` in output pixels; attrs ``dual_height``, ``dual_width`` of the
        output, ``intrinsics_affine`` (the 2 x 3 affine, row-major) and ``intrinsics`` (text).
    """
    if size is not None and (np.ndim(size) != 1 or len(size) != 2):
        raise ValueError(f"size must be (height, width); got {size!r}")
    dual_shape = (int(coords.attrs["dual_height"]), int(coords.attrs["dual_width"]))
    affine, shape = intrinsics_affine(dual_shape, skew_deg=skew_deg, aspect=aspect,
                                      shape=None if size is None else tuple(size))
    x, y = apply_affine(affine, coords["u"].values, coords["v"].values)
    out = coords.copy()
    out["u"] = out["u"].copy(data=x.astype(np.float32))
    out["v"] = out["v"].copy(data=y.astype(np.float32))
    out.attrs.update(dual_height=int(shape[0]), dual_width=int(shape[1]),
                     intrinsics_affine=affine.ravel(),
                     intrinsics=f"skew {skew_deg:g} deg, aspect {aspect:g}, "
                                f"{shape[0]}x{shape[1]} px")
    return out
