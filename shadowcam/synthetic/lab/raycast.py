"""Vectorised numpy ray casting against a scene's objects; analytic wire occlusion.

All functions are pure and work on batches of rays: ``origins``, ``directions`` are
(N, 3) float64 arrays (directions unit length). A miss has distance ``inf`` and object id -1.

Offers
------
as_rays : ray origins and directions as checked float64 (N, 3) arrays.
RayHits : result of ``intersect_scene`` (distance, point, normal, object_id, albedo).
intersect_sphere, intersect_box, intersect_ground, intersect_back_plane :
    nearest hit distance (and normal, for boxes) with one object.
intersect_scene : nearest hit over all objects, with point, outward normal and albedo.
occluded : shadow-ray test for segments (or rays, for distant lights).
wire_occlusion_interval : frames during which a sweep's wire blocks point-to-light segments.
"""

from dataclasses import dataclass

import numpy as np

from shadowcam._shared.validation import check_array, check_same_shape
from shadowcam.synthetic.lab.scene import BackPlane, Box, GroundPlane, Sphere, texture_albedo

#: default minimum hit distance (scene units) to avoid self-intersection
T_MIN = 1e-9
#: shadow-ray origins are pushed this far (scene units) off the surface
SURFACE_OFFSET = 1e-7


def as_rays(origins, directions):
    """Return `origins` and `directions` as float64 ``(N, 3)`` arrays of one shape (checked)."""
    origins = check_array(np.asarray(origins, dtype=np.float64), "origins", shape=(None, 3))
    directions = np.asarray(directions, dtype=np.float64)
    check_same_shape({"origins": origins, "directions": directions})
    return origins, directions


def intersect_sphere(origins, directions, center, radius, *, t_min=T_MIN):
    """Nearest intersection distance with a sphere.

    Parameters
    ----------
    origins, directions : (N, 3) ndarray
    center : (3,) ndarray
    radius : float
    t_min : float
        Hits closer than this are ignored (the far root is used when inside).

    Returns
    -------
    (N,) ndarray
        Distance along the (unit) direction; ``inf`` where missed.
    """
    origins, directions = as_rays(origins, directions)
    oc = origins - center
    b = np.einsum("ij,ij->i", oc, directions)
    c = np.einsum("ij,ij->i", oc, oc) - radius * radius
    disc = b * b - c
    root = np.sqrt(np.maximum(disc, 0.0))
    t1, t2 = -b - root, -b + root
    t = np.where(t1 > t_min, t1, np.where(t2 > t_min, t2, np.inf))
    return np.where(disc >= 0, t, np.inf)


def intersect_box(origins, directions, center, half_extents, rotation, *, t_min=T_MIN):
    """Nearest intersection with an oriented box (slab method).

    Parameters
    ----------
    origins, directions : (N, 3) ndarray
    center, half_extents : (3,) ndarray
    rotation : (3, 3) ndarray
        Local -> world rotation.

    Returns
    -------
    t : (N,) ndarray
        Distance, ``inf`` where missed.
    normal : (N, 3) ndarray
        Outward world normal of the face hit (undefined where missed).
    """
    origins, directions = as_rays(origins, directions)
    o = (origins - center) @ rotation  # rotation^T (origins - center), row-wise
    d = directions @ rotation
    with np.errstate(divide="ignore", invalid="ignore"):
        t_a = (-half_extents - o) / d
        t_b = (half_extents - o) / d
    t_lo = np.fmin(t_a, t_b)
    t_hi = np.fmax(t_a, t_b)
    axis_near = np.argmax(t_lo, axis=1)
    axis_far = np.argmin(t_hi, axis=1)
    rows = np.arange(len(o))
    t_near = t_lo[rows, axis_near]
    t_far = t_hi[rows, axis_far]
    hit = (t_near <= t_far) & (t_far > t_min)
    use_far = t_near <= t_min
    t = np.where(hit, np.where(use_far, t_far, t_near), np.inf)
    axis = np.where(use_far, axis_far, axis_near)
    sign = np.sign(d[rows, axis]) * np.where(use_far, 1.0, -1.0)
    local_normal = np.zeros_like(o)
    local_normal[rows, axis] = sign
    return t, local_normal @ rotation.T


