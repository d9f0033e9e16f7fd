"""Optical elements on the camera's side only: mirrors and thick glass that bend primary rays.

Paper section V (Fig. 14, 15): a camera that sees the scene reflected in a curved mirror
(a catadioptric view) or through thick glass gets a distorted image, while the light reaches
the scene directly, so the dual view from a perspective light is free of that distortion.
The elements here act on the camera's rays only: they are invisible to the light, to the
scene's shadow rays and to the wire; the reciprocal render's light is the camera's, so it
leaves through them (``camera_light_through_optics``).

A primary ray is followed through the elements (nearest surface first) until it leaves all
of them; it then continues into the scene. A ray that meets no element sees the scene
directly (this holds for mirror set-ups too). A ray that is totally internally reflected,
or that still interacts after ``max_interactions`` surfaces, is marked as not valid (no
hit). A scene object met before the next element surface ends the optical path there (the
object hides the element).

Offers
------
SphereMirror, PlaneMirror : reflective surfaces (convex sphere; disc, reflective on both sides).
GlassSphere, GlassCylinder, GlassSlab : refractive solids of a given index of refraction.
OPTICAL_ELEMENTS : the element types.
reflect, refract : mirror reflection ``r = d - 2 (d.n) n`` and Snell's law (with total
    internal reflection) for batches of unit directions.
BentRays, trace_through_optics : follow camera rays through the elements.
intersect_through_optics : scene hits of camera rays after the elements (``raycast.RayHits``).
camera_pixels_of_points : the camera pixel whose bent ray meets each given scene point first
    (the inverse of the bent view; where it exists, the camera sees the point).
camera_light_through_optics : the primal camera as a light through its optics (Helmholtz
    reciprocity): direction, exit point and irradiance gain (ray-tube Jacobian) per branch.
mirror_setup, glass_setup, OPTICS_SETUPS, optics_setup : build a set-up (elements and the
    camera that looks through them) from a capture description ``{"kind": ..., ...}``.
"""

import math
from dataclasses import dataclass

import numpy as np

from shadowcam.synthetic.lab.raycast import (
    T_MIN,
    RayHits,
    intersect_scene,
    intersect_sphere,
    occluded,
)
from shadowcam.synthetic.lab.scene import PinholeCamera, _unit, _vec, camera_rays, look_at_camera


def _positive(value, name):
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"{name}: must be a positive number, got {value!r}")
    return float(value)


def _index(value):
    if not (np.isfinite(value) and value >= 1):
        raise ValueError(f"index: must be a finite index of refraction >= 1, got {value!r}")
    return float(value)


def _set(obj, **values):
    for key, value in values.items():
        object.__setattr__(obj, key, value)


# --------------------------------------------------------------------------- elements


@dataclass(frozen=True, eq=False)
class SphereMirror:
    """Convex spherical mirror: its outer surface reflects."""

    center: np.ndarray
    radius: float

    def __post_init__(self):
        _set(self, center=_vec(self.center, "center"), radius=_positive(self.radius, "radius"))


@dataclass(frozen=True, eq=False)
class PlaneMirror:
    """Flat disc mirror of `radius` about `center`, perpendicular to `normal`; both sides
    reflect. ``radius=inf`` is the whole plane."""

    center: np.ndarray
    normal: np.ndarray
    radius: float = math.inf

    def __post_init__(self):
        radius = float(self.radius)
        if not radius > 0:
            raise ValueError(f"radius: must be positive (or inf), got {self.radius!r}")
        _set(self, center=_vec(self.center, "center"), normal=_unit(self.normal, "normal"),
             radius=radius)


@dataclass(frozen=True, eq=False)
class GlassSphere:
    """Solid glass sphere of index of refraction `index` (surroundings: index 1)."""

    center: np.ndarray
    radius: float
    index: float = 1.5

    def __post_init__(self):
        _set(self, center=_vec(self.center, "center"), radius=_positive(self.radius, "radius"),
             index=_index(self.index))


