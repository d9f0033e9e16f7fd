"""A static grid mask under a moving light: the virtual camera array (paper III, Fig. 6).

The mask holds ``n`` horizontal wires (along ``e_u``) and ``m`` vertical wires (along
``e_v``) in the mask plane of a lab scene. The light moves along a line in the plane through
its rest position parallel to the mask: along ``e_u`` for the experiment with the vertical
wires, along ``e_v`` for the one with the horizontal wires (the paper records the two
families separately). Frame k puts the light at ``L(k) = L_c + (k - (T - 1) / 2) step e``.

Geometry (exact). A scene point P is shadowed by the vertical wire j (through ``W_j``,
direction ``e_v``) when the light lies in the plane through the wire and P, i.e. at the
frame ``t = c - (L_c - W_j).N / (step e_u.N)`` with ``N = (P - W_j) x e_v`` and
``c = (T - 1) / 2``. The plane contains ``e_v``, so that frame is the ``e_u`` coordinate of
the point where the ray from P through the crossing ``C_ij`` of wire j with horizontal wire
i meets the light plane: the pair (time of wire j, time of wire i) is the pinhole
projection of P from ``C_ij`` onto the light plane, in frames. Crossing (i, j) is therefore
a virtual pinhole camera (:func:`array_camera`); every camera of one array row shares the
``v`` coordinate of a point and every camera of one array column its ``u`` coordinate
(the array is rectified), and the disparity between columns j, j' is
``(x_j - x_j') (1 + g / d) / step`` for a point at depth d beyond the mask, g the light-mask
distance. Its reciprocal image is the view from ``C_ij`` lit from the primal camera; the
primal image lit by a light placed at ``C_ij`` carries its colours.

Offers
------
GridMask : the static mask (wire offsets, radius) in a scene's mask plane.
make_grid_mask : a grid of n x m wires centred on the mask plane.
light_positions : (T, 3) light positions of one experiment.
static_wire_shadow_time : exact frame at which a static wire shadows each point.
grid_mask_frames : (T, rows, cols, 3) frames of one experiment.
array_camera : the virtual pinhole camera of crossing (i, j).
render_camera_array : a whole array capture with its ground truth, as an xarray Dataset.
"""

from dataclasses import dataclass

import numpy as np
import xarray as xr

from shadowcam._shared.progress import Progress
from shadowcam._shared.validation import check_in, check_positive
from shadowcam.synthetic.lab.raycast import SURFACE_OFFSET, occluded
from shadowcam.synthetic.lab.render import (
    LightPaths, pixel_centre_ground_truth, render_image, render_reciprocal, trace_light_paths,
)
from shadowcam.synthetic.lab.scene import PinholeCamera, PointLight

#: experiment -> (direction of the light's motion, family of wires whose shadows move)
EXPERIMENTS = {"horizontal": "vertical", "vertical": "horizontal"}


@dataclass(frozen=True, eq=False)
class GridMask:
    """Static wires in a scene's mask plane.

    Attributes
    ----------
    mask : MaskPlane
        The plane (origin ``M0``, normal ``n``, axes ``e_u``, ``e_v``, ``delta``, ``focal``).
    rows : (n,) float64
        Offsets of the horizontal wires (direction ``e_u``) from ``M0`` along ``e_v``
        (scene units), top to bottom of the array.
    cols : (m,) float64
        Offsets of the vertical wires (direction ``e_v``) from ``M0`` along ``e_u``.
    radius : float
        Wire radius (scene units).
    """

    mask: object
    rows: np.ndarray
    cols: np.ndarray
    radius: float

    def crossing(self, i, j):
        """(3,) point where horizontal wire `i` crosses vertical wire `j`."""
        m = self.mask
        return m.origin + self.cols[j] * m.e_u + self.rows[i] * m.e_v