def intersect_ground(origins, directions, height, *, t_min=T_MIN):
    """Distance to the infinite plane ``y = height`` (``inf`` where missed)."""
    origins, directions = as_rays(origins, directions)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (height - origins[:, 1]) / directions[:, 1]
    return np.where(np.isfinite(t) & (t > t_min), t, np.inf)


def intersect_back_plane(origins, directions, plane, *, t_min=T_MIN):
    """Distance to a finite BackPlane rectangle (``inf`` where missed)."""
    origins, directions = as_rays(origins, directions)
    n = plane.normal
    with np.errstate(divide="ignore", invalid="ignore"):
        t = ((plane.center - origins) @ n) / (directions @ n)
    ok = np.isfinite(t) & (t > t_min)
    t = np.where(ok, t, np.inf)
    xy = plane.plane_coords(origins + np.where(ok, t, 0.0)[:, None] * directions)
    inside = (np.abs(xy[:, 0]) <= plane.width / 2) & (np.abs(xy[:, 1]) <= plane.height / 2)
    return np.where(inside, t, np.inf)


def _intersect_object(obj, origins, directions, t_min):
    """(t, normal or None) of one object."""
    if isinstance(obj, Sphere):
        return intersect_sphere(origins, directions, obj.center, obj.radius, t_min=t_min), None
    if isinstance(obj, Box):
        return intersect_box(origins, directions, obj.center, obj.half_extents, obj.rotation,
                             t_min=t_min)
    if isinstance(obj, GroundPlane):
        return intersect_ground(origins, directions, obj.height, t_min=t_min), None
    if isinstance(obj, BackPlane):
        return intersect_back_plane(origins, directions, obj, t_min=t_min), None
    raise ValueError(f"objects: unsupported object type {type(obj).__name__}")


def _texture_coords(obj, points):
    if isinstance(obj, Sphere):
        rel = (points - obj.center) / obj.radius
        azimuth = np.arctan2(rel[:, 0], rel[:, 2])
        polar = np.arccos(np.clip(rel[:, 1], -1.0, 1.0))
        return np.stack([azimuth, polar], axis=-1) * obj.radius
    if isinstance(obj, Box):
        local = (points - obj.center) @ obj.rotation
        return np.stack([local[:, 0] + local[:, 2], local[:, 1]], axis=-1)
    if isinstance(obj, GroundPlane):
        return points[:, [0, 2]]
    return obj.plane_coords(points)


def _normals(obj, points, box_normal):
    if isinstance(obj, Sphere):
        return (points - obj.center) / obj.radius
    if isinstance(obj, Box):
        return box_normal
    if isinstance(obj, GroundPlane):
        return np.broadcast_to(np.array([0.0, 1.0, 0.0]), points.shape)
    return np.broadcast_to(obj.normal, points.shape)


@dataclass(frozen=True)
class RayHits:
    """Nearest hits of a batch of N rays.

    Attributes
    ----------
    distance : (N,) float64, ``inf`` = miss
    point : (N, 3) float64, NaN where missed
    normal : (N, 3) float64 outward geometric normal (unit), NaN where missed
    object_id : (N,) int64 index into the object tuple, -1 = miss
    albedo : (N, 3) float64 linear diffuse albedo, 0 where missed
    """

    distance: np.ndarray
    point: np.ndarray
    normal: np.ndarray
    object_id: np.ndarray
    albedo: np.ndarray

    @property
    def hit(self):
        """(N,) bool: the ray hit something."""
        return self.object_id >= 0