@dataclass(frozen=True, eq=False)
class GlassCylinder:
    """Solid glass cylinder of infinite length about the line through `center` along `axis`."""

    center: np.ndarray
    axis: np.ndarray
    radius: float
    index: float = 1.5

    def __post_init__(self):
        _set(self, center=_vec(self.center, "center"), axis=_unit(self.axis, "axis"),
             radius=_positive(self.radius, "radius"), index=_index(self.index))


@dataclass(frozen=True, eq=False)
class GlassSlab:
    """Glass plate with two parallel faces ``(X - center).normal = +-thickness / 2``,
    unbounded across its faces."""

    center: np.ndarray
    normal: np.ndarray
    thickness: float
    index: float = 1.5

    def __post_init__(self):
        _set(self, center=_vec(self.center, "center"), normal=_unit(self.normal, "normal"),
             thickness=_positive(self.thickness, "thickness"), index=_index(self.index))


OPTICAL_ELEMENTS = (SphereMirror, PlaneMirror, GlassSphere, GlassCylinder, GlassSlab)


def _nearest_surface(element, origins, directions):
    """(t, outward unit normal) of the nearest surface hit beyond ``T_MIN`` (t = inf: miss)."""
    n = len(origins)
    if isinstance(element, (SphereMirror, GlassSphere)):
        t = intersect_sphere(origins, directions, element.center, element.radius)
        with np.errstate(invalid="ignore"):
            normal = (origins + np.where(np.isfinite(t), t, 0.0)[:, None] * directions
                      - element.center) / element.radius
        return t, normal
    if isinstance(element, PlaneMirror):
        nrm = element.normal
        with np.errstate(divide="ignore", invalid="ignore"):
            t = ((element.center - origins) @ nrm) / (directions @ nrm)
            ok = np.isfinite(t) & (t > T_MIN)
            rel = origins + np.where(ok, t, 0.0)[:, None] * directions - element.center
            ok &= np.linalg.norm(rel, axis=1) <= element.radius
        return np.where(ok, t, np.inf), np.broadcast_to(nrm, (n, 3))
    if isinstance(element, GlassCylinder):
        a = element.axis
        oc = origins - element.center
        oc_p = oc - np.outer(oc @ a, a)
        d_p = directions - np.outer(directions @ a, a)
        qa = np.einsum("ij,ij->i", d_p, d_p)
        qb = np.einsum("ij,ij->i", oc_p, d_p)
        qc = np.einsum("ij,ij->i", oc_p, oc_p) - element.radius**2
        with np.errstate(divide="ignore", invalid="ignore"):
            disc = qb * qb - qa * qc
            root = np.sqrt(np.maximum(disc, 0.0))
            t1, t2 = (-qb - root) / qa, (-qb + root) / qa
            t = np.where(t1 > T_MIN, t1, np.where(t2 > T_MIN, t2, np.inf))
            t = np.where((disc >= 0) & (qa > 0), t, np.inf)
            normal = (oc_p + np.where(np.isfinite(t), t, 0.0)[:, None] * d_p) / element.radius
        return t, normal
    if isinstance(element, GlassSlab):
        nrm = element.normal
        h = element.thickness / 2
        with np.errstate(divide="ignore", invalid="ignore"):
            dn = directions @ nrm
            s = (origins - element.center) @ nrm
            t_plus, t_minus = (h - s) / dn, (-h - s) / dn
            t_plus = np.where(np.isfinite(t_plus) & (t_plus > T_MIN), t_plus, np.inf)
            t_minus = np.where(np.isfinite(t_minus) & (t_minus > T_MIN), t_minus, np.inf)
        plus = t_plus <= t_minus
        normal = np.where(plus[:, None], nrm, -nrm)
        return np.where(plus, t_plus, t_minus), normal
    raise ValueError(f"optics: unsupported optical element {type(element).__name__}")


# --------------------------------------------------------------------------- surface laws


def reflect(directions, normals):
    """Mirror reflection ``r = d - 2 (d.n) n`` of (N, 3) unit directions at (N, 3) unit normals."""
    dn = np.einsum("ij,ij->i", directions, normals)
    return directions - 2.0 * dn[:, None] * normals


