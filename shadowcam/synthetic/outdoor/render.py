"""Synthetic outdoor sunset time-lapse: scene, static geometry, sun visibility, frame radiance.

A camera on the lower flank of a ridge looks across a valley at a cliff while the sun sets
behind the ridge; the ridge's shadow climbs the cliff (shared data README section 2 gives
the conventions: world x east, y north, z up, metres; OpenCV camera; pixel (row v, col u)
centre at image point (u + 0.5, v + 0.5)).

Sun visibility (the one test used by the frames and the ground truth)::

    lit(p, t) = n(p) . l(t) > 0  and  elevation(t) > H(p, azimuth(t))

with ``H`` the terrain horizon of :func:`shadowcam.synthetic.outdoor.terrain.horizon_angles` tabulated at
azimuth nodes ``HORIZON_FINE_DEG`` apart over the sun's path (probed where the sun crosses
it, see :func:`trace_samples`) and linearly interpolated in azimuth. A disc sun (the real one, 0.53 deg across, uniform
disc: no limb darkening) is partly hidden where its centre is within its radius of the
horizon's tangent line: the lit indicator becomes the visible disc fraction
(:func:`sun_lit_fraction`), the penumbra, whose centre is the point sun's edge. Radiance of a terrain sample (Lambertian, sun irradiance pi so a white surface
facing the sun has radiance 1)::

    L = albedo (lit cloud max(n.l, 0) sun_rgb(t) + (1 + n_z) / 2 sky_rgb(t))

and of a sky sample ``skydome(t, view direction)``; a pixel is the mean of its
``supersample x supersample`` samples (stratum centres).

Offers
------
OutdoorScene : terrain, camera and sun path of a capture.
make_outdoor_scene : the seeded ``ridge`` scene (camera placed as in dev_ridge).
OUTDOOR_SCENES : scene name -> factory.
window_camera : the camera of a window (strip, crop) of a camera's pixels.
SampleGeometry : per-sample terrain hits, normals, albedo, view directions, horizons.
trace_samples : intersect view rays through image points and compute their horizons.
sample_grid : image points of the supersample grid (pixel-major) or of pixel centres.
horizon_clearance : angle of the sun's centre above the local horizon line of samples.
sun_lit : lit(p, t) of samples (point sun, or the penumbra's centre/start/end of a disc sun).
disc_fraction_above : fraction of a uniform disc above a line at a signed distance.
sun_lit_fraction : visible fraction of the 0.53 deg sun disc (the penumbra).
sky_colour : colour of the uniform sky light at sun elevations (fades and warms).
frame_radiance : noise-free linear radiance of one frame, (rows, cols, 3), with and
    without a cloud shadow.
"""

from dataclasses import dataclass

import numpy as np

from shadowcam._shared.validation import check_in, check_in_interval
from shadowcam.synthetic.lab.scene import PinholeCamera, camera_rays, look_at_camera
from shadowcam.synthetic.outdoor.sun import SunPath, sun_colour
from shadowcam.synthetic.outdoor.terrain import horizon_angles, intersect_heightfield, make_ridge_terrain

#: azimuth spacing (deg) of the coarse and the fine horizon table
HORIZON_NODE_DEG = 2.0
HORIZON_FINE_DEG = 0.25
#: fine nodes are probed where the coarse horizon is within this of the sun's elevation (deg)
HORIZON_REFINE_MARGIN_DEG = 0.75
#: apparent angular diameter of the sun (deg)
SUN_DIAMETER_DEG = 0.53
#: sky light (uniform dome) colour at the start elevation, linear RGB
SKY_RGB_START = (0.12, 0.1425, 0.1875)
#: exponents of the sky dimming factor per channel (red fades least: the sky warms)
SKY_WARMING = (0.7, 0.85, 1.0)