def make_grid_mask(mask, *, n_rows=2, n_cols=3, spacing_frames=8.0, radius_frames=0.6):
    """A grid of `n_rows` horizontal and `n_cols` vertical wires centred on the mask plane.

    Parameters
    ----------
    mask : MaskPlane
        A point-light scene's mask plane (``focal`` set).
    n_rows, n_cols : int
        Wires per family (the array has ``n_rows x n_cols`` cameras).
    spacing_frames : float
        Distance between neighbouring wires, in units of the plane's ``delta`` (the light's
        step per frame: the baseline of neighbouring cameras in frames).
    radius_frames : float
        Wire radius in units of ``delta``.

    Returns
    -------
    GridMask
    """
    if mask.focal is None:
        raise ValueError("mask: the virtual camera array needs a near (point) light; got the "
                         "mask plane of a distant light")
    for name, value in (("n_rows", n_rows), ("n_cols", n_cols)):
        if int(value) != value or value < 1:
            raise ValueError(f"{name} must be an integer >= 1; got {value!r}")
    check_positive(spacing_frames, "spacing_frames", finite=True)
    check_positive(radius_frames, "radius_frames", finite=True)
    offsets = lambda k: (np.arange(k) - (k - 1) / 2.0) * spacing_frames * mask.delta  # noqa: E731
    return GridMask(mask=mask, rows=offsets(int(n_rows)), cols=offsets(int(n_cols)),
                    radius=float(radius_frames) * mask.delta)


def _frames_needed(grid, experiment):
    m = grid.mask
    offsets = grid.cols if experiment == "horizontal" else grid.rows
    n = m.n_u if experiment == "horizontal" else m.n_v
    return int(n + np.ceil((offsets.max() - offsets.min()) / m.delta))


def light_positions(light, grid, experiment, *, frames=None):
    """Light positions of one experiment.

    Parameters
    ----------
    light : PointLight
        The light at rest (its position is the centre of the motion).
    grid : GridMask
    experiment : {"horizontal", "vertical"}
        Direction of the light's motion (``e_u`` or ``e_v``).
    frames : int, optional
        Frames T (default: the mask plane's dual size plus the wires' spread, so that every
        wire's shadow crosses the whole field).

    Returns
    -------
    (T, 3) float64 ndarray
        ``L(k) = L_c + (k - (T - 1) / 2) delta e``.
    """
    check_in(experiment, "experiment", tuple(EXPERIMENTS))
    frames = _frames_needed(grid, experiment) if frames is None else int(frames)
    e = grid.mask.e_u if experiment == "horizontal" else grid.mask.e_v
    k = np.arange(frames) - (frames - 1) / 2.0
    return light.center + (k * grid.mask.delta)[:, None] * e


def _wires(grid, family):
    """(points (W, 3), direction (3,)) of one family of wires."""
    m = grid.mask
    if family == "vertical":
        return m.origin + grid.cols[:, None] * m.e_u, m.e_v
    return m.origin + grid.rows[:, None] * m.e_v, m.e_u


def static_wire_shadow_time(points, wire_point, wire_direction, positions):
    """Exact (fractional) frame at which a static wire shadows each point.

    Parameters
    ----------
    points : (N, 3) array_like
        Scene points P.
    wire_point, wire_direction : (3,) array_like
        A point of the wire's centre line and its direction.
    positions : (T, 3) array_like
        Light positions of the experiment (a uniform motion along a line).

    Returns
    -------
    (N,) float64 ndarray
        Frame t with ``L(t)`` in the plane through the wire and P (NaN where that plane
        is parallel to the motion).
    """
    points = np.asarray(points, dtype=np.float64)
    positions = np.asarray(positions, dtype=np.float64)
    step = positions[1] - positions[0]
    normal = np.cross(points - np.asarray(wire_point, dtype=np.float64),
                      np.asarray(wire_direction, dtype=np.float64))
    with np.errstate(divide="ignore", invalid="ignore"):
        return -((positions[0] - wire_point) @ normal.T) / (normal @ step)


def _blocked(points, light_point, wire_points, direction, radius):
    """(n,) bool: the segment point -> light passes within `radius` of any wire line."""
    seg = light_point - points
    w = np.cross(seg, direction)
    w /= np.linalg.norm(w, axis=1, keepdims=True)
    distance = np.abs(np.einsum("nwk,nk->nw", points[:, None, :] - wire_points[None], w))
    return (distance < radius).any(axis=1)