def refract(directions, normals, index):
    """Snell's law at a surface between index 1 (outside) and `index` (inside).

    Parameters
    ----------
    directions : (N, 3) ndarray
        Unit incident directions.
    normals : (N, 3) ndarray
        Unit outward normals (pointing into the index-1 side); a ray with ``d.n < 0`` enters.
    index : float
        Index of refraction of the inside.

    Returns
    -------
    refracted : (N, 3) ndarray
        Unit transmitted directions (NaN where totally internally reflected).
    transmitted : (N,) bool ndarray
        False where the ray is totally internally reflected.
    """
    cos_out = np.einsum("ij,ij->i", directions, normals)
    entering = cos_out < 0
    eta = np.where(entering, 1.0 / index, index)
    facing = np.where(entering[:, None], normals, -normals)  # normal against the ray
    cos_i = np.abs(cos_out)
    k = 1.0 - eta * eta * (1.0 - cos_i * cos_i)
    transmitted = k >= 0
    with np.errstate(invalid="ignore"):
        out = eta[:, None] * directions + (eta * cos_i - np.sqrt(k))[:, None] * facing
    out[~transmitted] = np.nan
    return out, transmitted


# --------------------------------------------------------------------------- tracing


@dataclass(frozen=True)
class BentRays:
    """Camera rays after the optical elements.

    Attributes
    ----------
    origins, directions : (N, 3) float64
        Where each ray leaves the last element it met, and its unit direction into the
        scene (the camera ray itself where it met none; NaN where not valid).
    valid : (N,) bool
        False where the ray was totally internally reflected or did not leave the elements.
    path_length : (N,) float64
        Geometric length of the path from the camera ray origin to `origins`.
    interactions : (N,) int64
        Number of element surfaces met.
    """

    origins: np.ndarray
    directions: np.ndarray
    valid: np.ndarray
    path_length: np.ndarray
    interactions: np.ndarray


def trace_through_optics(optics, origins, directions, *, objects=(), max_interactions=16):
    """Follow camera rays through mirrors and glass until they leave every element.

    Parameters
    ----------
    optics : sequence of optical elements (``OPTICAL_ELEMENTS``)
    origins, directions : (N, 3) ndarray
        Camera ray origins and unit directions.
    objects : sequence of scene objects
        A scene object met before the next element surface ends the ray's optical path.
    max_interactions : int
        Rays still meeting elements after this many surfaces are marked not valid.

    Returns
    -------
    BentRays
    """
    origins = np.array(origins, dtype=np.float64)
    directions = np.array(directions, dtype=np.float64)
    if origins.ndim != 2 or origins.shape[1] != 3:
        raise ValueError(f"origins: expected (N, 3), got {origins.shape}")
    if directions.shape != origins.shape:
        raise ValueError(f"directions: expected {origins.shape}, got {directions.shape}")
    if int(max_interactions) < 1:
        raise ValueError(f"max_interactions: must be >= 1, got {max_interactions}")
    for element in optics:
        if not isinstance(element, OPTICAL_ELEMENTS):
            raise ValueError(f"optics: unsupported optical element {type(element).__name__}")
    n = len(origins)
    valid = np.ones(n, dtype=bool)
    path_length = np.zeros(n)
    interactions = np.zeros(n, dtype=np.int64)
    active = np.arange(n)
    for _ in range(int(max_interactions)):
        if not len(active) or not optics:
            break
        o, d = origins[active], directions[active]
        best = np.full(len(active), np.inf)
        which = np.full(len(active), -1)
        normal = np.full((len(active), 3), np.nan)
        for k, element in enumerate(optics):
            t, nrm = _nearest_surface(element, o, d)
            closer = t < best
            best[closer], which[closer], normal[closer] = t[closer], k, nrm[closer]
        met = which >= 0
        if objects:
            idx = np.flatnonzero(met)
            met[idx[occluded(objects, o[idx], d[idx], best[idx])]] = False
        active, best, which, normal = active[met], best[met], which[met], normal[met]
        if not len(active):
            break
        points = origins[active] + best[:, None] * directions[active]
        new_dirs = np.empty((len(active), 3))
        ok = np.ones(len(active), dtype=bool)
        for k, element in enumerate(optics):
            sel = which == k
            if not sel.any():
                continue
            if isinstance(element, (SphereMirror, PlaneMirror)):
                new_dirs[sel] = reflect(directions[active[sel]], normal[sel])
            else:
                new_dirs[sel], ok[sel] = refract(directions[active[sel]], normal[sel],
                                                 element.index)
        origins[active] = points
        directions[active] = new_dirs
        path_length[active] += best
        interactions[active] += 1
        valid[active[~ok]] = False
        active = active[ok]
    else:
        valid[active] = False  # still inside the elements
    origins[~valid] = np.nan
    directions[~valid] = np.nan
    return BentRays(origins=origins, directions=directions, valid=valid,
                    path_length=path_length, interactions=interactions)


