"""General wire sweeps (Fig. 12 and 10 of the paper) and their exact ground truth.

A sweep is declared by its wire angle in the mask plane, its motion direction and speed, its
frame count, the plane it moves in (the mask plane or a parallel one) and its own light. Angles
are measured in the mask plane in the sense that turns e_u into e_v: a wire at ``angle_deg``
theta has direction ``d = -sin(theta) e_u + cos(theta) e_v`` (theta = 0: along e_v, the u sweep
of README 1.3), and by default moves along ``m = cos(theta) e_u + sin(theta) e_v``
(perpendicular to the wire; theta = 90 moves along e_v like the v sweep).

Offers
------
SPEC_KEYS : the keys a sweep specification may hold.
make_sweeps : WireSweeps from a mask plane and a list of specifications.
wire_position : wire centre point ``p0 + t v`` at given times.
shadow_crossing : where the segment point -> light crosses a sweep's wire plane.
dual_affine : exact affine relation ``t = a u + b v + c`` between a sweep's shadow time and
    the dual coordinates (u, v) of the mask plane, for a sweep sharing the mask's light.
true_dual_coordinates : the virtual-image coordinates (t_a, t_b) of points for a sweep pair.
"""

import math

import numpy as np

from shadowcam.cameras.models import frames_to_cross
from shadowcam.synthetic.lab.scene import (
    AreaLight,
    DistantLight,
    PointLight,
    WireSweep,
    _vec,
    wire_shadow_time,
)

#: keys of a sweep specification (see ``make_sweeps``)
SPEC_KEYS = ("name", "angle_deg", "motion_deg", "speed", "speed_scene", "frames",
             "plane_offset", "light", "light_offset", "light_direction")

#: smallest |sine| between wire and motion, or between a pair of wires, and smallest relative
#: height of a light over a wire plane, accepted before a geometry counts as degenerate
DEGENERATE_SINE = 1e-6


def _cos_sin_deg(angle_deg):
    """(cos, sin) of an angle in degrees, exact at multiples of 90."""
    a = float(angle_deg) % 360.0
    exact = {0.0: (1.0, 0.0), 90.0: (0.0, 1.0), 180.0: (-1.0, 0.0), 270.0: (0.0, -1.0)}
    if a in exact:
        return exact[a]
    r = math.radians(a)
    return math.cos(r), math.sin(r)


def _finite(value, name):
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a number, got {value!r}") from None
    if not math.isfinite(value):
        raise ValueError(f"{name}: must be finite, got {value!r}")
    return value


def _spec_light(spec, key_prefix, base_light, mask):
    """The light a spec asks for (None = the sweeps' default light)."""
    given = [k for k in ("light", "light_offset", "light_direction") if spec.get(k) is not None]
    if len(given) > 1:
        raise ValueError(f"{key_prefix}: give at most one of light, light_offset, "
                         f"light_direction (got {given})")
    if not given:
        return base_light
    key = given[0]
    value = spec[key]
    if key == "light":
        if not isinstance(value, (PointLight, AreaLight, DistantLight)):
            raise ValueError(f"{key_prefix}.light: expected a PointLight, AreaLight or "
                             f"DistantLight, got {type(value).__name__}")
        return value
    if key == "light_direction":
        direction = _vec(value, f"{key_prefix}.light_direction")
        strength = (base_light.irradiance if isinstance(base_light, DistantLight)
                    else (2.0, 2.0, 2.0))
        return DistantLight(direction, strength)
    if not isinstance(base_light, (PointLight, AreaLight)):
        raise ValueError(f"{key_prefix}.light_offset: needs a point or area default light "
                         f"(pass light=...); use light_direction for a distant light")
    offset = _vec(value, f"{key_prefix}.light_offset")
    shift = offset[0] * mask.e_u + offset[1] * mask.e_v + offset[2] * mask.normal
    if isinstance(base_light, PointLight):
        return PointLight(base_light.position + shift, base_light.intensity)
    return AreaLight(base_light.position + shift, base_light.normal, base_light.size,
                     base_light.shape, base_light.intensity, base_light.samples_per_side)


