"""Dual view: resample camera colours onto the ``(v, u)`` dual grid.

By Helmholtz reciprocity (paper section II-A) the dual image at ``(u, v)`` is
the camera colour of the pixel whose dual coordinates are ``(u, v)``. The
camera pixels give scattered samples in the dual grid; two resamplers turn
them into an image, neither of them last-write-wins splatting:

* ``mesh``: forward mesh warp. The camera pixel grid is split into triangles
  (two per 2x2 pixel quad), their vertices moved to ``(u, v)`` and each
  triangle rasterised at the dual pixel centres it covers with barycentric
  colour interpolation. Which triangles to keep is decided on the camera
  side: their three pixels must have dual coordinates (all timed) and none of
  their edges may straddle a discontinuity. The dual coordinates are smooth
  functions of the shadow times, so on one continuous surface the dual step
  between neighbouring camera pixels changes little from one pixel to the next
  (however much the optics magnify); a step across a depth or shadow-time
  discontinuity differs from the steps before and after it along the same
  camera line (`continuous_steps`). Steps up to ``max_edge`` dual pixels are
  below the timing noise's reach and always kept. Where several triangles
  cover a dual pixel their colours are averaged. Fully vectorised (triangles are expanded to candidate
  pixels of their bounding boxes, in bounded-memory chunks).
  With ``density=True`` each triangle's colour is weighted by the camera-pixel
  density ``1 / |det d(u, v)/d(col, row)|`` (its Jacobian smoothed over the mesh,
  `mesh_smoothed_areas`) and the triangles covering a dual pixel are summed, not
  averaged (pixel-transport reciprocity, docs/methods.md): the dual image is the
  reciprocal image, for a pinhole as for a camera behind a mirror or glass, whose
  branches add up. The front function `dual_view_from_coords` carries it by default.
* ``idw``: inverse-distance weighting of the ``k`` nearest camera samples
  within ``radius`` dual pixels (``scipy.spatial.cKDTree``).

Dual pixels without a sample stay NaN and ``coverage`` is False there.

Offers
------
DUAL_VIEW_METHODS : name -> resampler, ``mesh`` and ``idw``.
continuous_steps : camera-side test that a neighbour step does not straddle a discontinuity.
mesh_smoothed_areas : triangle areas averaged over their mesh neighbourhood.
dual_view_mesh : forward mesh warp.
dual_view_idw : k-nearest inverse-distance weighting.
resample_dual_view : dispatch through `DUAL_VIEW_METHODS` with input checks.
reference_image : the image of a decoded reference frame store.
camera_colours : the camera colours to resample (reference frame or mean lit image).
dual_view_dataset : assemble the ``dual_view`` xarray Dataset.
dual_view_from_coords : dual-coordinates + shadow-time datasets -> dual-view dataset.
"""

import json
import logging
import time

import numpy as np
import xarray as xr
from scipy.spatial import cKDTree

from shadowcam._shared.coverage import MIN_COVERAGE, check_coverage
from shadowcam._shared.validation import check_array, check_in, check_in_interval

log = logging.getLogger(__name__)

#: candidate (triangle, dual pixel) pairs processed at once by the mesh warp
_CHUNK_CANDIDATES = 1 << 21


def _grid_triangles(rows, cols):
    """Vertex indices ``(n, 3)`` of the two triangles of every 2x2 pixel quad."""
    r, c = np.mgrid[0 : rows - 1, 0 : cols - 1]
    tl = (r * cols + c).ravel()
    tr, bl, br = tl + 1, tl + cols, tl + cols + 1
    return np.concatenate([np.stack([tl, tr, bl], 1), np.stack([br, bl, tr], 1)])