def intersect_through_optics(objects, optics, origins, directions, *, max_interactions=16):
    """Scene hits of camera rays bent by the optical elements.

    Parameters
    ----------
    objects : sequence of scene objects
    optics : sequence of optical elements
    origins, directions : (N, 3) ndarray
        Camera ray origins and unit directions.
    max_interactions : int

    Returns
    -------
    hits : raycast.RayHits
        Hits of the bent rays (``distance`` counted from where the ray leaves the optics;
        not-valid rays are misses).
    bent : BentRays
    """
    bent = trace_through_optics(optics, origins, directions, objects=objects,
                                max_interactions=max_interactions)
    n = len(bent.valid)
    idx = np.flatnonzero(bent.valid)
    part = intersect_scene(objects, bent.origins[idx], bent.directions[idx])
    distance = np.full(n, np.inf)
    point = np.full((n, 3), np.nan)
    normal = np.full((n, 3), np.nan)
    object_id = np.full(n, -1, dtype=np.int64)
    albedo = np.zeros((n, 3))
    distance[idx], point[idx], normal[idx] = part.distance, part.point, part.normal
    object_id[idx], albedo[idx] = part.object_id, part.albedo
    hits = RayHits(distance=distance, point=point, normal=normal, object_id=object_id,
                   albedo=albedo)
    return hits, bent


def _bent_offset(optics, camera, target, x, y):
    """Bent rays through pixel-edge (x, y): (N, 3) offset of `target` from the ray's last
    segment (perpendicular to it), the distance along it, and its origin and direction."""
    origins, dirs = camera_rays(camera, x, y)
    bent = trace_through_optics(optics, origins, dirs)
    rel = target - bent.origins
    along = np.einsum("nk,nk->n", rel, bent.directions)
    return rel - along[:, None] * bent.directions, along, bent


def _solve_pixel(optics, camera, target, x, y, *, iterations, step):
    """Gauss-Newton on pixel-edge (x, y) so that the bent ray passes through `target`
    (N, 3), at most one pixel per step; returns x, y, the ray's miss distance in pixels
    (inf where the ray is not valid), the distance along it, and the bent rays."""
    for k in range(iterations + 1):
        off, along, bent = _bent_offset(optics, camera, target, x, y)
        jx = (_bent_offset(optics, camera, target, x + step, y)[0] - off) / step
        jy = (_bent_offset(optics, camera, target, x, y + step)[0] - off) / step
        jac = np.stack([jx, jy], axis=-1)  # (N, 3, 2)
        jtj = np.einsum("nki,nkj->nij", jac, jac)
        with np.errstate(invalid="ignore"):
            det = np.linalg.det(np.nan_to_num(jtj, nan=0.0))
        good = np.isfinite(det) & (det > 0) & bent.valid & (along > 0)
        footprint = np.sqrt(np.sqrt(np.where(good, det, np.nan)))  # scene units per pixel
        miss_px = np.where(good, np.linalg.norm(off, axis=1) / footprint, np.inf)
        if k == iterations or not np.any(good & (miss_px > 1e-6)):
            break  # (x, y) are where miss_px was measured
        delta = np.zeros((len(target), 2))
        jtr = np.einsum("nki,nk->ni", jac[good], -off[good])
        delta[good] = np.linalg.solve(jtj[good], jtr[..., None])[..., 0]
        delta /= np.maximum(np.linalg.norm(delta, axis=1, keepdims=True), 1.0)
        x, y = x + delta[:, 0], y + delta[:, 1]
    return x, y, miss_px, footprint, bent