def _check_light_off_plane(light, p0, normal, scale, key_prefix):
    """ValueError when the light lies (nearly) in the plane the wire moves in."""
    if light is None:
        return
    if isinstance(light, DistantLight):
        height, reach = abs(light.direction @ normal), 1.0
    else:
        height, reach = abs((light.center - p0) @ normal), max(scale,
                                                                np.linalg.norm(light.center - p0))
    if height <= DEGENERATE_SINE * reach:
        raise ValueError(f"{key_prefix}.light: lies (nearly) in the plane the wire moves in "
                         f"(height {height:.3g} over the plane); every shadow plane of the "
                         f"sweep would be the same plane. Move the light off the plane")


def make_sweeps(mask, specs, *, light=None, radius=None, length=None):
    """Wire sweeps from specifications (Fig. 12: slanted, stretched; Fig. 10: cross-slit).

    Parameters
    ----------
    mask : MaskPlane
    specs : sequence of dict
        One dict per sweep, keys from ``SPEC_KEYS``:

        ``name`` (str, required, unique, not starting with ``cal_``);
        ``angle_deg`` (float, default 0): wire direction ``-sin e_u + cos e_v``;
        ``motion_deg`` (float, optional): motion direction ``cos e_u + sin e_v``; default
        ``angle_deg`` (perpendicular to the wire). An oblique motion is stored as its
        component perpendicular to the wire (the same wire line in every frame);
        ``speed`` (float, default 1): mask-plane step per frame along the motion, in dual
        pixels (multiples of ``mask.delta``), or ``speed_scene`` in scene units;
        ``frames`` (int >= 2, default: enough to cross the dual field
        ``(N_u |cos| + N_v |sin|) delta`` at the perpendicular speed);
        ``plane_offset`` (float, default 0): the wire moves in the plane parallel to the mask
        plane, shifted by this many scene units along the mask normal;
        ``light`` (a light object), ``light_offset`` ((3,) shift of the default point/area
        light along (e_u, e_v, n), scene units) or ``light_direction`` ((3,) toward a
        distant light of the default distant light's irradiance, or (2, 2, 2) as the
        tabletop preset's); default: `light`.

        The sweep's middle frame ``(frames - 1) / 2`` passes through the foot of the mask
        origin on its plane; sweep ``{"name": "u"}`` is ``make_wire_sweeps(mask)["u"]``
        bit for bit.
    light : PointLight, AreaLight or DistantLight, optional
        Default light of the sweeps (None: sweeps without their own light use the scene's).
    radius, length : float, optional
        Wire radius (default ``mask.delta``) and length (default 1.5 x the dual field
        diagonal), as in ``make_wire_sweeps``.

    Returns
    -------
    dict of str to WireSweep
        In the order of `specs`; each carries its light (``WireSweep.light``).

    Raises
    ------
    ValueError
        Naming the parameter: unknown keys, duplicate names, non-positive speed, motion
        (nearly) parallel to the wire, a light (nearly) in the plane the wire moves in.
    """
    if isinstance(specs, dict) or not hasattr(specs, "__iter__"):
        raise ValueError("specs: expected a sequence of dicts (one per sweep)")
    specs = list(specs)
    if not specs:
        raise ValueError("specs: at least one sweep is needed")
    radius = mask.delta if radius is None else _positive_value(radius, "radius")
    if length is None:
        length = 1.5 * math.hypot(mask.n_u, mask.n_v) * mask.delta
    length = _positive_value(length, "length")
    scale = max(mask.n_u, mask.n_v) * mask.delta
    sweeps = {}
    for index, spec in enumerate(specs):
        if not isinstance(spec, dict):
            raise ValueError(f"specs[{index}]: expected a dict, got {type(spec).__name__}")
        unknown = sorted(set(spec) - set(SPEC_KEYS))
        if unknown:
            raise ValueError(f"specs[{index}]: unknown keys {unknown}; allowed {SPEC_KEYS}")
        name = spec.get("name")
        if not isinstance(name, str) or not name or name.startswith("cal_"):
            raise ValueError(f"specs[{index}].name: expected a non-empty name not starting "
                             f"with 'cal_', got {name!r}")
        if name in sweeps:
            raise ValueError(f"specs[{index}].name: duplicate sweep name {name!r}")
        key = f"specs[{index}] ({name!r})"
        angle = _finite(spec.get("angle_deg", 0.0), f"{key}.angle_deg")
        cos_w, sin_w = _cos_sin_deg(angle)
        direction = -sin_w * mask.e_u + cos_w * mask.e_v
        across = cos_w * mask.e_u + sin_w * mask.e_v  # in-plane unit normal of the wire
        motion_deg = spec.get("motion_deg")
        if motion_deg is None:
            perpendicular = 1.0
        else:
            cos_m, sin_m = _cos_sin_deg(_finite(motion_deg, f"{key}.motion_deg"))
            perpendicular = cos_m * cos_w + sin_m * sin_w  # m . across
            if abs(perpendicular) <= DEGENERATE_SINE:
                raise ValueError(f"{key}.motion_deg: the motion ({motion_deg} deg) is (nearly) "
                                 f"parallel to the wire (angle_deg {angle}); the wire would "
                                 f"slide along itself and shadow nothing new")
        if spec.get("speed") is not None and spec.get("speed_scene") is not None:
            raise ValueError(f"{key}: give speed or speed_scene, not both")
        if spec.get("speed_scene") is not None:
            step = _positive_value(spec["speed_scene"], f"{key}.speed_scene")
        else:
            step = _positive_value(spec.get("speed", 1.0), f"{key}.speed") * mask.delta
        velocity = (step * perpendicular) * across
        if spec.get("frames") is None:
            frames = frames_to_cross((mask.n_v, mask.n_u), angle,
                                     step * abs(perpendicular) / mask.delta)
        else:
            frames = spec["frames"]
            if isinstance(frames, bool) or int(frames) != frames or int(frames) < 2:
                raise ValueError(f"{key}.frames: must be an integer >= 2, got {frames!r}")
            frames = int(frames)
        plane_offset = _finite(spec.get("plane_offset", 0.0), f"{key}.plane_offset")
        centre = mask.origin + plane_offset * mask.normal if plane_offset else mask.origin
        p0 = centre - (frames - 1) / 2.0 * velocity
        sweep_light = _spec_light(spec, key, light, mask)
        _check_light_off_plane(sweep_light, p0, mask.normal, scale, key)
        sweeps[name] = WireSweep(axis=name, p0=p0, velocity=velocity, direction=direction,
                                 frames=frames, radius=radius, length=length,
                                 light=sweep_light)
    return sweeps