def continuous_steps(u, v, *, valid, step, max_edge=2.0, smooth_tol=2.0 / 3.0):
    """Whether the dual step between each camera pixel and its neighbour is continuous.

    The step ``d_i`` from pixel ``p`` to ``p + step`` is compared with the steps
    ``d_{i-1}`` (from ``p - step``) and ``d_{i+1}`` (from ``p + step`` to
    ``p + 2 step``) along the same camera line. It is continuous when
    ``|d_i| <= max_edge`` or when every neighbouring step with both pixels valid
    agrees with it, ``|d_i - d_n| <= smooth_tol * max(|d_i|, |d_n|)``, and at
    least one does. A step across a discontinuity is much longer (or turned)
    than the steps on either side; a step on a surface that the optics magnify
    is long, but so are its neighbours.

    Parameters
    ----------
    u, v : (rows, cols) ndarray
        Dual coordinates of the camera pixel centres (dual pixels).
    valid : (rows, cols) bool ndarray, keyword-only
        Pixels with usable dual coordinates.
    step : (int, int)
        Camera neighbour offset ``(d_row, d_col)``, e.g. ``(0, 1)`` or ``(1, 0)``.
    max_edge : float
        Steps up to this length (dual pixels) are always continuous.
    smooth_tol : float
        Largest change of a step relative to its neighbour, in ``(0, 1)``.

    Returns
    -------
    (rows, cols) bool ndarray
        True at ``p`` when ``p`` and ``p + step`` are valid and the step between them is
        continuous; False where ``p + step`` is outside the grid.
    """
    rows, cols = u.shape
    dr, dc = (int(s) for s in step)
    ok = valid & np.isfinite(u) & np.isfinite(v)
    pad = 3 * max(abs(dr), abs(dc))
    pu = np.pad(np.asarray(u, dtype=np.float64), pad, constant_values=np.nan)
    pv = np.pad(np.asarray(v, dtype=np.float64), pad, constant_values=np.nan)
    pok = np.pad(ok, pad, constant_values=False)
    pu[~pok] = np.nan
    pv[~pok] = np.nan

    def shifted(a, k):  # a[p + k step] over the camera grid
        return a[pad + k * dr : pad + k * dr + rows, pad + k * dc : pad + k * dc + cols]

    def d(k):  # step from p + k step to p + (k + 1) step, NaN unless both valid
        return shifted(pu, k + 1) - shifted(pu, k), shifted(pv, k + 1) - shifted(pv, k)

    du, dv = d(0)
    length = np.hypot(du, dv)
    agree_all = np.ones((rows, cols), dtype=bool)
    any_neighbour = np.zeros((rows, cols), dtype=bool)
    for k in (-1, 1):
        nu, nv = d(k)
        n_len = np.hypot(nu, nv)
        present = np.isfinite(n_len)
        with np.errstate(invalid="ignore"):
            agree = np.hypot(du - nu, dv - nv) <= smooth_tol * np.maximum(length, n_len)
        agree_all &= agree | ~present
        any_neighbour |= present
    with np.errstate(invalid="ignore"):
        return np.isfinite(length) & ((length <= max_edge) | (agree_all & any_neighbour))


def mesh_smoothed_areas(triangles, areas, *, n_vertices, passes):
    """Average triangle areas over their mesh neighbourhood, never across a missing triangle.

    Each pass averages the areas of the triangles meeting at each vertex, then gives each
    triangle the mean of its three vertices' averages: a diffusion over the kept mesh, so a
    surface's neighbours on the other side of a silhouette (no triangle joins them) never
    mix in. ``passes`` passes reach about ``passes`` camera pixels.

    Parameters
    ----------
    triangles : (n, 3) int ndarray
        Vertex indices of the kept triangles.
    areas : (n,) float ndarray
        Their absolute areas (dual pixels per camera triangle).
    n_vertices : int
    passes : int
        0 returns `areas` unchanged.

    Returns
    -------
    (n,) float64 ndarray
    """
    if int(passes) != passes or passes < 0:
        raise ValueError(f"passes must be an integer >= 0; got {passes!r}")
    smoothed = np.asarray(areas, dtype=np.float64)
    if len(triangles) == 0:
        return smoothed
    flat = np.asarray(triangles).ravel()
    count = np.maximum(np.bincount(flat, minlength=n_vertices), 1)
    for _ in range(int(passes)):
        per_vertex = np.bincount(flat, weights=np.repeat(smoothed, 3), minlength=n_vertices) / count
        smoothed = per_vertex[triangles].mean(axis=1)
    return smoothed