def _seen_from(objects, optics, camera, target, x, y, *, tolerance, iterations, step):
    """Solve the bent ray through `target` (N, 3) from pixel-edge starts (x, y): returns
    x, y, seen (the ray passes within `tolerance` pixel, inside the image, and its first
    scene hit is the target), the ray footprint (scene units per pixel) and the bent rays."""
    x, y, miss_px, footprint, bent = _solve_pixel(optics, camera, target, x, y,
                                                  iterations=int(iterations), step=step)
    hit = ((miss_px < tolerance) & (x >= 0) & (x <= camera.width) & (y >= 0)
           & (y <= camera.height))
    idx = np.flatnonzero(hit)
    first = intersect_scene(objects, bent.origins[idx], bent.directions[idx])
    gap = np.linalg.norm(np.nan_to_num(first.point - target[idx], nan=np.inf), axis=1)
    hit[idx[~(gap < tolerance * footprint[idx])]] = False
    return x, y, hit, footprint, bent


def _checked_point_query(points, *, tolerance, iterations, step, starts):
    """`points` as (N, 3) float64, after checking the options of a camera-pixel search."""
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"points: expected (N, 3), got {points.shape}")
    if not (np.isfinite(tolerance) and tolerance > 0):
        raise ValueError(f"tolerance: must be a positive number of pixels, got {tolerance!r}")
    if int(iterations) < 1:
        raise ValueError(f"iterations: must be >= 1, got {iterations!r}")
    if not (np.isfinite(step) and step > 0):
        raise ValueError(f"step: must be a positive number of pixels, got {step!r}")
    if int(starts) < 1:
        raise ValueError(f"starts: must be >= 1, got {starts!r}")
    return points


def _pixel_centre_hits(objects, optics, camera):
    """Every pixel centre's ray through the optics: centres ``gx, gy`` (H*W,) and the
    scene hits and bent rays of ``intersect_through_optics``."""
    rows, cols = np.mgrid[0:camera.height, 0:camera.width]
    gx, gy = cols.ravel() + 0.5, rows.ravel() + 0.5
    origins, dirs = camera_rays(camera, gx, gy)
    grid, bent = intersect_through_optics(objects, optics, origins, dirs)
    return gx, gy, grid, bent


def camera_pixels_of_points(objects, optics, camera, points, *, tolerance=0.01,
                            iterations=12, step=0.05, starts=4):
    """Camera pixel whose ray, bent by the optics, meets each scene point first.

    The inverse of the bent view. Per point P, Gauss-Newton on the pixel-edge coordinates
    x makes the bent ray through x pass through P: it minimises P's offset from the ray's
    last segment (smooth in x away from the optics' rims), with its Jacobian from finite
    differences of `step` pixel and steps of at most one pixel. It starts at the pixel
    centre whose scene hit lies nearest to P, then (if that fails) at the next nearest, up
    to `starts` of them. P is seen when that ray passes within `tolerance` camera pixel of
    it (offset / ray footprint ``(det J^T J)^(1/4)``), x lies inside the image, and the
    ray's first scene hit is P (to the same tolerance): a point hidden behind another
    object stays unseen. Where several rays see a point (e.g. past and through a glass
    sphere) the first one found is returned.

    Parameters
    ----------
    objects : sequence of scene objects
    optics : sequence of optical elements
    camera : PinholeCamera or OrthographicCamera
        The primal camera whose rays the optics bend.
    points : (N, 3) ndarray
        Scene points (NaN rows are never seen).
    tolerance : float
        Largest miss in camera pixels for a point to count as seen.
    iterations : int
        Gauss-Newton steps.
    step : float
        Finite-difference step in pixels.
    starts : int
        Pixel centres tried as starts per point.

    Returns
    -------
    xy : (N, 2) float64
        Camera (col, row) pixel-centre index of each point (NaN where not seen).
    seen : (N,) bool
    """
    points = _checked_point_query(points, tolerance=tolerance, iterations=iterations, step=step, starts=starts)
    from scipy.spatial import cKDTree

    n = len(points)
    xy = np.full((n, 2), np.nan)
    seen = np.zeros(n, dtype=bool)
    gx, gy, grid, _ = _pixel_centre_hits(objects, optics, camera)
    todo = np.flatnonzero(np.all(np.isfinite(points), axis=1))
    if not grid.hit.any() or not len(todo):
        return xy, seen
    sx, sy = gx[grid.hit], gy[grid.hit]
    k_starts = min(int(starts), len(sx))
    _, nearest = cKDTree(grid.point[grid.hit]).query(points[todo], k=k_starts)
    nearest = nearest.reshape(len(todo), k_starts)
    for k in range(k_starts):  # the next nearest start for the points not seen yet
        x, y, hit, _, _ = _seen_from(objects, optics, camera, points[todo],
                                     sx[nearest[:, k]], sy[nearest[:, k]],
                                     tolerance=tolerance, iterations=iterations, step=step)
        seen[todo[hit]] = True
        xy[todo[hit]] = np.stack([x[hit] - 0.5, y[hit] - 0.5], axis=1)
        todo, nearest = todo[~hit], nearest[~hit]
        if not len(todo):
            break
    return xy, seen