def _positive_value(value, name):
    value = _finite(value, name)
    if value <= 0:
        raise ValueError(f"{name}: must be positive, got {value!r}")
    return value


def wire_position(sweep, times):
    """Wire centre point ``p0 + t velocity`` at `times`.

    Parameters
    ----------
    sweep : WireSweep
    times : (N,) array_like
        Fractional frames.

    Returns
    -------
    (N, 3) float64 ndarray
    """
    times = np.asarray(times, dtype=np.float64).reshape(-1)
    return sweep.p0 + times[:, None] * sweep.velocity


def _sweep_normal(sweep):
    normal = np.cross(sweep.direction, sweep.velocity)
    return normal / np.linalg.norm(normal)


def shadow_crossing(points, sweep, light=None):
    """Where the segment from each point toward the light crosses the sweep's wire plane.

    Parameters
    ----------
    points : (N, 3) ndarray
    sweep : WireSweep
    light : PointLight, AreaLight or DistantLight, optional
        Default ``sweep.light``; area lights use their centre.

    Returns
    -------
    (N, 3) float64 ndarray
        The crossing Q; the wire shadows the point at time t exactly when Q lies on the wire
        centre line ``wire_position(sweep, t) + s direction`` (NaN where the segment is
        parallel to the plane).
    """
    light = sweep.light if light is None else light
    if light is None:
        raise ValueError("light: the sweep carries no light; pass one")
    points = np.asarray(points, dtype=np.float64)
    normal = _sweep_normal(sweep)
    toward = (np.broadcast_to(light.direction, points.shape) if isinstance(light, DistantLight)
              else light.center - points)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = ((sweep.p0 - points) @ normal) / (toward @ normal)
    return points + s[:, None] * toward