@dataclass(frozen=True, eq=False)
class OutdoorScene:
    """Terrain, camera and sun of an outdoor capture.

    Attributes
    ----------
    terrain : shadowcam.synthetic.outdoor.terrain.Heightfield
    camera : shadowcam.synthetic.lab.scene.PinholeCamera
        OpenCV convention, ``X_cv = R (X - center)``.
    sun : shadowcam.synthetic.outdoor.sun.SunPath
    duration_s : float
        Time from the first to the last frame (sun from start to end elevation).
    start_elevation_deg, end_elevation_deg : float
    """

    terrain: object
    camera: object
    sun: SunPath
    duration_s: float
    start_elevation_deg: float
    end_elevation_deg: float


def make_outdoor_scene(name="ridge", *, seed=0, height=128, width=192, latitude_deg=35.0,
                       declination_deg=-18.0, start_elevation_deg=20.0, end_elevation_deg=1.5,
                       hfov_deg=50.0, window=None):
    """Build an outdoor scene by name.

    Parameters
    ----------
    name : str
        A key of :data:`OUTDOOR_SCENES` (``ridge``).
    seed : int, keyword-only
        Terrain detail/albedo seed.
    height, width : int, keyword-only
        Image rows, cols.
    latitude_deg, declination_deg : float, keyword-only
        Ephemeris of the day.
    start_elevation_deg, end_elevation_deg : float, keyword-only
        Sun elevation at the first and the last frame (setting: start > end).
    hfov_deg : float, keyword-only
        Horizontal field of view.
    window : (4,) sequence of int or None, keyword-only
        ``(row0, col0, rows, cols)``: the scene's camera sees only these pixels of the
        `height` x `width` camera (its principal point moved by ``(col0, row0)``), so that
        a strip or crop of a real-size frame renders at its true resolution. None: the
        whole frame.

    Returns
    -------
    OutdoorScene
    """
    check_in(name, "name", OUTDOOR_SCENES)
    if int(height) < 8 or int(width) < 8:
        raise ValueError(f"height, width: need at least 8 pixels, got {height}x{width}")
    if not 0.5 <= end_elevation_deg < start_elevation_deg <= 40.0:
        raise ValueError("start_elevation_deg, end_elevation_deg: need 0.5 <= end < start <= 40 "
                         f"(a setting sun), got {start_elevation_deg}, {end_elevation_deg}")
    terrain = make_ridge_terrain(seed=seed)
    # camera on the ridge's lower flank, 25 m above ground, looking at the cliff (dev_ridge)
    cx, cy = terrain.to_xy(-1000.0, 600.0)
    cz = float(terrain.height(cx, cy)) + 25.0
    tx, ty = terrain.to_xy(100.0, -150.0)
    camera = look_at_camera((cx, cy, cz), (tx, ty, 720.0), fov_x_deg=hfov_deg,
                            width=int(width), height=int(height), up=(0.0, 0.0, 1.0))
    if window is not None:
        camera = window_camera(camera, window)
    sun = SunPath.from_start_elevation(start_elevation_deg, latitude_deg=latitude_deg,
                                       declination_deg=declination_deg)
    return OutdoorScene(terrain=terrain, camera=camera, sun=sun,
                        duration_s=float(sun.time_at_elevation(end_elevation_deg)),
                        start_elevation_deg=float(start_elevation_deg),
                        end_elevation_deg=float(end_elevation_deg))


OUTDOOR_SCENES = {"ridge": make_outdoor_scene}