def _emitted_per_pixel(camera, x, y):
    """(N,) measure the camera-as-light emits into per square pixel at pixel-edge (x, y):
    solid angle ``|det K^-1| / |K^-1 (x, y, 1)|^3`` (sr) for a pinhole, the pixel area
    ``pixel_size^2`` for an orthographic camera."""
    if not isinstance(camera, PinholeCamera):
        return np.full(len(x), float(camera.pixel_size) ** 2)
    k_inv = np.linalg.inv(camera.K)
    rays = np.stack([x, y, np.ones_like(x)], axis=1) @ k_inv.T
    return abs(np.linalg.det(k_inv)) / np.linalg.norm(rays, axis=1) ** 3


def _tube_area(optics, camera, target, x, y, step):
    """(N,) cross-section of the bent ray tube at `target` per square pixel at pixel-edge
    (x, y): ``|dO/dx x dO/dy|`` of the target's offset O from the ray. Central differences
    within the ray's branch; where one side's ray meets a different number of element
    surfaces (the step crosses a mirror's or a glass's rim) the one-sided difference on the
    ray's own branch, so the density of the branch is not taken across its jump."""
    centre, _, bent = _bent_offset(optics, camera, target, x, y)

    def d_offset(dx, dy):
        plus, _, bent_p = _bent_offset(optics, camera, target, x + dx, y + dy)
        minus, _, bent_m = _bent_offset(optics, camera, target, x - dx, y - dy)
        same_p = (bent_p.valid & (bent_p.interactions == bent.interactions))[:, None]
        same_m = (bent_m.valid & (bent_m.interactions == bent.interactions))[:, None]
        return np.where(same_p & same_m, (plus - minus) / (2 * step),
                        np.where(same_p, (plus - centre) / step, (centre - minus) / step))

    return np.linalg.norm(np.cross(d_offset(step, 0.0), d_offset(0.0, step)), axis=1)


