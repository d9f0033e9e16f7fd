"""Virtual (shadow) cameras defined by a pair of wire sweeps: perspective, orthographic,
skewed/stretched (Fig. 12) and cross-slit (Fig. 10).

The shadow plane of sweep k at time t is the plane through the wire centre line
``p0 + t v + s d`` and the sweep's light: through the light centre L for a point or area
light (normal ``d x (p(t) - L)``), parallel to the light direction l for a distant light
(normal ``d x l``). A point shadowed at (t_a, t_b) lies on both shadow planes, so the viewing
ray of virtual pixel (t_a, t_b) is their intersection line. Under one light this line passes
through the light (perspective) or runs along l (orthographic); with sweep a under L1 and
sweep b under L2 it meets both slits ``L1 + s d_a`` and ``L2 + s d_b``: a cross-slit camera.

Offers
------
SweepPairCamera : the virtual camera of two sweeps; pixel (row j, col i) centre <-> (t_a, t_b)
    = (i, j). It offers ``rays``, ``view_dirs`` and ``project`` and is accepted by
    ``scene.camera_rays`` / ``scene.project`` and the renderer.
sweep_pair_camera : build it from a dict of sweeps and two names.
shadow_planes : unit normals and offsets of a sweep's shadow planes at given times.
"""

from dataclasses import dataclass

import numpy as np

from shadowcam.synthetic.lab.scene import DistantLight, wire_shadow_time
from shadowcam.synthetic.lab.sweeps import DEGENERATE_SINE


def _light_of(sweep, light):
    light = sweep.light if sweep.light is not None else light
    if light is None:
        raise ValueError(f"light: sweep {sweep.axis!r} carries no light; pass one")
    return light


def _normalise(vectors):
    with np.errstate(divide="ignore", invalid="ignore"):
        return vectors / np.linalg.norm(vectors, axis=-1, keepdims=True)


def shadow_planes(sweep, times, light=None):
    """Shadow planes of a sweep at `times`: ``{X : normal . X = offset}``.

    Parameters
    ----------
    sweep : WireSweep
    times : (N,) array_like
        Fractional frames.
    light : PointLight, AreaLight or DistantLight, optional
        Default ``sweep.light``; area lights use their centre.

    Returns
    -------
    normal : (N, 3) float64 ndarray
        Unit normals.
    offset : (N,) float64 ndarray
    """
    light = _light_of(sweep, light)
    times = np.asarray(times, dtype=np.float64).reshape(-1)
    wire = sweep.p0 + times[:, None] * sweep.velocity
    if isinstance(light, DistantLight):
        normal = np.broadcast_to(np.cross(sweep.direction, light.direction), wire.shape)
        normal = _normalise(normal)
        return normal, (normal * wire).sum(axis=1)
    normal = _normalise(np.cross(sweep.direction, wire - light.center))
    return normal, normal @ light.center


def _plane_through_point(sweep, light, points):
    """Unit normals of the planes through `points` containing the sweep's slit."""
    if isinstance(light, DistantLight):
        return np.broadcast_to(_normalise(np.cross(sweep.direction, light.direction)),
                               points.shape)
    return _normalise(np.cross(sweep.direction, points - light.center))