def window_camera(camera, window):
    """The pinhole camera that sees only a window of `camera`'s pixels.

    Parameters
    ----------
    camera : shadowcam.synthetic.lab.scene.PinholeCamera
    window : (4,) sequence of int
        ``(row0, col0, rows, cols)`` inside ``camera.height`` x ``camera.width``.

    Returns
    -------
    PinholeCamera
        ``rows`` x ``cols``, principal point moved by ``(-col0, -row0)``: its pixel
        ``(r, c)`` is `camera`'s pixel ``(row0 + r, col0 + c)``.
    """
    try:
        row0, col0, rows, cols = (int(v) for v in window)
    except (TypeError, ValueError):
        raise ValueError(f"window: expected (row0, col0, rows, cols); got {window!r}") from None
    if (row0 < 0 or col0 < 0 or rows < 8 or cols < 8 or row0 + rows > camera.height
            or col0 + cols > camera.width):
        raise ValueError(f"window {list(window)}: must lie inside the {camera.width}x{camera.height} "
                         "frame (row0, col0 >= 0, rows, cols >= 8)")
    K = camera.K.copy()
    K[0, 2] -= col0
    K[1, 2] -= row0
    return PinholeCamera(K=K, R=camera.R, center=camera.center, width=cols, height=rows)


def sample_grid(rows, cols, supersample=None):
    """Image points (pixel-edge x = col, y = row) of the sample grid.

    Parameters
    ----------
    rows, cols : int
    supersample : int or None
        ``s``: an s x s grid of stratum centres per pixel, ordered pixel-major
        (pixel (r, c) owns samples ``(r * cols + c) * s**2 ...``, sub-row-major); None:
        the pixel centres.

    Returns
    -------
    x, y : (rows * cols * s**2,) ndarray
    """
    s = 1 if supersample is None else int(supersample)
    if s < 1:
        raise ValueError(f"supersample must be >= 1; got {supersample}")
    offsets = (np.arange(s) + 0.5) / s
    r, c, oy, ox = np.meshgrid(np.arange(rows), np.arange(cols), offsets, offsets,
                               indexing="ij")
    return (c + ox).ravel(), (r + oy).ravel()


@dataclass(frozen=True, eq=False)
class SampleGeometry:
    """Static geometry of image samples.

    Attributes
    ----------
    sky : (N,) bool
        The view ray misses the terrain.
    position, normal, albedo : (N, 3) ndarray
        Terrain point (NaN for sky samples), unit shading normal and linear albedo (0 for
        sky samples).
    ambient : (N, 3) ndarray
        Sky-light factor ``albedo (1 + n_z) / 2`` (radiance under a unit uniform sky).
    view_dir : (N, 3) ndarray
        Unit view-ray directions (world).
    depth_z : (N,) ndarray
        Camera z of the terrain point (NaN sky).
    horizon : (N, A) float32 ndarray
        Horizon elevation (rad) at the azimuth nodes (``-inf`` for sky samples).
    node_azimuth : (A,) ndarray
        Azimuth nodes (rad, in the branch of the sun path's azimuths).
    """

    sky: np.ndarray
    position: np.ndarray
    normal: np.ndarray
    albedo: np.ndarray
    ambient: np.ndarray
    view_dir: np.ndarray
    depth_z: np.ndarray
    horizon: np.ndarray
    node_azimuth: np.ndarray


def _azimuth_nodes(scene, node_deg):
    _, az = scene.sun.elevation_azimuth(np.linspace(0.0, scene.duration_s, 64))
    az = np.unwrap(az)
    lo, hi = az.min(), az.max()
    step = np.radians(node_deg)
    n = int(np.ceil((hi - lo) / step)) + 1
    start = 0.5 * (lo + hi) - 0.5 * (n - 1) * step
    return start + step * np.arange(n + 2) - step  # one spare node each side


def _sun_elevation_at_azimuth(scene, azimuths):
    """Elevation (rad) of the sun when it stands at `azimuths` (rad, node branch; clamped to
    the sequence)."""
    t = np.linspace(0.0, scene.duration_s, 2048)
    e, a = scene.sun.elevation_azimuth(t)
    a = np.unwrap(a)
    a = a + (2 * np.pi) * np.round((azimuths[0] - a[0]) / (2 * np.pi))
    return np.interp(azimuths, a, e)


