"""Exact occlusion of a continuous area light by a wire (a cylinder), per scene point and frame.

Seen from a scene point P, the lines through P that touch the wire (axis ``p0 + t v``,
direction d, radius r) form two planes through P parallel to d, tangent to the cylinder;
the light P receives through the wire is cut off between them. A source in a plane meets
that wedge in a strip (two straight lines, parallel when the plane holds d), so the share
of a uniform disc the wire blocks is a difference of two circular segments, and of a
uniform line source (a tube) a segment's overlap. A sphere of uniform radiance shadows
as the uniform disc of its radius facing P (``scene._sphere_offsets``). This is the
continuous source the renderer's point samples approximate; a square has no exact form
here (its samples are used).

Offers
------
EXACT_SHAPES : area-light shapes with an exact occlusion.
exact_occlusion : whether a light's occlusion by the wire is computed exactly.
blocked_share : share of the source the wire blocks, per point and time.
occlusion_times : when the blocked share first reaches and last leaves a value, per point.
extreme_offset : half extent of the source along a direction (its extreme point's offset).
"""

import numpy as np

from shadowcam._shared.validation import check_array, check_in_interval
from shadowcam.lab.penumbra_law import disc_share_below
from shadowcam.synthetic.lab.raycast import wire_occlusion_interval
from shadowcam.synthetic.lab.scene import AreaLight, light_plane_axes

#: area-light shapes whose occlusion by the wire is exact (a square keeps its samples)
EXACT_SHAPES = ("disc", "sphere", "tube")


def exact_occlusion(light):
    """True when `light` is an area light of one of :data:`EXACT_SHAPES`."""
    return isinstance(light, AreaLight) and light.shape in EXACT_SHAPES