def grid_mask_frames(objects, camera, grid, positions, family, *, supersample=3, on_frame=None):
    """Frames of one experiment: the light at each position, the family's wires in place.

    Parameters
    ----------
    objects : sequence of scene objects
    camera : PinholeCamera or OrthographicCamera
    grid : GridMask
    positions : (T, 3) ndarray
        Light positions (:func:`light_positions`).
    family : {"vertical", "horizontal"}
        The wires present in this experiment.
    supersample : int
        Sub-samples per pixel side; the wires' partial cover of a pixel gives smooth dips.
    on_frame : callable, optional
        Called with no argument after each frame (progress reporting).

    Returns
    -------
    (T, rows, cols, 3) float32 ndarray
        Linear radiance (direct light, scene shadows, wire shadows).
    """
    check_in(family, "family", ("vertical", "horizontal"))
    wire_points, direction = _wires(grid, family)
    frames = []
    for position in positions:
        paths = trace_light_paths(objects, camera, PointLight(position), supersample=supersample)
        keep = ~_blocked(paths.points, position, wire_points, direction, grid.radius)
        frames.append(render_image(LightPaths(
            shape=paths.shape, pixel=paths.pixel[keep], points=paths.points[keep],
            light=paths.light[keep], radiance=paths.radiance[keep], distant=False)))
        if on_frame is not None:
            on_frame()
    return np.stack(frames)


def array_camera(grid, i, j, *, frames_u, frames_v):
    """The virtual pinhole camera of crossing (`i`, `j`).

    Its pixel (row v, col u) centre is the frame pair (time of horizontal wire i in the
    vertical experiment, time of vertical wire j in the horizontal experiment).

    Parameters
    ----------
    grid : GridMask
    i, j : int
        Horizontal and vertical wire.
    frames_u, frames_v : int
        Frames of the horizontal and of the vertical experiment (the image size).

    Returns
    -------
    PinholeCamera
        At the crossing, looking along the mask normal, ``R`` rows ``(-e_u, -e_v, n)``
        (the light plane lies behind the centre), focal ``g / delta``.
    """
    m = grid.mask
    k = m.focal / m.delta
    c_u = (frames_u - 1) / 2.0 + grid.cols[j] / m.delta
    c_v = (frames_v - 1) / 2.0 + grid.rows[i] / m.delta
    K = np.array([[k, 0.0, c_u + 0.5], [0.0, k, c_v + 0.5], [0.0, 0.0, 1.0]])
    return PinholeCamera(K=K, R=np.stack([-m.e_u, -m.e_v, m.normal]), center=grid.crossing(i, j),
                         width=int(frames_u), height=int(frames_v))