@dataclass(frozen=True, eq=False)
class SweepPairCamera:
    """The virtual camera of sweeps a and b: pixel (row j, col i) centre <-> (t_a, t_b) = (i, j).

    Pixel-edge coordinates (x, y) (pixel centre at (i + 0.5, j + 0.5)) map to the times
    ``(t_a, t_b) = (x - 0.5, y - 0.5)``; the viewing ray is the intersection of the shadow
    planes (``shadow_planes``), directed along `forward` (away from the lights, into the
    scene) and starting on the entrance plane ``(X - p0_a) . forward = entrance`` (the
    rearmost of the lights and the wire planes).

    Attributes
    ----------
    sweep_a, sweep_b : WireSweep
    light_a, light_b : PointLight, AreaLight or DistantLight
    forward : (3,) unit normal of sweep a's wire plane, pointing away from light a.
    entrance : float
    width, height : int
        Virtual image size (cols = frames of a, rows = frames of b by default).
    """

    sweep_a: object
    sweep_b: object
    light_a: object
    light_b: object
    forward: np.ndarray
    entrance: float
    width: int
    height: int

    def _ray_lines(self, t_a, t_b):
        n_a, o_a = shadow_planes(self.sweep_a, t_a, self.light_a)
        n_b, o_b = shadow_planes(self.sweep_b, t_b, self.light_b)
        direction = np.cross(n_a, n_b)
        sine = np.linalg.norm(direction, axis=1)
        f = self.forward
        o_f = f @ self.sweep_a.p0 + self.entrance
        # Cramer's rule for {n_a.X = o_a, n_b.X = o_b, f.X = o_f}
        det = (direction * f).sum(axis=1)
        origin = (o_a[:, None] * np.cross(n_b, f) + o_b[:, None] * np.cross(f, n_a)
                  + o_f * direction)
        with np.errstate(divide="ignore", invalid="ignore"):
            origin = origin / det[:, None]
            direction = direction * (np.sign(det) / sine)[:, None]
        bad = (sine <= DEGENERATE_SINE) | (np.abs(det) <= DEGENERATE_SINE * sine)
        origin[bad] = np.nan
        direction[bad] = np.nan
        return origin, direction

    def rays(self, x, y):
        """Viewing rays through pixel-edge coordinates.

        Parameters
        ----------
        x, y : (N,) ndarray
            Pixel-edge coordinates (column, row).

        Returns
        -------
        origins, directions : (N, 3) ndarray
            Ray origins on the entrance plane and unit directions into the scene (NaN where
            the two shadow planes are parallel).
        """
        x = np.asarray(x, dtype=np.float64).ravel()
        y = np.asarray(y, dtype=np.float64).ravel()
        if x.shape != y.shape:
            raise ValueError(f"x, y: shapes differ ({x.shape} vs {y.shape})")
        return self._ray_lines(x - 0.5, y - 0.5)

    def view_dirs(self, points):
        """(N, 3) unit directions from `points` back along their viewing rays (toward the
        slits / the light)."""
        points = np.asarray(points, dtype=np.float64)
        back = np.cross(_plane_through_point(self.sweep_a, self.light_a, points),
                        _plane_through_point(self.sweep_b, self.light_b, points))
        back = _normalise(back)
        return back * -np.sign(back @ self.forward)[:, None]

    def project(self, points):
        """Pixel-edge (x, y) = (t_a + 0.5, t_b + 0.5) of (N, 3) `points` and their (N,) depth
        beyond the entrance plane along `forward`."""
        points = np.asarray(points, dtype=np.float64)
        xy = np.stack([wire_shadow_time(points, self.sweep_a, self.light_a),
                       wire_shadow_time(points, self.sweep_b, self.light_b)], axis=-1) + 0.5
        depth = (points - self.sweep_a.p0) @ self.forward - self.entrance
        return xy, depth


def sweep_pair_camera(sweeps, names=("u", "v"), *, light=None, width=None, height=None):
    """The virtual camera of two sweeps (perspective, orthographic, skewed or cross-slit).

    Parameters
    ----------
    sweeps : dict of str to WireSweep
    names : (str, str)
        Sweep a gives the column coordinate, sweep b the row coordinate.
    light : PointLight, AreaLight or DistantLight, optional
        Light of sweeps that carry none (the scene's light).
    width, height : int, optional
        Image size; default the frame counts of sweeps a and b.

    Returns
    -------
    SweepPairCamera

    Raises
    ------
    ValueError
        If the wires are (nearly) parallel (``names``): their shadow planes meet in no ray.
    """
    names = tuple(names)
    if len(names) != 2 or any(n not in sweeps for n in names) or names[0] == names[1]:
        raise ValueError(f"names: expected two different names of {sorted(sweeps)}, "
                         f"got {names!r}")
    sweep_a, sweep_b = (sweeps[n] for n in names)
    light_a, light_b = _light_of(sweep_a, light), _light_of(sweep_b, light)
    if np.linalg.norm(np.cross(sweep_a.direction, sweep_b.direction)) <= DEGENERATE_SINE:
        raise ValueError(f"names: the wires of sweeps {names[0]!r} and {names[1]!r} are "
                         f"(nearly) parallel; their shadow times do not form a 2-D image")
    forward = np.cross(sweep_a.direction, sweep_a.velocity)
    forward /= np.linalg.norm(forward)
    if isinstance(light_a, DistantLight):
        toward_a = light_a.direction @ forward
    else:
        toward_a = (light_a.center - sweep_a.p0) @ forward
    if toward_a > 0:
        forward = -forward
    heights = [0.0, (sweep_b.p0 - sweep_a.p0) @ forward]
    for lt in (light_a, light_b):
        if not isinstance(lt, DistantLight):
            heights.append((lt.center - sweep_a.p0) @ forward)
    width = sweep_a.frames if width is None else int(width)
    height = sweep_b.frames if height is None else int(height)
    if width < 1 or height < 1:
        raise ValueError(f"width, height: must be positive, got {width}, {height}")
    return SweepPairCamera(sweep_a=sweep_a, sweep_b=sweep_b, light_a=light_a, light_b=light_b,
                           forward=forward, entrance=float(min(heights)), width=width,
                           height=height)
