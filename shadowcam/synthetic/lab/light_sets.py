"""Several lights at once under one wire sweep (paper Fig. 11): point and tube lights.

Each light casts its own shadow of the wire, so a pixel lit by k lights sees k dips, one
per light, at the times the wire's shadow from each light passes it. A tube light (a
fluorescent tube: a uniform line source) casts a shadow whose width grows with the tube's
extent across the wire: parallel to the wire the shadow stays sharp, perpendicular to it
the shadow spreads over the frames the wire needs to cross the tube's projection, and its
depth drops (the contrast the paper notes).

The light paths of every light (every sample of a tube) are traced and concatenated, so
``render.sweep_frames`` renders the sweep unchanged (each path is blocked when the wire
crosses its own segment).

Offers
------
TubeLight : a uniform line source sampled by point lights.
light_points : the point lights that make up a light (a tube's samples, or the light).
trace_light_set : LightPaths of several lights (point, area or tube) together.
light_set_ground_truth : per-light shadow times (centre, first and last over the light's
    extent) and the light's share of each pixel's radiance (the dip's depth).
"""

from dataclasses import dataclass

import numpy as np

from shadowcam._shared.validation import check_positive
from shadowcam.synthetic.lab.raycast import intersect_scene
from shadowcam.synthetic.lab.render import LightPaths, _pixel_centres, _surface_terms, trace_light_paths
from shadowcam.synthetic.lab.scene import PointLight, camera_rays, light_samples, wire_shadow_time


@dataclass(frozen=True, eq=False)
class TubeLight:
    """A uniform line source from `start` to `end` of total radiant intensity `intensity`
    (3,) W/sr, sampled by `samples` point lights at the centres of equal segments."""

    start: np.ndarray
    end: np.ndarray
    intensity: np.ndarray = (0.02, 0.02, 0.02)
    samples: int = 16

    def __post_init__(self):
        for name in ("start", "end", "intensity"):
            value = np.asarray(getattr(self, name), dtype=np.float64)
            if value.shape != (3,) or not np.all(np.isfinite(value)):
                raise ValueError(f"{name}: expected 3 finite numbers; got {getattr(self, name)!r}")
            object.__setattr__(self, name, value)
        if int(self.samples) != self.samples or self.samples < 1:
            raise ValueError(f"samples must be an integer >= 1; got {self.samples!r}")
        check_positive(float(np.linalg.norm(self.end - self.start)), "tube length", finite=True)
        object.__setattr__(self, "samples", int(self.samples))

    @property
    def center(self):
        return 0.5 * (self.start + self.end)


def light_points(light):
    """The point lights a light is made of.

    Parameters
    ----------
    light : PointLight, AreaLight or TubeLight

    Returns
    -------
    list of PointLight
        One per sample, each with its share of the intensity.
    """
    if isinstance(light, TubeLight):
        s = (np.arange(light.samples) + 0.5) / light.samples
        positions = light.start + s[:, None] * (light.end - light.start)
        return [PointLight(p, light.intensity / light.samples) for p in positions]
    positions, _, weights = light_samples(light)
    if positions is None:
        raise ValueError("light: a distant light has no position; use point, area or tube "
                         "lights in a light set")
    return [PointLight(p, w) for p, w in zip(positions, weights)]


def trace_light_set(objects, camera, lights, *, supersample=4):
    """Light paths of several lights together (the image is their sum).

    Parameters
    ----------
    objects : sequence of scene objects
    camera : PinholeCamera or OrthographicCamera
    lights : sequence of PointLight, AreaLight or TubeLight
    supersample : int

    Returns
    -------
    paths : LightPaths
        Concatenated over every light's samples.
    source : (n,) int64 ndarray
        Index into `lights` of each path.
    """
    if len(lights) < 1:
        raise ValueError("lights: give at least one light")
    parts, source = [], []
    for index, light in enumerate(lights):
        for point in (light_points(light) if isinstance(light, TubeLight) else [light]):
            paths = trace_light_paths(objects, camera, point, supersample=supersample)
            parts.append(paths)
            source.append(np.full(len(paths.pixel), index, np.int64))
    first = parts[0]
    return LightPaths(shape=first.shape,
                      pixel=np.concatenate([p.pixel for p in parts]),
                      points=np.concatenate([p.points for p in parts]),
                      light=np.concatenate([p.light for p in parts]),
                      radiance=np.concatenate([p.radiance for p in parts]),
                      distant=False), np.concatenate(source)


def light_set_ground_truth(objects, camera, lights, sweep, paths, source):
    """Per-light exact shadow times at the pixel centres and each light's radiance share.

    Parameters
    ----------
    objects, camera
        As for :func:`trace_light_set`.
    lights : sequence of PointLight, AreaLight or TubeLight
    sweep : WireSweep
    paths, source
        From :func:`trace_light_set` (for the radiance shares).

    Returns
    -------
    dict of str to ndarray
        ``t_center`` (K, rows, cols): the frame at which the wire's centre line shadows the
        pixel-centre point from the light's centre; ``t_first``, ``t_last`` (K, rows, cols):
        the earliest and latest such frame over the light's points (a tube's samples and
        ends, an area light's samples); all NaN where the light's centre is hidden from
        the point or the point does not face it. ``share`` (K, rows, cols): the light's
        fraction of the pixel's radiance (the depth of its dip when its shadow is full).
    """
    rows, cols = camera.height, camera.width
    x, y = _pixel_centres(camera)
    origins, dirs = camera_rays(camera, x, y)
    hits = intersect_scene(objects, origins, dirs)
    t_center, t_first, t_last = [], [], []
    for light in lights:
        lit = _surface_terms(objects, hits.point, hits.normal, hits.hit, camera,
                             PointLight(light.center))[4]
        ends = [p.position for p in light_points(light)]
        if isinstance(light, TubeLight):
            ends += [light.start, light.end]
        times = np.stack([wire_shadow_time(hits.point, sweep, PointLight(e)) for e in ends])
        centre = wire_shadow_time(hits.point, sweep, PointLight(light.center))
        t_center.append(np.where(lit, centre, np.nan))
        t_first.append(np.where(lit, times.min(axis=0), np.nan))
        t_last.append(np.where(lit, times.max(axis=0), np.nan))
    n_pix = rows * cols
    per_light = np.stack([np.bincount(paths.pixel[source == k],
                                      weights=paths.radiance[source == k].sum(axis=1),
                                      minlength=n_pix) for k in range(len(lights))])
    total = per_light.sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        share = np.where(total > 0, per_light / total, np.nan)
    shape = (len(lights), rows, cols)
    return {"t_center": np.stack(t_center).reshape(shape),
            "t_first": np.stack(t_first).reshape(shape),
            "t_last": np.stack(t_last).reshape(shape),
            "share": share.reshape(shape)}