def render_camera_array(scene, *, n_rows=2, n_cols=3, spacing_frames=8.0, radius_frames=0.6,
                        supersample=3):
    """A virtual-camera-array capture of a point-light lab scene, with exact ground truth.

    Parameters
    ----------
    scene : Scene
        A point-light lab scene (:func:`shadowcam.synthetic.lab.scenes.make_scene`); its
        mask plane holds the grid and its light's position is the centre of the motion.
    n_rows, n_cols, spacing_frames, radius_frames
        The grid (:func:`make_grid_mask`).
    supersample : int

    Returns
    -------
    xarray.Dataset
        ``frames_horizontal`` (t_u, y, x, channel) and ``frames_vertical`` (t_v, y, x,
        channel): the two experiments; ``crossing_images`` (camera_row, camera_col, y, x,
        channel): the primal image lit from each crossing; ground truth ``t_vertical_wire``
        (camera_col, y, x) and ``t_horizontal_wire`` (camera_row, y, x): exact frames of each
        wire's shadow at the pixel centres (NaN where the point is not lit or the time falls
        outside the experiment); ``reciprocal`` (camera_row, camera_col, v, u, channel): the
        view of each virtual camera lit from the primal camera.
    """
    light = scene.light
    if not isinstance(light, PointLight):
        raise ValueError(f"scene.light: the virtual camera array needs a point light; got "
                         f"{type(light).__name__}")
    grid = make_grid_mask(scene.mask, n_rows=n_rows, n_cols=n_cols,
                          spacing_frames=spacing_frames, radius_frames=radius_frames)
    pos_u = light_positions(light, grid, "horizontal")
    pos_v = light_positions(light, grid, "vertical")
    cams = [(i, j) for i in range(n_rows) for j in range(n_cols)]
    progress = Progress(len(pos_u) + len(pos_v) + 2 * len(cams), "camera array render",
                        unit="images")
    done = [0]

    def one_done():
        done[0] += 1
        progress.update(done[0])

    frames_u = grid_mask_frames(scene.objects, scene.camera, grid, pos_u, "vertical",
                                supersample=supersample, on_frame=one_done)
    frames_v = grid_mask_frames(scene.objects, scene.camera, grid, pos_v, "horizontal",
                                supersample=supersample, on_frame=one_done)
    rows, cols = scene.camera.height, scene.camera.width
    crossing = np.zeros((n_rows, n_cols, rows, cols, 3), np.float32)
    reciprocal = np.zeros((n_rows, n_cols, len(pos_v), len(pos_u), 3), np.float32)
    for i, j in cams:
        at = PointLight(grid.crossing(i, j), light.intensity)
        paths = trace_light_paths(scene.objects, scene.camera, at, supersample=supersample)
        crossing[i, j] = render_image(paths)
        one_done()
        cam = array_camera(grid, i, j, frames_u=len(pos_u), frames_v=len(pos_v))
        reciprocal[i, j] = render_reciprocal(scene.objects, scene.camera, at, None,
                                             supersample=supersample, dual=cam)["reciprocal"]
        one_done()
    truth_u, truth_v = _wire_times(scene, grid, pos_u, pos_v)
    dims = ("y", "x")
    return xr.Dataset(
        {"frames_horizontal": (("t_u", *dims, "channel"), frames_u),
         "frames_vertical": (("t_v", *dims, "channel"), frames_v),
         "crossing_images": (("camera_row", "camera_col", *dims, "channel"), crossing),
         "t_vertical_wire": (("camera_col", *dims), truth_u),
         "t_horizontal_wire": (("camera_row", *dims), truth_v),
         "reciprocal": (("camera_row", "camera_col", "v", "u", "channel"), reciprocal)},
        coords={"channel": ["R", "G", "B"], "camera_row": np.arange(n_rows),
                "camera_col": np.arange(n_cols)},
        attrs={"wire_rows_offset": grid.rows.tolist(), "wire_cols_offset": grid.cols.tolist(),
               "wire_radius": grid.radius, "delta": scene.mask.delta,
               "light_mask_distance": scene.mask.focal,
               "definitions": "t_*_wire: frame at which the wire's centre line shadows the "
                              "pixel-centre point (static_wire_shadow_time); reciprocal: view "
                              "of array_camera(i, j) lit from the primal camera"})


def _wire_times(scene, grid, pos_u, pos_v):
    """Exact wire times at the pixel-centre points; NaN where the point does not face the
    camera and the light at that time, the light is hidden by the scene, or the time falls
    outside the experiment."""
    centre = pixel_centre_ground_truth(scene.objects, scene.camera, scene.light, scene.mask, {},
                                       optics=scene.optics)
    shape = centre["hit"].shape
    points, normals = centre["P"].reshape(-1, 3), centre["N"].reshape(-1, 3)
    hit = centre["hit"].ravel() & (centre["cos_C"].ravel() > 0)
    out = []
    for family, positions in (("vertical", pos_u), ("horizontal", pos_v)):
        wire_points, direction = _wires(grid, family)
        per_wire = []
        for w in wire_points:
            t = static_wire_shadow_time(np.nan_to_num(points), w, direction, positions)
            ok = hit & (t >= 0) & (t <= len(positions) - 1)
            lights = positions[0] + np.where(ok, t, 0.0)[:, None] * (positions[1] - positions[0])
            ok &= _lit_by(scene.objects, points, normals, lights, ok)
            per_wire.append(np.where(ok, t, np.nan).reshape(shape))
        out.append(np.stack(per_wire))
    return out


def _lit_by(objects, points, normals, lights, candidates):
    """(N,) bool: each candidate point faces its own light position and sees it."""
    rel = lights - points
    dist = np.linalg.norm(rel, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        to_light = rel / dist[:, None]
        faces = candidates & ((normals * to_light).sum(axis=1) > 0)
    idx = np.flatnonzero(faces)
    lit = faces.copy()
    lit[idx[occluded(objects, points[idx] + SURFACE_OFFSET * normals[idx], to_light[idx],
                     dist[idx])]] = False
    return lit