def intersect_scene(objects, origins, directions, *, t_min=T_MIN):
    """Nearest intersection of rays with the scene objects.

    Parameters
    ----------
    objects : sequence of Sphere, Box, GroundPlane, BackPlane
    origins, directions : (N, 3) ndarray
        Ray origins and unit directions.
    t_min : float

    Returns
    -------
    RayHits
    """
    origins, directions = as_rays(origins, directions)
    n = len(origins)
    best = np.full(n, np.inf)
    ids = np.full(n, -1, dtype=np.int64)
    box_normal = np.full((n, 3), np.nan)
    for k, obj in enumerate(objects):
        t, normal = _intersect_object(obj, origins, directions, t_min)
        closer = t < best
        best = np.where(closer, t, best)
        ids[closer] = k
        if normal is not None:
            box_normal[closer] = normal[closer]
    point = np.full((n, 3), np.nan)
    normal = np.full((n, 3), np.nan)
    albedo = np.zeros((n, 3))
    hit = ids >= 0
    point[hit] = origins[hit] + best[hit, None] * directions[hit]
    for k, obj in enumerate(objects):
        sel = ids == k
        if not sel.any():
            continue
        normal[sel] = _normals(obj, point[sel], box_normal[sel])
        material = obj.material
        if material.texture is None:
            albedo[sel] = material.albedo
        else:
            albedo[sel] = texture_albedo(material.texture, _texture_coords(obj, point[sel]))
    return RayHits(distance=best, point=point, normal=normal, object_id=ids, albedo=albedo)


def occluded(objects, origins, directions, max_distance):
    """Shadow-ray test: is anything hit within ``(0, max_distance)`` along each ray?

    Parameters
    ----------
    objects : sequence of scene objects
    origins : (N, 3) ndarray
        Segment starts (already offset off their surface, e.g. by ``SURFACE_OFFSET``).
    directions : (N, 3) ndarray
        Unit directions toward the segment ends (the light).
    max_distance : (N,) ndarray or float
        Segment lengths; ``inf`` for rays toward a distant light.

    Returns
    -------
    (N,) bool ndarray
    """
    origins, directions = as_rays(origins, directions)
    max_distance = np.broadcast_to(np.asarray(max_distance, dtype=np.float64), (len(origins),))
    blocked = np.zeros(len(origins), dtype=bool)
    for obj in objects:
        todo = ~blocked
        if not todo.any():
            break
        t, _ = _intersect_object(obj, origins[todo], directions[todo], T_MIN)
        blocked[todo] = t < max_distance[todo] * (1 - 1e-9)
    return blocked


def wire_occlusion_interval(points, light_points, sweep, mask, *, distant=False):
    """When does a sweep's wire (a cylinder) block the segments point -> light?

    The distance between the segment's line (through P, direction s) and the wire centre
    line ``p(t) = p0 + t v`` (direction d) is ``|(P - p0 - t v).w|`` with
    ``w = normalize(s x d)``: linear in t, so the wire of radius r blocks the segment for
    ``|t - t_c| < r / |v.w|`` with ``t_c = (P - p0).w / (v.w)`` (the analytic shadow time
    of README 1.3 for that light point). The finite wire covers the segment when its crossing
    Q with the mask plane satisfies ``|(Q - p0).d| <= length / 2`` (independent of t, since
    v is perpendicular to d) and Q lies between P and the light.

    Parameters
    ----------
    points : (N, 3) ndarray
        Scene points P.
    light_points : (N, 3) ndarray
        Light sample positions, or unit directions toward a distant light.
    sweep : WireSweep
    mask : MaskPlane
    distant : bool
        `light_points` are directions toward a distant light.

    Returns
    -------
    t_center : (N,) ndarray
        Frame at which the wire centre line shadows P (NaN where not covered).
    half_width : (N,) ndarray
        Half-width of the blocked interval in frames.
    """
    points = np.asarray(points, dtype=np.float64)
    light_points = np.asarray(light_points, dtype=np.float64)
    check_array(points, "points", shape=(None, 3))
    if light_points.shape != points.shape:
        raise ValueError(f"light_points: expected {points.shape}, got {light_points.shape}")
    seg = light_points if distant else light_points - points
    with np.errstate(divide="ignore", invalid="ignore"):
        s = ((mask.origin - points) @ mask.normal) / (seg @ mask.normal)
        between = (s > 0) if distant else (s > 0) & (s < 1)
        q = points + s[:, None] * seg
        covered = between & (np.abs((q - sweep.p0) @ sweep.direction) <= sweep.length / 2)
        w = np.cross(seg, sweep.direction)
        w /= np.linalg.norm(w, axis=1, keepdims=True)
        b = w @ sweep.velocity
        t_center = ((points - sweep.p0) * w).sum(axis=1) / b
        half_width = sweep.radius / np.abs(b)
    t_center = np.where(covered & np.isfinite(t_center), t_center, np.nan)
    return t_center, half_width
