"""Irradiance of a light field on any plane, flux-conserving, with exact area weights.

The rays of a :mod:`shadowcam.lightfield.rays` dataset sit at the near screen's pixel
centres; each pixel is a ray tube carrying the pixel's flux ``irradiance * pixel area``
along it. On a target plane the tube's corners land where the ray map, interpolated
to the pixel's corners (the mean of the four surrounding rays' hits, linearly
extrapolated at the border), puts them. The tube's image is cut into triangles along
both diagonals (each carrying a quarter of the flux, so no diagonal is preferred), and
each triangle's flux is spread uniformly over it and given to every target pixel in
proportion to the exact area of their intersection (a conservative rasterisation: no
filter beyond the target pixel itself). Irradiance is flux over target pixel area. On
the near screen itself this reproduces the captured image; the change of a tube's
cross-section is the exact form of the inverse-square and cosine terms along each ray
(for rays from one point it reduces to ``I cos(theta) / d^2``); folded tubes
(caustics) add up.

Offers
------
plane_frame : origin, col axis, row axis and unit normal of a plane.
splat_bilinear : add weights at fractional (row, col) positions to a grid.
splat_polygons : spread weights uniformly over polygons onto a grid with exact area weights.
tube_triangles : the triangles of the pixel ray tubes of a grid of plane hits.
splat_tubes : the flux of a grid of ray tubes on a square grid of any 2-D chart, by exact area.
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


def _quadrant_area(x, y, qx, qy):
    """Signed area of polygons ``(x, y)`` ``(N, V)`` inside the quadrants ``x <= qx, y <= qy`` ``(N, K)``.

    Clamping a closed curve onto a quadrant keeps its winding number around every
    point inside, so the area is the shoelace area of the clamped boundary; each edge
    is split where it crosses ``x = qx`` or ``y = qy`` so that the clamp is affine on
    every piece. Returns ``(N, K)``.
    """
    x0, y0 = x[:, None, :], y[:, None, :]
    x1, y1 = np.roll(x, -1, axis=1)[:, None, :], np.roll(y, -1, axis=1)[:, None, :]
    qx, qy = qx[..., None], qy[..., None]
    dx, dy = x1 - x0, y1 - y0
    with np.errstate(invalid="ignore", divide="ignore"):
        tx = np.clip(np.where(dx != 0, (qx - x0) / dx, 0.0), 0.0, 1.0)
        ty = np.clip(np.where(dy != 0, (qy - y0) / dy, 0.0), 0.0, 1.0)
    ts = (np.zeros_like(tx), np.minimum(tx, ty), np.maximum(tx, ty), np.ones_like(tx))
    px = [np.minimum(x0 + t * dx, qx) for t in ts]
    py = [np.minimum(y0 + t * dy, qy) for t in ts]
    twice = sum(px[i] * py[i + 1] - px[i + 1] * py[i] for i in range(3))
    return 0.5 * twice.sum(axis=-1)


def splat_polygons(rows, cols, weights, shape):
    """Spread each weight uniformly over its polygon and sum it into a grid by exact area.

    Parameters
    ----------
    rows, cols : (N, V) ndarray
        Polygon vertices in pixel units (pixel ``(i, j)`` covers ``[i - 1/2, i + 1/2] x
        [j - 1/2, j + 1/2]``); polygons must not self-intersect (e.g. triangles),
        either orientation.
    weights : (N,) ndarray
    shape : (rows, cols)

    Returns
    -------
    (rows, cols) float64 ndarray
        Each pixel holds ``sum weight * area(polygon & pixel) / area(polygon)``; weight
        outside the grid is dropped; a polygon of (nearly) zero area gives its weight
        to the pixel of its centroid.
    """
    rows = np.asarray(rows, np.float64)
    cols = np.asarray(cols, np.float64)
    weights = np.asarray(weights, np.float64)
    h, w = shape
    out = np.zeros(h * w, np.float64)
    keep = np.all(np.isfinite(rows) & np.isfinite(cols), axis=1) & np.isfinite(weights) & (weights != 0)
    rows, cols, weights = rows[keep], cols[keep], weights[keep]
    x0, y0 = np.roll(cols, -1, axis=1), np.roll(rows, -1, axis=1)
    area = 0.5 * np.sum(cols * y0 - x0 * rows, axis=1)
    tiny = np.abs(area) < 1e-9
    if tiny.any():  # degenerate tubes: the whole weight at the centroid's pixel
        r = np.rint(rows[tiny].mean(axis=1)).astype(np.int64)
        c = np.rint(cols[tiny].mean(axis=1)).astype(np.int64)
        inside = (r >= 0) & (r < h) & (c >= 0) & (c < w)
        out += np.bincount((r * w + c)[inside], weights[tiny][inside], minlength=h * w)
        rows, cols, weights, area = rows[~tiny], cols[~tiny], weights[~tiny], area[~tiny]
    # lattice lines bounding each polygon; group polygons by how many pixels they span
    r_lo = np.floor(rows.min(axis=1) + 0.5).astype(np.int64)
    c_lo = np.floor(cols.min(axis=1) + 0.5).astype(np.int64)
    span = np.maximum(np.floor(rows.max(axis=1) + 0.5).astype(np.int64) - r_lo,
                      np.floor(cols.max(axis=1) + 0.5).astype(np.int64) - c_lo) + 1
    visible = (r_lo + span > 0) & (r_lo < h) & (c_lo + span > 0) & (c_lo < w)
    for k in np.unique(span[visible]):
        sel = np.flatnonzero(visible & (span == k))
        for part in np.array_split(sel, max(1, sel.size * (k + 1) ** 2 // 200_000)):
            offsets = np.arange(k + 1)
            qy = (r_lo[part, None] + offsets[None, :] - 0.5)[:, :, None] + np.zeros(k + 1)
            qx = (c_lo[part, None] + offsets[None, :] - 0.5)[:, None, :] + np.zeros((k + 1, 1))
            a = _quadrant_area(cols[part], rows[part], qx.reshape(part.size, -1),
                               qy.reshape(part.size, -1)).reshape(part.size, k + 1, k + 1)
            cell = a[:, 1:, 1:] - a[:, :-1, 1:] - a[:, 1:, :-1] + a[:, :-1, :-1]
            share = cell * (weights[part] / area[part])[:, None, None]
            r = r_lo[part, None, None] + np.arange(k)[None, :, None]
            c = c_lo[part, None, None] + np.arange(k)[None, None, :]
            r, c = np.broadcast_arrays(r, c)
            inside = (r >= 0) & (r < h) & (c >= 0) & (c < w)
            out += np.bincount((r * w + c)[inside], share[inside], minlength=h * w)
    return out.reshape(h, w)


def tube_triangles(u, v):
    """Triangles of the pixel ray tubes whose rays hit a plane at ``(u, v)``.

    Parameters
    ----------
    u, v : (H, W) ndarray
        Plane coordinates of the rays through the pixel centres.

    Returns
    -------
    tri_u, tri_v : (4, H, W, 3) ndarray
        Four triangles per pixel (the pixel's corner quad cut along both diagonals); each
        covers half the pixel, so each carries a quarter of its flux. Corners are the mean
        of the four surrounding rays' hits (linear extrapolation beyond the border).
    """
    def corners(a):
        a = np.pad(a, 1, mode="reflect", reflect_type="odd")
        return 0.25 * (a[:-1, :-1] + a[:-1, 1:] + a[1:, :-1] + a[1:, 1:])

    out = []
    for a in (u, v):
        c = corners(a)
        c00, c01, c10, c11 = c[:-1, :-1], c[:-1, 1:], c[1:, :-1], c[1:, 1:]
        out.append(np.stack([np.stack(t, -1) for t in ((c00, c01, c11), (c00, c11, c10),
                                                        (c00, c01, c10), (c01, c11, c10))]))
    return out[0], out[1]


def splat_tubes(u, v, flux, *, shape, pitch):
    """Flux of a grid of ray tubes summed into a square grid, by exact area shares.

    The chart ``(u, v)`` may be a plane's coordinates (irradiance) or an equal-area
    chart of directions (intensity, :mod:`shadowcam.lightfield.photometry_export`).

    Parameters
    ----------
    u, v : (H, W) ndarray
        Chart coordinates of the rays through the tubes' centres (:func:`tube_triangles`).
    flux : (H, W) ndarray
        Flux of each tube.
    shape : (rows, cols), keyword-only
        Target grid, centred on the chart's origin; cols along ``u``, rows along ``v``.
    pitch : float, keyword-only
        Cell size in chart units.

    Returns
    -------
    (rows, cols) float64 ndarray
        Flux per cell (flux outside the grid is dropped); >= 0 where every flux is.
    """
    tri_u, tri_v = tube_triangles(u, v)
    weights = np.broadcast_to(0.25 * np.asarray(flux, np.float64), tri_u.shape[:3])
    cols = tri_u.reshape(-1, 3) / pitch + (shape[1] - 1) / 2
    rows = tri_v.reshape(-1, 3) / pitch + (shape[0] - 1) / 2
    grid = splat_polygons(rows, cols, weights.ravel(), shape)
    # shares of a flux >= 0 are >= 0: the quadrant areas' differences leave round-off below 0
    return np.maximum(grid, 0.0) if not np.any(weights < 0) else grid


def irradiance_on_plane(rays, *, centre, shape, pixel_size, normal=(0.0, 0.0, 1.0), up=(0.0, 1.0, 0.0)):
    """Irradiance of a ray set on a plane grid.

    Parameters
    ----------
    rays : xarray.Dataset
        A rays dataset (:func:`shadowcam.lightfield.rays.rays_dataset`): ``origin`` and
        ``direction`` ``(row, col, axis)`` mm, ``flux`` ``(row, col)`` lm per pixel.
    centre : (3,) array_like, keyword-only
        Centre of the target grid, mm.
    shape : (rows, cols), keyword-only
    pixel_size : float, keyword-only
        Target pitch, mm.
    normal, up : (3,) array_like, keyword-only
        Plane normal (tilt) and the direction of increasing rows.

    Returns
    -------
    xarray.DataArray
        ``(row, col)`` irradiance in lux (mean over each target pixel), with ``y``/``x``
        plane coordinates in mm.
    """
    check_positive(pixel_size, "pixel_size", finite=True)
    if len(shape) != 2 or min(shape) < 1:
        raise ValueError(f"shape must be (rows, cols) of positive ints; got {shape}")
    plane = plane_frame(centre, normal, up)
    u, v = _hits(rays["origin"].values, rays["direction"].values, *plane)
    irradiance = splat_tubes(u, v, rays["flux"].values, shape=shape, pitch=pixel_size) / (pixel_size * 1e-3) ** 2
    rows = (np.arange(shape[0]) - (shape[0] - 1) / 2) * pixel_size
    cols = (np.arange(shape[1]) - (shape[1] - 1) / 2) * pixel_size
    return xr.DataArray(
        irradiance.astype(np.float32), dims=("row", "col"),
        coords={"y": ("row", rows), "x": ("col", cols)},
        attrs={"units": "lx", "long_name": "irradiance on the target plane",
               "plane_centre_mm": list(map(float, plane[0])), "plane_normal": list(map(float, plane[3]))},
    )
