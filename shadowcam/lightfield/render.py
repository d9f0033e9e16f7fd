"""Irradiance of a light field on any plane, flux-conserving.

The rays of a :mod:`shadowcam.lightfield.rays` dataset sit on the near screen's pixel
grid, so neighbouring rays bound ray tubes: each pixel cell carries the flux
``irradiance * cell area`` and keeps it along the tube. On a target plane the cell's
corners land where the four rays hit it; the cell is cut into ``s x s`` sub-cells
(bilinear in the corners, ``s`` chosen so a sub-cell spans at most half a target pixel)
whose flux is splatted bilinearly onto the target grid. Irradiance is flux over target
pixel area. The change of a tube's cross-section is the exact form of the
inverse-square and cosine terms along each ray (for rays from one point it reduces to
``I cos(theta) / d^2``); folded tubes (caustics) add up; no smoothing beyond the
bilinear splat.

Offers
------
plane_frame : origin, col axis, row axis and unit normal of a plane.
splat_bilinear : add weights at fractional (row, col) positions to a grid.
irradiance_on_plane : the rays' irradiance on a plane grid (position, tilt), as a DataArray.
"""

import numpy as np
import xarray as xr

from shadowcam._shared.validation import check_array, check_positive


def plane_frame(centre, normal, up):
    """Origin ``(3,)``, col axis, row axis and unit normal of the plane through `centre`.

    The row axis is `up` made orthogonal to `normal`; the col axis is ``row x normal``
    (for ``normal = +z``, ``up = +y`` it is ``+x``).
    """
    centre = check_array(centre, "centre", shape=(3,)).astype(np.float64)
    n = check_array(normal, "normal", shape=(3,)).astype(np.float64)
    up = check_array(up, "up", shape=(3,)).astype(np.float64)
    if not np.linalg.norm(n) > 0:
        raise ValueError(f"normal must be a non-zero vector; got {n.tolist()}")
    n = n / np.linalg.norm(n)
    e_row = up - (up @ n) * n
    if not np.linalg.norm(e_row) > 1e-9:
        raise ValueError(f"up must not be parallel to normal; got up {up.tolist()}, normal {n.tolist()}")
    e_row /= np.linalg.norm(e_row)
    e_col = np.cross(e_row, n)
    return centre, e_col, e_row, n


def splat_bilinear(rows, cols, weights, shape, *, layer=None, n_layers=1):
    """Sum `weights` at fractional positions into a grid with bilinear (tent) weights.

    Parameters
    ----------
    rows, cols : (N,) ndarray
        Positions in pixel units (pixel centres at integers).
    weights : (N,) ndarray
    shape : (rows, cols)
    layer : (N,) int ndarray, optional, keyword-only
        Layer of each weight in ``[0, n_layers)`` (e.g. a mask bin); others are dropped.
    n_layers : int, keyword-only

    Returns
    -------
    (rows, cols) or (rows, cols, n_layers) float64 ndarray
        Weight outside the grid is dropped; the layer axis is last when `layer` is given.
    """
    r0 = np.floor(rows)
    c0 = np.floor(cols)
    fr = rows - r0
    fc = cols - c0
    r0 = r0.astype(np.int64)
    c0 = c0.astype(np.int64)
    h, w = shape
    k = 1 if layer is None else int(n_layers)
    lay = np.zeros(np.shape(rows), np.int64) if layer is None else np.asarray(layer, np.int64)
    out = np.zeros(h * w * k, np.float64)
    for dr, dc, wt in ((0, 0, (1 - fr) * (1 - fc)), (0, 1, (1 - fr) * fc), (1, 0, fr * (1 - fc)), (1, 1, fr * fc)):
        r = r0 + dr
        c = c0 + dc
        inside = (r >= 0) & (r < h) & (c >= 0) & (c < w) & (lay >= 0) & (lay < k) & np.isfinite(wt)
        out += np.bincount(((r * w + c) * k + lay)[inside], (weights * wt)[inside], minlength=h * w * k)
    return out.reshape(h, w) if layer is None else out.reshape(h, w, k)