def trace_samples(scene, x, y, *, node_deg=HORIZON_NODE_DEG, fine_deg=HORIZON_FINE_DEG,
                  margin_deg=HORIZON_REFINE_MARGIN_DEG):
    """Intersect the view rays through image points with the terrain; horizons of the hits.

    The horizon table has nodes every `fine_deg` over the sun's azimuth range. It is probed
    (:func:`shadowcam.synthetic.outdoor.terrain.horizon_angles`) every `node_deg`, interpolated linearly onto
    the fine nodes, and probed again at the fine nodes where the interpolated horizon is
    within `margin_deg` of the sun's elevation at that azimuth (where the sun crosses it).

    Parameters
    ----------
    scene : OutdoorScene
    x, y : (N,) ndarray
        Pixel-edge image coordinates (col, row).
    node_deg, fine_deg, margin_deg : float, keyword-only

    Returns
    -------
    SampleGeometry
    """
    if not 0 < fine_deg <= node_deg:
        raise ValueError(f"fine_deg must be in (0, node_deg]; got {fine_deg}")
    origins, dirs = camera_rays(scene.camera, x, y)
    dist = intersect_heightfield(scene.terrain, origins, dirs)
    sky = np.isnan(dist)
    pos = origins + dist[:, None] * dirs
    hit = ~sky
    normal = np.zeros_like(pos)
    albedo = np.zeros_like(pos)
    normal[hit] = scene.terrain.normal(pos[hit, 0], pos[hit, 1])
    albedo[hit] = scene.terrain.albedo_at(pos[hit, 0], pos[hit, 1])
    depth = (pos - scene.camera.center) @ scene.camera.R[2]
    coarse = _azimuth_nodes(scene, node_deg)
    ratio = int(round(node_deg / fine_deg))
    fine = coarse[0] + np.radians(node_deg / ratio) * np.arange((len(coarse) - 1) * ratio + 1)
    clip = dict(min_elevation_rad=np.radians(scene.end_elevation_deg - 0.5),
                max_elevation_rad=np.radians(scene.start_elevation_deg + 0.5))
    points = pos[hit]
    h_coarse = horizon_angles(scene.terrain, points, coarse, **clip)
    # linear interpolation onto the fine nodes (every ratio-th fine node is a coarse node)
    j = np.arange(len(fine)) / ratio
    j0 = np.minimum(j.astype(np.intp), len(coarse) - 2)
    f = (j - j0).astype(np.float32)
    h_fine = (h_coarse[:, j0] * (1 - f) + h_coarse[:, j0 + 1] * f).astype(np.float32)
    near = np.abs(h_fine - _sun_elevation_at_azimuth(scene, fine)) < np.radians(margin_deg)
    near[:, ::ratio] = False  # coarse nodes are probed already
    rows, cols = np.nonzero(near)
    h_fine[rows, cols] = horizon_angles(scene.terrain, points[rows], fine[cols],
                                        pairwise=True, **clip)
    horizon = np.full((len(x), len(fine)), -np.inf, dtype=np.float32)
    horizon[hit] = h_fine
    ambient = albedo * (0.5 * (1.0 + normal[:, 2]))[:, None]
    return SampleGeometry(sky=sky, position=pos, normal=normal, albedo=albedo, ambient=ambient,
                          view_dir=dirs, depth_z=depth, horizon=horizon, node_azimuth=fine)


