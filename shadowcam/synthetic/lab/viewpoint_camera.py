"""The reciprocal camera of a viewpoint across a wide wire's dip (paper Fig. 13's ground truth).

A wire of radius r (a cylinder around ``p(t) = p0 + t v``, direction d) blocks the
line from a scene point P to a source point s while that line lies within r of the
wire's axis; the distance is linear in t (:func:`shadowcam.synthetic.lab.raycast.wire_occlusion_interval`),
so the blocked interval is ``t_c +- h``. The time at fraction f across it,
``t_c + (2 f - 1) h``, is when the line s -> P lies at signed distance ``(1 - 2 f) r``
from the axis, ahead of it in the motion for f < 1/2 (f = 0: the leading edge touches
the line; f = 1/2: the axis crosses it; f = 1: the trailing edge leaves it). Every line
from s at that distance from the axis at time t, and parallel to d, lies in one plane
through s: so the points whose times in two sweeps are (t_a, t_b) lie on the line where
two such planes meet, a ray from s. The viewpoint's dual view is the exact pinhole view
from s with these rays; f = 1/2 with s at the light centre is the standard dual camera.

Offers
------
ViewpointCamera : the virtual camera of a source point and a fraction across the dip; pixel
    (row j, col i) centre <-> (t_a, t_b) = (i, j). It offers ``rays``, ``view_dirs`` and
    ``project`` and is accepted by ``scene.camera_rays`` / ``scene.project`` and the renderer.
viewpoint_camera : build it from a dict of sweeps, two names, a source point and a fraction.
"""

from dataclasses import dataclass

import numpy as np

from shadowcam._shared.validation import check_array, check_in_interval
from shadowcam.synthetic.lab.raycast import wire_occlusion_interval
from shadowcam.synthetic.lab.sweeps import DEGENERATE_SINE


def _unit(vectors):
    with np.errstate(divide="ignore", invalid="ignore"):
        return vectors / np.linalg.norm(vectors, axis=-1, keepdims=True)


@dataclass(frozen=True, eq=False)
class ViewpointCamera:
    """The view from `source` at `fraction` across the dip of sweeps a (columns) and b (rows).

    Pixel-edge coordinates (x, y) (pixel centre at (i + 0.5, j + 0.5)) map to the times
    ``(t_a, t_b) = (x - 0.5, y - 0.5)``.

    Attributes
    ----------
    sweep_a, sweep_b : WireSweep
    source : (3,) float64 ndarray
        The source point the view is from.
    fraction : float
        0 = entry (leading edge), 0.5 = the wire's axis, 1 = exit (trailing edge).
    mask : MaskPlane
    forward : (3,) unit vector into the scene (away from the source).
    width, height : int
    """

    sweep_a: object
    sweep_b: object
    source: np.ndarray
    fraction: float
    mask: object
    forward: np.ndarray
    width: int
    height: int

    def _planes(self, sweep, times):
        """Unit normals of the planes through the source holding the lines at the
        fraction's distance from the wire's axis at `times`."""
        axis = sweep.p0 + times[:, None] * sweep.velocity - self.source
        d = sweep.direction
        across = axis - (axis @ d)[:, None] * d
        dist = np.linalg.norm(across, axis=1)
        e1 = across / dist[:, None]
        e2 = np.cross(d, e1)
        side = np.sign(e2 @ sweep.velocity)
        with np.errstate(invalid="ignore"):
            sine = side * (1.0 - 2.0 * self.fraction) * sweep.radius / dist
            cosine = np.sqrt(1.0 - sine**2)
        line = cosine[:, None] * e1 + sine[:, None] * e2
        return np.cross(d, line)

    def rays(self, x, y):
        """(N, 3) origins (the source) and unit directions into the scene of the rays through
        (N,) pixel-edge coordinates `x`, `y` (column, row); NaN where the two planes are
        parallel or the wire's edge would cover the source itself."""
        x, y = (np.asarray(c, dtype=np.float64).ravel() for c in (x, y))
        if x.shape != y.shape:
            raise ValueError(f"x, y: shapes differ ({x.shape} vs {y.shape})")
        direction = np.cross(self._planes(self.sweep_a, x - 0.5), self._planes(self.sweep_b, y - 0.5))
        sine = np.linalg.norm(direction, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            direction = direction * (np.sign(direction @ self.forward) / sine)[:, None]
        direction[~(sine > DEGENERATE_SINE)] = np.nan
        return np.broadcast_to(self.source, direction.shape).copy(), direction

    def view_dirs(self, points):
        """(N, 3) unit directions from `points` toward the source."""
        return _unit(self.source - np.asarray(points, dtype=np.float64))

    def project(self, points):
        """Pixel-edge (x, y) = (t_a + 0.5, t_b + 0.5) of (N, 3) `points` and their (N,) depth
        along `forward` (NaN times where a wire misses the line to the source)."""
        points = np.asarray(points, dtype=np.float64)
        source = np.broadcast_to(self.source, points.shape)
        times = []
        for sweep in (self.sweep_a, self.sweep_b):
            centre, half = wire_occlusion_interval(points, source, sweep, self.mask)
            times.append(centre + (2.0 * self.fraction - 1.0) * half)
        return np.stack(times, axis=-1) + 0.5, (points - self.source) @ self.forward


def viewpoint_camera(sweeps, names, source, fraction, mask, *, width=None, height=None):
    """The reciprocal camera of one viewpoint (see the module docstring).

    Parameters
    ----------
    sweeps : dict of str to WireSweep
    names : (str, str)
        Sweep a gives the column coordinate, sweep b the row coordinate.
    source : (3,) array_like
        The source point seen (e.g. a light's centre, or its extreme point).
    fraction : float
        Fraction across the dip interval, in [0, 1].
    mask : MaskPlane
    width, height : int, optional
        Image size; default the frame counts of sweeps a and b.

    Returns
    -------
    ViewpointCamera
    """
    names = tuple(names)
    if len(names) != 2 or any(n not in sweeps for n in names) or names[0] == names[1]:
        raise ValueError(f"names: expected two different names of {sorted(sweeps)}, got {names!r}")
    source = np.asarray(source, dtype=np.float64)
    check_array(source, "source", shape=(3,))
    fraction = float(check_in_interval(fraction, "fraction", 0.0, 1.0, closed="both"))
    sweep_a, sweep_b = (sweeps[n] for n in names)
    if np.linalg.norm(np.cross(sweep_a.direction, sweep_b.direction)) <= DEGENERATE_SINE:
        raise ValueError(f"names: the wires of sweeps {names[0]!r} and {names[1]!r} are (nearly) parallel")
    forward = mask.origin - source
    forward = forward / np.linalg.norm(forward)
    width = sweep_a.frames if width is None else int(width)
    height = sweep_b.frames if height is None else int(height)
    return ViewpointCamera(sweep_a=sweep_a, sweep_b=sweep_b, source=source, fraction=fraction,
                           mask=mask, forward=forward, width=width, height=height)