def camera_light_through_optics(objects, optics, camera, points, *, tolerance=0.01,
                                iterations=12, step=0.05, starts=2):
    """The primal camera as a light seen from scene points, through its optics.

    By Helmholtz reciprocity the camera's reciprocal light leaves its centre (a pinhole)
    or its image plane along the viewing direction (orthographic) through its image
    pixels and follows the camera rays bent by the optics (lossless: perfect mirrors, no
    Fresnel loss). A point P receives it along every bent ray whose first scene hit is P;
    rays that meet different numbers of element surfaces are different branches (e.g.
    past and through a glass sphere, or beside and in a mirror), each solved like
    ``camera_pixels_of_points`` from the nearest pixel centres of its own branch. The
    ray tube carries the emitted measure of a pixel (``_emitted_per_pixel``) onto the
    tube's cross-section at P (``_tube_area``, per square pixel, central differences of
    `step` pixel within the ray's branch, one-sided at an element's rim), so the irradiance on a surface normal to the ray is ``strength * gain``
    with ``gain = emitted per pixel / cross-section`` (the Jacobian of the optics' area change;
    without optics ``1 / d^2`` for a pinhole and 1 for an orthographic camera).

    Parameters
    ----------
    objects : sequence of scene objects
    optics : sequence of optical elements
    camera : PinholeCamera or OrthographicCamera
    points : (N, 3) ndarray
        Scene points (NaN rows receive nothing).
    tolerance, iterations, step : as in ``camera_pixels_of_points``
    starts : int
        Pixel centres tried as starts per point and branch.

    Returns
    -------
    to_light : (N, B, 3) float64
        Unit direction from P back along each branch's ray (NaN where it does not reach P).
    gain : (N, B) float64
        Irradiance normal to the ray per unit strength (0 where the branch does not reach P).
    origin : (N, B, 3) float64
        Where the branch's ray leaves the optics (the camera centre for a direct ray).
    """
    points = _checked_point_query(points, tolerance=tolerance, iterations=iterations, step=step, starts=starts)
    from scipy.spatial import cKDTree

    n = len(points)
    gx, gy, grid, bent_grid = _pixel_centre_hits(objects, optics, camera)
    branches = np.unique(bent_grid.interactions[grid.hit])
    to_light = np.full((n, len(branches), 3), np.nan)
    gain = np.zeros((n, len(branches)))
    origin = np.full((n, len(branches), 3), np.nan)
    finite = np.flatnonzero(np.all(np.isfinite(points), axis=1))
    for b, count in enumerate(branches):
        member = grid.hit & (bent_grid.interactions == count)
        sx, sy = gx[member], gy[member]
        k_starts = min(int(starts), len(sx))
        _, nearest = cKDTree(grid.point[member]).query(points[finite], k=k_starts)
        nearest = nearest.reshape(len(finite), k_starts)
        todo = finite
        for k in range(k_starts):
            x, y, hit, _, bent = _seen_from(
                objects, optics, camera, points[todo], sx[nearest[:, k]], sy[nearest[:, k]],
                tolerance=tolerance, iterations=iterations, step=step)
            hit &= bent.interactions == count
            idx = todo[hit]
            to_light[idx, b] = -bent.directions[hit]
            origin[idx, b] = bent.origins[hit]
            area = _tube_area(optics, camera, points[idx], x[hit], y[hit], step)
            gain[idx, b] = _emitted_per_pixel(camera, x[hit], y[hit]) / area
            todo, nearest = todo[~hit], nearest[~hit]
            if not len(todo):
                break
    return to_light, gain, origin


# --------------------------------------------------------------------------- set-ups


def mirror_setup(camera, *, offset=0.2, distance=0.08, radius=0.035, fov_x_deg=30.0,
                 deflection_deg=90.0):
    """A catadioptric set-up: a camera looks at the scene in a convex spherical mirror.

    The mirror's centre M lies `offset` along the optical axis (forward direction f) of
    `camera` from its centre (negative: behind it). The new camera sits at
    ``M + distance g``, with g the direction f turned by `deflection_deg` about the camera's
    up axis, and aims at the mirror point whose normal bisects f and g, so that it sees the
    scene reflected about (roughly) the former viewing direction; ``deflection_deg = 0``
    with ``offset = -distance`` puts it at the former camera centre, looking straight back
    at the mirror. It keeps the image size and up direction of `camera`. Its pixels whose
    rays miss the mirror see the scene directly (``edges.EdgePoints.through_optics`` tells
    the two apart for edge points).

    Parameters
    ----------
    camera : PinholeCamera
        The direct-view camera of the scene.
    offset : float
        Signed position of the mirror centre along the former optical axis (scene units).
    distance : float
        New camera centre to mirror centre; must exceed `radius`.
    radius : float
        Mirror radius.
    fov_x_deg : float
        Horizontal field of view of the camera that looks at the mirror.
    deflection_deg : float
        Angle at the mirror between the directions to the camera and to the scene, in
        [0, 150] (larger = more oblique reflection, stronger distortion).

    Returns
    -------
    camera : PinholeCamera
    optics : tuple of SphereMirror
    """
    if not isinstance(camera, PinholeCamera):
        raise ValueError("camera: a mirror set-up needs a PinholeCamera")
    distance, radius = _positive(distance, "distance"), _positive(radius, "radius")
    if distance <= radius:
        raise ValueError(f"distance: must exceed radius ({radius}), got {distance}")
    if not 0 <= deflection_deg <= 150:
        raise ValueError(f"deflection_deg: must be in [0, 150], got {deflection_deg!r}")
    forward, up = camera.R[2], -camera.R[1]
    centre = camera.center + float(offset) * forward
    a = math.radians(deflection_deg)
    side = np.cross(up, forward)  # the camera's left: turning f toward it about up
    toward_camera = math.cos(a) * forward + math.sin(a) * side
    bisector = forward + toward_camera
    bisector /= np.linalg.norm(bisector)
    new = look_at_camera(centre + distance * toward_camera, centre + radius * bisector,
                         fov_x_deg=fov_x_deg, width=camera.width, height=camera.height, up=up)
    return new, (SphereMirror(centre, radius),)