def horizon_clearance(geometry, sun, t_s):
    """Angle of the sun's centre above the local terrain horizon, and whether the surface faces it.

    The horizon near the sun is its tangent line in the sky: with ``H(a)`` the tabulated
    horizon (piecewise linear in azimuth ``a``) and ``m = H'(a) / cos(e)`` its slope in
    angle units on the sky at sun elevation ``e``, the perpendicular angular distance of the
    sun's centre from the line is ``(e - H(a)) / sqrt(1 + m**2)`` (positive above it).

    Parameters
    ----------
    geometry : SampleGeometry
    sun : shadowcam.synthetic.outdoor.sun.SunPath
    t_s : float or (N,) ndarray
        One time for all samples, or one time per sample (seconds since frame 0).

    Returns
    -------
    clearance : (N,) ndarray
        Radians (NaN for sky samples).
    facing : (N,) bool ndarray
        ``n . l > 0`` toward the sun's centre (False for sky samples).
    """
    t = np.asarray(t_s, dtype=np.float64)
    n = len(geometry.sky)
    if t.ndim not in (0, 1) or (t.ndim == 1 and t.shape != (n,)):
        raise ValueError(f"t_s: expected a scalar or ({n},) times, got shape {t.shape}")
    elevation, azimuth = sun.elevation_azimuth(t)
    nodes = geometry.node_azimuth
    step = nodes[1] - nodes[0]
    azimuth = nodes[0] + np.mod(azimuth - nodes[0] + np.pi, 2 * np.pi) - np.pi
    j = np.clip((azimuth - nodes[0]) / step, 0.0, len(nodes) - 1.000001)
    j0 = j.astype(np.intp)
    f = j - j0
    rows = slice(None) if t.ndim == 0 else np.arange(n)
    h0, h1 = geometry.horizon[rows, j0], geometry.horizon[rows, j0 + 1]
    if t.ndim == 0:
        facing = geometry.normal @ sun.direction(t) > 0
    else:
        facing = np.einsum("ij,ij->i", geometry.normal, sun.direction(t)) > 0
    with np.errstate(invalid="ignore"):
        slope = (h1 - h0) / step / np.cos(elevation)
        clearance = (elevation - (h0 * (1.0 - f) + h1 * f)) / np.sqrt(1.0 + slope * slope)
    return clearance, facing


def sun_lit(geometry, sun, t_s, *, offset_rad=0.0):
    """Sun visibility of samples: the sun's centre is above the horizon (a point sun).

    Parameters
    ----------
    geometry, sun, t_s
        As :func:`horizon_clearance`.
    offset_rad : float, keyword-only
        Lit iff the clearance (:func:`horizon_clearance`) exceeds this: 0 is the centre of
        a disc sun's penumbra, ``+radius`` its start (first loss of light), ``-radius`` its
        end (the whole disc hidden).

    Returns
    -------
    (N,) bool ndarray
        False for sky samples (their normal is 0).
    """
    clearance, facing = horizon_clearance(geometry, sun, t_s)
    with np.errstate(invalid="ignore"):
        return facing & (clearance > offset_rad)


def disc_fraction_above(distance):
    """Fraction of a uniform disc on the positive side of a line.

    Parameters
    ----------
    distance : float or ndarray
        Signed distance of the disc's centre from the line, in disc radii.

    Returns
    -------
    ndarray
        ``1/2 + (d sqrt(1 - d**2) + arcsin d) / pi`` with ``d`` clipped to [-1, 1]: 0 at
        ``d <= -1``, 1/2 at 0, 1 at ``d >= 1``.
    """
    d = np.clip(np.asarray(distance, dtype=np.float64), -1.0, 1.0)
    return 0.5 + (d * np.sqrt(1.0 - d * d) + np.arcsin(d)) / np.pi


def sun_lit_fraction(geometry, sun, t_s, *, diameter_deg=SUN_DIAMETER_DEG):
    """Visible fraction of a uniform sun disc (no limb darkening) above the terrain horizon.

    The fraction of the disc of angular radius ``r`` above the horizon's tangent line at
    clearance ``c`` (:func:`horizon_clearance`) is :func:`disc_fraction_above` ``(c / r)``;
    a surface turned away from the sun's centre gets 0 (the attached shadow keeps the
    centre's ``n . l``). ``diameter_deg = 0`` is the point sun of :func:`sun_lit`.

    Returns
    -------
    (N,) ndarray
        In [0, 1]; 0 for sky samples.
    """
    check_in_interval(diameter_deg, "diameter_deg", 0.0, 1.0, closed="both")
    if diameter_deg == 0:
        return sun_lit(geometry, sun, t_s).astype(np.float64)
    clearance, facing = horizon_clearance(geometry, sun, t_s)
    radius = np.radians(0.5 * diameter_deg)
    return np.where(facing, disc_fraction_above(np.nan_to_num(clearance / radius, nan=-1.0)), 0.0)