def _hits(origin, direction, plane_origin, e_col, e_row, n):
    """Plane coordinates (mm) of rays ``origin + t direction``; NaN for rays parallel to it."""
    with np.errstate(invalid="ignore", divide="ignore"):
        t = ((plane_origin - origin) @ n) / (direction @ n)
        t = np.where(t > -np.inf, t, np.nan)
    hit = origin + t[..., None] * direction - plane_origin
    return hit @ e_col, hit @ e_row


def irradiance_on_plane(rays, *, centre, shape, pixel_size, normal=(0.0, 0.0, 1.0), up=(0.0, 1.0, 0.0),
                        max_subdivision=16):
    """Irradiance of a ray set on a plane grid.

    Parameters
    ----------
    rays : xarray.Dataset
        A rays dataset (:func:`shadowcam.lightfield.rays.rays_dataset`): ``origin`` and
        ``direction`` ``(row, col, axis)`` mm, ``flux`` ``(row, col)`` lm per cell.
    centre : (3,) array_like, keyword-only
        Centre of the target grid, mm.
    shape : (rows, cols), keyword-only
    pixel_size : float, keyword-only
        Target pitch, mm.
    normal, up : (3,) array_like, keyword-only
        Plane normal (tilt) and the direction of increasing rows.
    max_subdivision : int, keyword-only
        Upper bound on sub-cells per cell side.

    Returns
    -------
    xarray.DataArray
        ``(row, col)`` irradiance in lux, with ``y``/``x`` plane coordinates in mm.
    """
    check_positive(pixel_size, "pixel_size", finite=True)
    if len(shape) != 2 or min(shape) < 1:
        raise ValueError(f"shape must be (rows, cols) of positive ints; got {shape}")
    plane = plane_frame(centre, normal, up)
    origin = rays["origin"].values
    direction = rays["direction"].values
    flux = rays["flux"].values
    u, v = _hits(origin, direction, *plane)
    # cells between four neighbouring rays; the cell's flux is the mean of its corners' flux
    corners_u = np.stack([u[:-1, :-1], u[:-1, 1:], u[1:, :-1], u[1:, 1:]])
    corners_v = np.stack([v[:-1, :-1], v[:-1, 1:], v[1:, :-1], v[1:, 1:]])
    cell_flux = 0.25 * (flux[:-1, :-1] + flux[:-1, 1:] + flux[1:, :-1] + flux[1:, 1:])
    good = np.all(np.isfinite(corners_u) & np.isfinite(corners_v), axis=0) & np.isfinite(cell_flux)
    cu = corners_u[:, good] / pixel_size + (shape[1] - 1) / 2
    cv = corners_v[:, good] / pixel_size + (shape[0] - 1) / 2
    cf = cell_flux[good]
    span = max(np.nanmax(np.abs(cu[3] - cu[0])), np.nanmax(np.abs(cu[1] - cu[2])),
               np.nanmax(np.abs(cv[3] - cv[0])), np.nanmax(np.abs(cv[1] - cv[2]))) if cf.size else 0.0
    s = int(np.clip(np.ceil(2 * span), 1, max_subdivision))
    grid = np.zeros(shape, np.float64)
    f = (np.arange(s) + 0.5) / s
    for a in f:          # along the cell's col direction
        for b in f:      # along its row direction
            w00, w01, w10, w11 = (1 - a) * (1 - b), a * (1 - b), (1 - a) * b, a * b
            pr = w00 * cv[0] + w01 * cv[1] + w10 * cv[2] + w11 * cv[3]
            pc = w00 * cu[0] + w01 * cu[1] + w10 * cu[2] + w11 * cu[3]
            grid += splat_bilinear(pr, pc, cf / (s * s), shape)
    irradiance = grid / (pixel_size * 1e-3) ** 2
    rows = (np.arange(shape[0]) - (shape[0] - 1) / 2) * pixel_size
    cols = (np.arange(shape[1]) - (shape[1] - 1) / 2) * pixel_size
    return xr.DataArray(
        irradiance.astype(np.float32), dims=("row", "col"),
        coords={"y": ("row", rows), "x": ("col", cols)},
        attrs={"units": "lx", "long_name": "irradiance on the target plane",
               "plane_centre_mm": list(map(float, plane[0])), "plane_normal": list(map(float, plane[3]))},
    )