GLASS_SHAPES = ("slab", "sphere", "cylinder")


def glass_setup(camera, *, shape="sphere", index=1.5, distance=0.12, size=0.05,
                tilt_deg=30.0):
    """Thick glass on the camera's optical axis, between the camera and the scene.

    Parameters
    ----------
    camera : PinholeCamera
    shape : {"slab", "sphere", "cylinder"}
        A plate (faces tilted by `tilt_deg` about the camera's vertical axis), a sphere, or
        a cylinder whose axis is the camera's vertical image direction.
    index : float
        Index of refraction (>= 1).
    distance : float
        Camera centre to the element's centre along the optical axis.
    size : float
        Plate thickness, or sphere / cylinder radius; must be below `distance`.
    tilt_deg : float
        Angle between the plate normal and the optical axis.

    Returns
    -------
    camera : PinholeCamera
        `camera` itself.
    optics : tuple of one glass element
    """
    if not isinstance(camera, PinholeCamera):
        raise ValueError("camera: a glass set-up needs a PinholeCamera")
    if shape not in GLASS_SHAPES:
        raise ValueError(f"shape: must be one of {GLASS_SHAPES}, got {shape!r}")
    distance, size = _positive(distance, "distance"), _positive(size, "size")
    if size >= distance:
        raise ValueError(f"size: must be below distance ({distance}), got {size}")
    forward, down = camera.R[2], camera.R[1]
    centre = camera.center + distance * forward
    if shape == "sphere":
        return camera, (GlassSphere(centre, size, index),)
    if shape == "cylinder":
        return camera, (GlassCylinder(centre, down, size, index),)
    a = math.radians(tilt_deg)
    normal = math.cos(a) * forward + math.sin(a) * camera.R[0]
    return camera, (GlassSlab(centre, normal, size, index),)


#: optics kind -> set-up builder(camera, **options) -> (camera, optics)
OPTICS_SETUPS = {"mirror": mirror_setup, "glass": glass_setup}


def optics_setup(description, camera):
    """Build the optics of a capture description.

    Parameters
    ----------
    description : dict
        ``{"kind": "mirror" | "glass", **options}``; the options are the keyword arguments
        of ``mirror_setup`` / ``glass_setup``, e.g. ``{"kind": "glass", "index": 1.5}``.
    camera : PinholeCamera
        The direct-view camera of the scene.

    Returns
    -------
    camera : PinholeCamera
    optics : tuple of optical elements
    """
    if not isinstance(description, dict) or "kind" not in description:
        raise ValueError(f"optics: expected a dict with a 'kind' key, got {description!r}")
    options = dict(description)
    kind = options.pop("kind")
    if kind not in OPTICS_SETUPS:
        raise ValueError(f"optics: unknown kind {kind!r}; choose one of {sorted(OPTICS_SETUPS)}")
    try:
        return OPTICS_SETUPS[kind](camera, **options)
    except TypeError as err:
        raise ValueError(f"optics: bad options for kind {kind!r}: {err}") from None