def sky_colour(elevation_deg, *, start_elevation_deg):
    """Colour of the uniform sky light, dimming and warming as the sun sets.

    ``sky_rgb = SKY_RGB_START * f**SKY_WARMING`` with
    ``f = 0.35 + 0.65 sin(e) / sin(e_start)``.

    Returns
    -------
    (..., 3) ndarray
    """
    e = np.asarray(elevation_deg, dtype=np.float64)
    f = 0.35 + 0.65 * np.sin(np.radians(e)) / np.sin(np.radians(start_elevation_deg))
    return np.asarray(SKY_RGB_START) * np.power.outer(f, np.asarray(SKY_WARMING))


def _skydome(view_dir, sun_dir, sky_rgb, sun_rgb):
    """Radiance of sky samples: brighter toward the horizon, a glow around the sun."""
    elevation = np.clip(view_dir[:, 2], 0.0, 1.0)
    gradient = (1.6 - 0.8 * elevation)[:, None] * sky_rgb
    cos_sun = np.clip(view_dir @ sun_dir, -1.0, 1.0)
    glow = (0.4 * np.exp(-np.arccos(cos_sun) / 0.3))[:, None] * sun_rgb
    return gradient + glow


def frame_radiance(geometry, scene, t_s, *, shape, supersample, lit=None, cloud=None):
    """Noise-free linear radiance of one frame, with and without the cloud shadow.

    Parameters
    ----------
    geometry : SampleGeometry
        Of the supersample grid (:func:`sample_grid`).
    scene : OutdoorScene
    t_s : float
        Frame time (s since frame 0).
    shape : (rows, cols), keyword-only
    supersample : int, keyword-only
    lit : (N,) bool or float ndarray, optional
        Sun visibility of the samples at `t_s` (default: :func:`sun_lit`), or the visible
        fraction of a disc sun (:func:`sun_lit_fraction`).
    cloud : (N,) ndarray, optional
        Cloud transmittance of the sun term per sample (default: no cloud).

    Returns
    -------
    radiance : (rows, cols, 3) float32 ndarray
        With the cloud shadow.
    clear : (rows, cols, 3) float32 ndarray
        Without it (the same array when `cloud` is None).
    """
    rows, cols = shape
    s2 = int(supersample) ** 2
    if len(geometry.sky) != rows * cols * s2:
        raise ValueError(f"geometry: expected {rows * cols * s2} samples for shape {shape} and "
                         f"supersample {supersample}, got {len(geometry.sky)}")
    sun_dir = scene.sun.direction(t_s)
    elevation = np.degrees(np.arcsin(sun_dir[2]))
    sun_rgb = sun_colour(elevation, reference_elevation_deg=scene.start_elevation_deg)
    sky_rgb = sky_colour(elevation, start_elevation_deg=scene.start_elevation_deg)
    if lit is None:
        lit = sun_lit(geometry, scene.sun, t_s)
    cos_sun = np.maximum(geometry.normal @ sun_dir, 0.0) * lit
    base = geometry.ambient * sky_rgb
    sky = geometry.sky
    base[sky] = _skydome(geometry.view_dir[sky], sun_dir, sky_rgb, sun_rgb)
    sun_term = geometry.albedo * sun_rgb
    clear = base + sun_term * cos_sun[:, None]
    clear_img = clear.reshape(rows, cols, s2, 3).mean(axis=2).astype(np.float32)
    if cloud is None:
        return clear_img, clear_img
    cloudy = base + sun_term * (cos_sun * cloud)[:, None]
    return cloudy.reshape(rows, cols, s2, 3).mean(axis=2).astype(np.float32), clear_img