def _tangent_normals(points, sweep, time):
    """(N, 2, 3) normals m of the two planes through `points` tangent to the wire at `time`:
    the wire blocks the line P -> x iff ``m_k . (x - P) < 0`` for both k. NaN where P is
    inside the wire's cylinder."""
    d = sweep.direction
    rel = sweep.p0 + np.asarray(time, dtype=np.float64)[..., None] * sweep.velocity - points
    rel = rel - (rel @ d)[..., None] * d
    dist = np.linalg.norm(rel, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        toward = rel / dist[..., None]
        sine = sweep.radius / dist
        cosine = np.sqrt(1.0 - sine * sine)
    across = np.cross(d, toward)
    first = cosine[..., None] * across - sine[..., None] * toward
    second = -cosine[..., None] * across - sine[..., None] * toward
    return np.stack([first, second], axis=-2)


def _disc_geometry(points, light):
    """Centre, unit normal (N, 3) and radius of the uniform disc each point sees."""
    centre = np.broadcast_to(light.position, points.shape)
    if light.shape == "sphere":
        normal = centre - points
        normal = normal / np.linalg.norm(normal, axis=-1, keepdims=True)
    else:
        normal = np.broadcast_to(light.normal, points.shape)
    return centre, normal, 0.5 * light.size


def _half_plane_share(points, light, normal_m):
    """Share of the source on the blocked side ``m . (x - P) < 0`` of one tangent plane."""
    offset = ((light.position - points) * normal_m).sum(axis=-1)
    if light.shape == "tube":
        axis = light_plane_axes(light)[0]
        slope = normal_m @ axis  # m . (x - P) = offset + a slope, a in [-L/2, L/2]
        half = 0.5 * light.size
        with np.errstate(invalid="ignore", divide="ignore"):
            root = -offset / slope
        below = np.clip((root + half) / (2 * half), 0.0, 1.0)  # share with a < root
        share = np.where(slope > 0, below, 1.0 - below)
        return np.where(slope == 0, (offset < 0).astype(np.float64), share)
    _, disc_normal, radius = _disc_geometry(points, light)
    in_plane = normal_m - (normal_m * disc_normal).sum(axis=-1, keepdims=True) * disc_normal
    length = np.linalg.norm(in_plane, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        z = -offset / (length * radius)
    return np.where(length > 0, disc_share_below(z), (offset < 0).astype(np.float64))


def blocked_share(points, light, sweep, mask, times):
    """Share of a continuous area light the wire blocks, seen from each point at each time.

    Parameters
    ----------
    points : (N, 3) array_like
        Scene points.
    light : AreaLight
        Of a shape in :data:`EXACT_SHAPES`, uniform over its disc, sphere or line.
    sweep : WireSweep
    mask : MaskPlane
    times : (N,) or (N, T) array_like
        Frames (the wire at ``p0 + t v``).

    Returns
    -------
    ndarray
        Shape of `times`: the blocked share in [0, 1] (0 where the finite wire does not
        cover the line to the light's centre, or the light is not beyond the mask plane).
    """
    points = np.asarray(points, dtype=np.float64)
    check_array(points, "points", shape=(None, 3))
    if not exact_occlusion(light):
        raise ValueError(f"light: needs an area light of shape {EXACT_SHAPES}; got {light!r}")
    times = np.asarray(times, dtype=np.float64)
    if times.shape[:1] != points.shape[:1] or times.ndim > 2:
        raise ValueError(f"times: expected shape ({len(points)},) or ({len(points)}, T); got {times.shape}")
    centre_time, _ = wire_occlusion_interval(points, np.broadcast_to(light.position, points.shape), sweep, mask)
    covered = np.isfinite(centre_time)
    stack = points if times.ndim == 1 else np.broadcast_to(points[:, None], times.shape + (3,))
    normals = _tangent_normals(stack, sweep, times)
    shares = [_half_plane_share(stack, light, normals[..., k, :]) for k in (0, 1)]
    # the two sides' shares overlap in the strip (their union is the whole source)
    share = np.clip(shares[0] + shares[1] - 1.0, 0.0, 1.0)
    share = np.where(np.isfinite(share), share, 1.0)  # the point inside the wire sees none of it
    covered = covered if times.ndim == 1 else covered[:, None]
    return np.where(covered, share, 0.0)


def occlusion_times(points, light, sweep, mask, *, share=0.0, iterations=45):
    """When the blocked share first exceeds `share` and last falls back to it, per point.

    The blocked share rises while the wire's leading edge crosses the source and falls
    while its trailing edge does, around the time its axis passes the source's centre
    (``wire_occlusion_interval`` of the centre); each side is solved by bisection.

    Parameters
    ----------
    points : (N, 3) array_like
    light, sweep, mask
        As :func:`blocked_share`.
    share : float, optional
        In [0, 1): 0 = first contact and last release (the source's extreme points),
        0.5 = half the source blocked.
    iterations : int, optional
        Bisection steps (45: below 1e-10 frame over a 20-frame reach).

    Returns
    -------
    first, last : (N,) float64 ndarray
        Frames; NaN where the wire misses the line to the centre or never blocks more
        than `share`.
    """
    check_in_interval(share, "share", 0.0, 1.0, closed="left")
    points = np.asarray(points, dtype=np.float64)
    centre, half = wire_occlusion_interval(points, np.broadcast_to(light.position, points.shape), sweep, mask)
    reach = 2.0 * half + 2.0 * _time_extent(points, light, sweep, mask, centre)
    peak = blocked_share(points, light, sweep, mask, np.nan_to_num(centre))
    found = np.isfinite(centre) & (peak > share)
    out = []
    for side in (-1.0, 1.0):
        inside, outside = centre.copy(), centre + side * reach
        for _ in range(iterations):
            middle = 0.5 * (inside + outside)
            above = blocked_share(points, light, sweep, mask, np.nan_to_num(middle)) > share
            inside, outside = np.where(above, middle, inside), np.where(above, outside, middle)
        out.append(np.where(found, 0.5 * (inside + outside), np.nan))
    return out[0], out[1]


def _time_extent(points, light, sweep, mask, centre):
    """Frames the wire's axis takes to cross the source's projection (an upper bound: points
    a whole size from its centre along the mask's axes; 0 where the finite wire misses them)."""
    offsets = [light.position + sign * light.size * axis for sign in (-1.0, 1.0) for axis in (mask.e_u, mask.e_v)]
    spans = np.stack([np.abs(wire_occlusion_interval(points, np.broadcast_to(o, points.shape), sweep, mask)[0]
                             - centre) for o in offsets])
    return np.where(np.isfinite(spans), spans, 0.0).max(axis=0)


def extreme_offset(light, direction):
    """Half extent of a continuous source along unit `direction`: its extreme points are
    ``position +- extreme_offset * direction`` in that coordinate.

    Parameters
    ----------
    light : AreaLight
        Of a shape in :data:`EXACT_SHAPES`.
    direction : (3,) array_like
        Unit vector.

    Returns
    -------
    float
        Disc: ``R sqrt(1 - (n.direction)^2)``; sphere: R; tube: ``L/2 |axis.direction|``.
    """
    direction = np.asarray(direction, dtype=np.float64)
    if light.shape == "sphere":
        return 0.5 * light.size
    if light.shape == "tube":
        axis = light_plane_axes(light)[0]
        return 0.5 * light.size * abs(float(axis @ direction))
    return 0.5 * light.size * float(np.sqrt(max(0.0, 1.0 - (light.normal @ direction) ** 2)))