def dual_affine(mask, sweep, light=None):
    """Exact affine relation between a sweep's shadow time and the dual coordinates (u, v).

    For a sweep whose light is the mask plane's own light (point/area light at
    ``M0 - f n``; or a distant light along ``-n``), every scene point whose mask-plane crossing
    has dual coordinates (u, v) (``Q = M0 + delta (u - (N_u-1)/2) e_u + delta (v - (N_v-1)/2) e_v``,
    so the standard sweeps give ``t_u = u``, ``t_v = v``) is shadowed at

        ``t = a u + b v + c``,
        ``a = s delta (e_u . vel) / |vel|^2``, ``b = s delta (e_v . vel) / |vel|^2``,
        ``c = (M0 - p0) . vel / |vel|^2 - a (N_u - 1)/2 - b (N_v - 1)/2``,

    with ``s = ((p0 - L) . n) / f`` (ratio of the wire plane's and the mask plane's distance
    from the light) for a point light and ``s = 1`` for a distant light. For a wire at
    ``angle_deg`` theta moving perpendicular to itself at ``speed`` sigma dual pixels per frame in
    the mask plane this is ``t = (cos(theta) (u - (N_u-1)/2) + sin(theta) (v - (N_v-1)/2)) / sigma
    + (frames - 1)/2``. The virtual image of two sweeps (a, b) has coordinates
    ``(t_a, t_b) = A (u, v, 1)`` (rows ``dual_affine`` of each): skew and stretch of the
    virtual camera are exactly those of the 2 x 2 part of A.

    Parameters
    ----------
    mask : MaskPlane
    sweep : WireSweep
    light : PointLight, AreaLight or DistantLight, optional
        Default ``sweep.light``.

    Returns
    -------
    (3,) float64 ndarray
        (a, b, c).

    Raises
    ------
    ValueError
        If the light is not the mask plane's light (then the time is not a function of
        (u, v) alone: it depends on depth).
    """
    light = sweep.light if light is None else light
    if light is None:
        raise ValueError("light: the sweep carries no light; pass one")
    vel = sweep.velocity
    speed2 = vel @ vel
    if isinstance(light, DistantLight):
        if mask.focal is not None or not np.allclose(light.direction, -mask.normal,
                                                     rtol=0, atol=1e-12):
            raise ValueError("light: a distant light along -mask.normal is needed for an "
                             "affine relation (the sweep has another light)")
        s = 1.0
    else:
        if mask.focal is None:
            raise ValueError("light: the mask plane belongs to a distant light")
        centre = mask.origin - mask.focal * mask.normal
        if np.linalg.norm(light.center - centre) > 1e-12 * max(1.0, np.linalg.norm(centre)):
            raise ValueError("light: the sweep's light is not the mask plane's light; its "
                             "shadow time depends on depth, not on (u, v) alone")
        s = ((sweep.p0 - light.center) @ mask.normal) / mask.focal
    a = s * mask.delta * (mask.e_u @ vel) / speed2
    b = s * mask.delta * (mask.e_v @ vel) / speed2
    c = (mask.origin - sweep.p0) @ vel / speed2 - a * (mask.n_u - 1) / 2 - b * (mask.n_v - 1) / 2
    return np.array([a, b, c])


def true_dual_coordinates(points, sweeps, names, *, light=None):
    """Virtual-image coordinates of points for the sweep pair `names` (Fig. 10, 12).

    The virtual camera of two sweeps (a, b) has pixel (row j, col i) centre at
    ``(t_a, t_b) = (i, j)``: its coordinates are the two analytic shadow times, each under its
    own sweep's light. With both sweeps under one light this is a perspective (point light)
    or orthographic (distant light) camera, affinely related to the dual coordinates
    (``dual_affine``); with two lights it is a cross-slit camera (``lab.virtual``).

    Parameters
    ----------
    points : (N, 3) ndarray
    sweeps : dict of str to WireSweep
    names : (str, str)
    light : PointLight, AreaLight or DistantLight, optional
        Light of sweeps that carry none (the scene's light).

    Returns
    -------
    (N, 2) float64 ndarray
        (t_a, t_b) per point (fractional frames, unrestricted; NaN where undefined).
    """
    names = tuple(names)
    if len(names) != 2 or any(n not in sweeps for n in names):
        raise ValueError(f"names: expected two of {sorted(sweeps)}, got {names!r}")
    lights = [light if sweeps[n].light is None else sweeps[n].light for n in names]
    if any(lt is None for lt in lights):
        raise ValueError("light: a sweep carries no light; pass the scene's light")
    return np.stack([wire_shadow_time(points, sweeps[n], lt) for n, lt in zip(names, lights)],
                    axis=-1)