def dual_view_mesh(colours, u, v, *, valid, shape, max_edge=2.0, smooth_tol=2.0 / 3.0, density=False,
                   density_passes=2, three_corners=False, eps=1e-9):
    """Forward mesh warp of camera colours into the dual grid.

    Parameters
    ----------
    colours : (rows, cols, channel) ndarray
        Linear camera colours.
    u, v : (rows, cols) ndarray
        Dual coordinates of the camera pixel centres (dual pixels).
    valid : (rows, cols) bool ndarray, keyword-only
        Pixels with usable coordinates and colours.
    shape : (int, int)
        ``(height, width)`` of the dual grid.
    max_edge : float
        Edges up to this length (dual pixels) are always kept (see `continuous_steps`).
    smooth_tol : float
        Largest relative change of a longer edge's dual step from the neighbouring
        steps along the same camera line (see `continuous_steps`).
    density : bool
        Carry the camera-pixel density of pixel-transport reciprocity: each triangle
        adds its interpolated colour times ``1 / |det d(u, v)/d(col, row)|`` (camera
        pixels per dual pixel) and the triangles covering a dual pixel are *summed*
        (the branches of a mirror or a glass add up), a pixel centre on an edge shared
        by two triangles counted once (top-left rule on the barycentric gradients).
        The image is then the reciprocal image ``T^T 1`` of a uniform camera pattern
        (docs/methods.md) in camera-colour x camera-pixels-per-dual-pixel units. False:
        the colours are averaged (the scene's radiance seen from the light).
    density_passes : int
        Smoothing passes of the triangles' Jacobians before the density is taken
        (:func:`mesh_smoothed_areas`): a Jacobian differenced from noisy dual coordinates is
        noisy, and its inverse more so; the smoothing stays on the surface.
    three_corners : bool
        Also draw the triangle of a quad's three timed pixels when its untimed one lies on
        the fixed diagonal (top-right or bottom-left), where neither fixed triangle exists;
        its two camera edges must be continuous. Where optics magnify, one quad covers
        several dual pixels, many of them next to silhouettes whose pixels get no time.
    eps : float
        Barycentric tolerance for pixel centres on triangle edges.

    Returns
    -------
    image : (height, width, channel) float32 ndarray
        NaN where no triangle covers the dual pixel centre.
    coverage : (height, width) bool ndarray
    """
    check_in_interval(smooth_tol, "smooth_tol", 0.0, 1.0, closed="neither")
    rows, cols, n_ch = colours.shape
    height, width = shape
    across = continuous_steps(u, v, valid=valid, step=(0, 1), max_edge=max_edge, smooth_tol=smooth_tol).ravel()
    down = continuous_steps(u, v, valid=valid, step=(1, 0), max_edge=max_edge, smooth_tol=smooth_tol).ravel()
    tri = _grid_triangles(rows, cols)
    # (tl, tr, bl): edges tl->tr, tl->bl; (br, bl, tr): edges bl->br, tr->br. Two continuous
    # edges put the third vertex on the same surface, so the diagonal needs no test.
    upper = tri[:, 0] + 1 == tri[:, 1]
    tri = tri[np.where(upper, across[tri[:, 0]] & down[tri[:, 0]], across[tri[:, 1]] & down[tri[:, 2]])]
    if three_corners:  # quads whose untimed corner lies on the fixed diagonal: the other diagonal
        tl = (np.arange(rows - 1)[:, None] * cols + np.arange(cols - 1)).ravel()
        tr, bl, br = tl + 1, tl + cols, tl + cols + 1
        ok = valid.ravel() & np.isfinite(u.ravel()) & np.isfinite(v.ravel())
        no_tr = ~ok[tr] & down[tl] & across[bl]  # (tl, bl, br): edges tl->bl, bl->br
        no_bl = ~ok[bl] & across[tl] & down[tr]  # (tl, tr, br): edges tl->tr, tr->br
        tri = np.concatenate([tri, np.stack([tl, bl, br], 1)[no_tr], np.stack([tl, tr, br], 1)[no_bl]])
    uf, vf = u.ravel().astype(np.float64), v.ravel().astype(np.float64)
    pu, pv = uf[tri], vf[tri]  # (n, 3)
    e1u, e1v = pu[:, 1] - pu[:, 0], pv[:, 1] - pv[:, 0]
    e2u, e2v = pu[:, 2] - pu[:, 0], pv[:, 2] - pv[:, 0]
    det = e1u * e2v - e1v * e2u
    nondegenerate = np.abs(det) > 1e-12
    keep = nondegenerate.copy()
    i0 = np.maximum(np.ceil(pu.min(axis=1) - eps), 0).astype(np.int64)
    i1 = np.minimum(np.floor(pu.max(axis=1) + eps), width - 1).astype(np.int64)
    j0 = np.maximum(np.ceil(pv.min(axis=1) - eps), 0).astype(np.int64)
    j1 = np.minimum(np.floor(pv.max(axis=1) + eps), height - 1).astype(np.int64)
    bw, bh = i1 - i0 + 1, j1 - j0 + 1
    keep &= (bw > 0) & (bh > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        weight = np.ones(len(det))
        if density:  # smoothed over every kept triangle, also those covering no dual pixel centre
            weight[nondegenerate] = 1.0 / mesh_smoothed_areas(tri[nondegenerate], np.abs(det[nondegenerate]),
                                                              n_vertices=rows * cols, passes=density_passes)
        # inward gradients of the barycentrics l1, l2, l0 (dual px^-1): an edge owns the
        # centres on it when its gradient points to +u (or +v when along u)
        grads = [(e2v / det, -e2u / det), (-e1v / det, e1u / det)]
        grads.append((-grads[0][0] - grads[1][0], -grads[0][1] - grads[1][1]))
    owns = [(gu > 0) | ((gu == 0) & (gv > 0)) for gu, gv in grads]
    sel = np.nonzero(keep)[0]
    flat_col = colours.reshape(-1, n_ch).astype(np.float64)
    sums = np.zeros((height * width, n_ch))
    counts = np.zeros(height * width)
    cum = np.cumsum((bw * bh)[sel])
    start = 0
    while start < len(sel):  # chunks of about _CHUNK_CANDIDATES candidate pixels
        done = cum[start - 1] if start else 0
        stop = max(int(np.searchsorted(cum, done + _CHUNK_CANDIDATES, side="right")), start + 1)
        part, start = sel[start:stop], stop
        nb = bw[part] * bh[part]
        t = np.repeat(np.arange(len(part)), nb)
        local = np.arange(nb.sum()) - np.repeat(np.cumsum(nb) - nb, nb)
        k = part[t]
        i = i0[k] + local % bw[k]
        j = j0[k] + local // bw[k]
        du, dv = i - pu[k, 0], j - pv[k, 0]
        l1 = (du * e2v[k] - dv * e2u[k]) / det[k]
        l2 = (e1u[k] * dv - e1v[k] * du) / det[k]
        l0 = 1.0 - l1 - l2
        if density:  # counted once: strictly inside, or on an edge the triangle owns
            inside = np.ones(len(k), dtype=bool)
            for lam, own in ((l1, owns[0]), (l2, owns[1]), (l0, owns[2])):
                inside &= (lam > eps) | ((lam >= -eps) & own[k])
        else:
            inside = (l0 >= -eps) & (l1 >= -eps) & (l2 >= -eps)
        k, l0, l1, l2 = k[inside], l0[inside], l1[inside], l2[inside]
        pix = j[inside] * width + i[inside]
        vert = tri[k]
        col = (l0[:, None] * flat_col[vert[:, 0]] + l1[:, None] * flat_col[vert[:, 1]]
               + l2[:, None] * flat_col[vert[:, 2]])
        if density:
            col *= weight[k, None]
        counts += np.bincount(pix, minlength=height * width)
        for ch in range(n_ch):
            sums[:, ch] += np.bincount(pix, weights=col[:, ch], minlength=height * width)
    coverage = counts > 0
    image = np.full((height * width, n_ch), np.nan, dtype=np.float32)
    image[coverage] = sums[coverage] if density else sums[coverage] / counts[coverage, None]
    return image.reshape(height, width, n_ch), coverage.reshape(height, width)


def dual_view_idw(colours, u, v, *, valid, shape, k=8, radius=1.0, power=2.0):
    """Inverse-distance weighting of the nearest camera samples.

    Parameters
    ----------
    colours : (rows, cols, channel) ndarray
    u, v : (rows, cols) ndarray
        Dual coordinates of the camera pixel centres (dual pixels).
    valid : (rows, cols) bool ndarray, keyword-only
    shape : (int, int)
        ``(height, width)`` of the dual grid.
    k : int
        Nearest samples considered per dual pixel.
    radius : float
        Only samples within this distance (dual pixels) contribute.
    power : float
        Weight ``1 / distance ** power`` (a sample exactly at the centre wins).

    Returns
    -------
    image : (height, width, channel) float32 ndarray
    coverage : (height, width) bool ndarray
    """
    height, width = shape
    n_ch = colours.shape[2]
    ok = valid & np.isfinite(u) & np.isfinite(v)
    points = np.column_stack([u[ok], v[ok]]).astype(np.float64)
    samples = colours[ok].astype(np.float64)
    image = np.full((height * width, n_ch), np.nan, dtype=np.float32)
    coverage = np.zeros(height * width, dtype=bool)
    if len(points):
        jj, ii = np.mgrid[0:height, 0:width]
        centres = np.column_stack([ii.ravel(), jj.ravel()]).astype(np.float64)
        dist, idx = cKDTree(points).query(centres, k=k, distance_upper_bound=radius)
        dist, idx = dist.reshape(len(centres), -1), idx.reshape(len(centres), -1)
        found = np.isfinite(dist)
        weight = np.where(found, 1.0 / np.maximum(dist, 1e-9) ** power, 0.0)
        wsum = weight.sum(axis=1)
        coverage = wsum > 0
        safe_idx = np.where(found, idx, 0)
        acc = np.einsum("pk,pkc->pc", weight, samples[safe_idx])
        image[coverage] = acc[coverage] / wsum[coverage, None]
    return image.reshape(height, width, n_ch), coverage.reshape(height, width)


#: dual-view resamplers, name -> function(colours, u, v, *, valid, shape, **params)
DUAL_VIEW_METHODS = {
    "mesh": dual_view_mesh,
    "idw": dual_view_idw,
}


def resample_dual_view(colours, u, v, *, shape, valid=None, method="mesh", **params):
    """Resample camera colours into the dual grid with a method of `DUAL_VIEW_METHODS`.

    Parameters
    ----------
    colours : (rows, cols, channel) ndarray
        Linear camera colours; non-finite colours count as invalid.
    u, v : (rows, cols) ndarray
        Dual coordinates (dual pixels; centre of dual column ``i`` is ``u = i``).
    shape : (int, int), keyword-only
        ``(height, width)`` of the dual grid.
    valid : (rows, cols) bool ndarray, optional
        Default: finite ``u``, ``v``.
    method : str
        Key of `DUAL_VIEW_METHODS`.
    **params
        Method options (``max_edge``, ``smooth_tol`` for mesh; ``k``, ``radius``, ``power`` for idw).

    Returns
    -------
    image : (height, width, channel) float32 ndarray
        NaN = hole.
    coverage : (height, width) bool ndarray
    """
    colours = np.asarray(colours)
    check_array(colours, "colours", ndim=3)
    u, v = np.asarray(u), np.asarray(v)
    if u.shape != colours.shape[:2] or v.shape != colours.shape[:2]:
        raise ValueError(f"u/v: shapes {u.shape}, {v.shape} differ from colours {colours.shape[:2]}")
    check_in(method, "method", DUAL_VIEW_METHODS)
    height, width = (int(s) for s in shape)
    if height < 1 or width < 1:
        raise ValueError(f"shape must be positive; got {shape}")
    ok = np.isfinite(u) & np.isfinite(v) & np.all(np.isfinite(colours), axis=2)
    if valid is not None:
        valid = np.asarray(valid, dtype=bool)
        if valid.shape != u.shape:
            raise ValueError(f"valid: shape {valid.shape} differs from u {u.shape}")
        ok &= valid
    return DUAL_VIEW_METHODS[method](colours, u, v, valid=ok, shape=(height, width), **params)


def reference_image(reference):
    """The reference frame of a decoded reference store as an image.

    Parameters
    ----------
    reference : xarray.Dataset
        Frame store with ``image ([time,] row, col, channel)`` (several frames are averaged).

    Returns
    -------
    (rows, cols, channel) ndarray
    """
    image = reference["image"]
    if "time" in image.dims:
        image = image.mean("time")
    return image.transpose("row", "col", "channel").values


def camera_colours(shadow_time, *, reference=None, sweeps=("u", "v")):
    """Camera colours to resample: the reference frame, else the mean lit image.

    Parameters
    ----------
    shadow_time : xarray.Dataset
        The ``shadow_time`` dataset; its ``lit_image (sweep, row, col, channel)``
        is used when `reference` is None.
    reference : (rows, cols, channel) array_like, optional
        Unshadowed reference frame (linear).
    sweeps : sequence of str
        Scene sweeps whose lit images are averaged (NaN-aware).

    Returns
    -------
    (rows, cols, channel) float32 ndarray
        NaN at the pixels the shadow-time dataset marks ``saturated`` in any of `sweeps`
        (a clipped colour is a lower bound: those dual pixels are left uncovered).
    """
    present = [s for s in sweeps if s in shadow_time["sweep"].values]
    clipped = (shadow_time["saturated"].sel(sweep=present).any("sweep").transpose("row", "col").values
               if "saturated" in shadow_time and present else False)
    if reference is not None:
        ref = np.asarray(reference, dtype=np.float32)
        check_array(ref, "reference", ndim=3)
        return np.where(np.asarray(clipped)[..., None], np.float32(np.nan), ref)
    if "lit_image" not in shadow_time:
        raise ValueError("shadow_time: no 'lit_image' variable and no reference frame given")
    if not present:
        raise ValueError(f"shadow_time: none of the sweeps {list(sweeps)} is present")
    lit = shadow_time["lit_image"].sel(sweep=present).transpose("sweep", "row", "col", "channel")
    with np.errstate(invalid="ignore"):
        stack = np.asarray(lit.values, dtype=np.float32)
        counts = np.sum(np.isfinite(stack), axis=0)
        mean = np.where(counts > 0, np.nansum(stack, axis=0) / np.maximum(counts, 1), np.nan)
    return np.where(np.asarray(clipped)[..., None], np.nan, mean).astype(np.float32)


def dual_view_dataset(image, coverage, *, method, params=None, channels=("R", "G", "B")):
    """Assemble the ``dual_view`` Dataset of docs/contracts.md.

    Parameters
    ----------
    image : (height, width, channel) ndarray
    coverage : (height, width) bool ndarray
    method : str, keyword-only
        Resampling method (stored as attr ``resampling``).
    params : mapping, optional
        Method options (stored as JSON attr ``resampling_params``).
    channels : sequence of str

    Returns
    -------
    xarray.Dataset
        ``dual_view (v, u, channel)`` float32 and ``coverage (v, u)`` bool.
    """
    height, width, n_ch = image.shape
    channels = list(channels)[:n_ch] if len(channels) >= n_ch else [str(c) for c in range(n_ch)]
    ds = xr.Dataset(
        {
            "dual_view": (("v", "u", "channel"), np.asarray(image, dtype=np.float32), {
                "units": "1", "long_name": "dual (shadow-camera) view, linear camera units"}),
            "coverage": (("v", "u"), np.asarray(coverage, dtype=bool), {
                "long_name": "dual pixel received camera samples"}),
        },
        coords={
            "v": ("v", np.arange(height), {"units": "dual_pixel", "long_name": "dual row"}),
            "u": ("u", np.arange(width), {"units": "dual_pixel", "long_name": "dual column"}),
            "channel": channels,
        },
    )
    ds.attrs.update(resampling=method, resampling_params=json.dumps(dict(params or {})))
    return ds


def dual_view_from_coords(coords, shadow_time, *, reference=None, method="mesh", min_coverage=MIN_COVERAGE,
                          density=None, **params):
    """Resample the camera colours into the dual grid of `coords`.

    Parameters
    ----------
    coords : xarray.Dataset
        Dual coordinates (``u``, ``v``, ``valid`` over ``(row, col)``; attrs ``dual_height``,
        ``dual_width``, ``model``).
    shadow_time : xarray.Dataset
        Its ``lit_image`` gives the colours when `reference` is None.
    reference : xarray.Dataset, optional
        Reference frame store (``image``, averaged over ``time`` if it has one).
    method : str
        Key of :data:`DUAL_VIEW_METHODS`.
    min_coverage : float
        Smallest fraction of the dual pixels that must receive a colour.
    density : bool, optional
        Carry the camera-pixel density (``dual_view_mesh(density=True)``): the dual image
        is then the reciprocal image (pixel-transport reciprocity). Default: when `method`
        is ``mesh``; False gives the camera colours averaged (the scene's radiance under
        the primal light, placed on the dual grid).
    **params
        Method options.

    Returns
    -------
    xarray.Dataset
        :func:`dual_view_dataset` with attrs ``colour_source``, ``dual_coords_model``,
        ``resampling_seconds`` (and ``intrinsics_affine``, ``intrinsics`` of `coords` from
        ``cameras.intrinsics.coords_to_intrinsics``; ``camera_pixel_density`` when the
        density is carried).

    Raises
    ------
    ValueError
        If the dual view covers less than `min_coverage` of its grid (with the counts), or
        `density` is asked of a method other than ``mesh``.
    """
    check_in_interval(min_coverage, "min_coverage", 0.0, 1.0, closed="both")
    optics = str(coords.attrs.get("optics", "none"))
    if density is None:
        density = method == "mesh"
    elif density and method != "mesh":
        raise ValueError(f"density: the camera-pixel density is carried by the mesh warp only, not by "
                         f"method {method!r}; set dual_view.method: mesh or drop dual_view.params.density")
    if density:
        params = {**params, "density": True}
    if reference is not None:
        reference = reference_image(reference)
    colours = camera_colours(shadow_time, reference=reference)
    shape = (int(coords.attrs["dual_height"]), int(coords.attrs["dual_width"]))
    u = coords["u"].transpose("row", "col").values
    v = coords["v"].transpose("row", "col").values
    if u.shape != colours.shape[:2]:
        raise ValueError(f"coords: grid {u.shape} differs from the camera colours {colours.shape[:2]}")
    start = time.perf_counter()
    try:
        image, coverage = resample_dual_view(colours, u, v, shape=shape, valid=coords["valid"].values,
                                             method=method, **params)
    except TypeError as exc:
        raise ValueError(f"params: {exc}") from None
    seconds = time.perf_counter() - start
    log.info("%s resampling: %d camera pixels in %.3f s (%.2f M px/s), coverage %.1f%% of %dx%d",
             method, u.size, seconds, u.size / seconds / 1e6, 100 * coverage.mean(), *shape)
    valid = int(np.count_nonzero(coords["valid"].values))
    check_coverage(np.count_nonzero(coverage), coverage.size, what=f"dual pixels of the {shape[0]}x{shape[1]} dual view "
                   "covered", reasons={"uncovered": coverage.size - np.count_nonzero(coverage)},
                   hint=f"{valid:,} of {u.size:,} camera pixels have dual coordinates", min_coverage=min_coverage)
    channels = ([str(c) for c in shadow_time["channel"].values] if "channel" in shadow_time.coords
                else ("R", "G", "B"))
    dataset = dual_view_dataset(image, coverage, method=method, params=params, channels=channels)
    dataset.attrs.update(colour_source="reference" if reference is not None else "mean lit_image of u, v",
                         dual_coords_model=coords.attrs.get("model", ""), resampling_seconds=seconds)
    if density:
        dataset.attrs["camera_pixel_density"] = (
            f"colour x camera pixels per dual pixel, branches summed (primal optics: {optics})")
    for key in ("intrinsics_affine", "intrinsics"):  # the grid of chosen virtual intrinsics
        if key in coords.attrs:
            dataset.attrs[key] = coords.attrs[key]
    return dataset
