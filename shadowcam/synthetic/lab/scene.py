"""Scene description for synthetic lab captures: geometry, materials, lights, cameras, wire sweeps.

Conventions are those of the shared development data (``/work/shared/data/README.md`` 1.3):
right-handed world, +y up; camera ``X_cam = R (X_world - centre)`` with camera axes x right,
y down, z forward; pinhole projection in *pixel-edge* coordinates, so pixel (row r, col c)
has its centre at ``(x, y) = (c + 0.5, r + 0.5)``.

Offers
------
Texture, Material : procedural albedo (checker, discs, bricks, coloured squares) and a
    Blinn-Phong specular term.
Sphere, Box, GroundPlane, BackPlane : scene objects (box yawed about +y; ground infinite;
    the finite back plane carries 2-D plane coordinates (x, y) and is the calibration plane).
PointLight, DistantLight, AreaLight : lights; ``light_samples`` gives their stratified samples,
    ``light_plane_axes`` an area light's in-plane axes.
PinholeCamera, OrthographicCamera : cameras; ``look_at_camera`` builds a pinhole.
camera_rays, project : pixel-edge coordinates <-> world rays / points.
MaskPlane, WireSweep : the mask plane and the wire sweeps u, v (README 1.3); a sweep may
    carry its own light (general sweeps: ``shadowcam.synthetic.lab.sweeps``).
make_mask_plane, make_wire_sweeps, dual_camera : build them from a light and an aim point.
wire_shadow_time : analytic time at which a sweep's wire centre line shadows points.
(Whole scenes and presets: :mod:`shadowcam.synthetic.lab.scenes`.)
texture_albedo : evaluate a texture at 2-D texture coordinates.
yaw_matrix : rotation about +y (local -> world).
"""

import math
from dataclasses import dataclass, field

import numpy as np

from shadowcam._shared.validation import check_array, check_in, check_in_interval, check_positive

UP = (0.0, 1.0, 0.0)


def _vec(value, name, size=3):
    arr = np.asarray(value, dtype=np.float64)
    if arr.shape != (size,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: expected {size} finite numbers, got {value!r}")
    return arr


def _unit(value, name):
    arr = _vec(value, name)
    norm = np.linalg.norm(arr)
    if norm == 0:
        raise ValueError(f"{name}: must not be the zero vector")
    return arr / norm


def _set(obj, **values):
    for key, value in values.items():
        object.__setattr__(obj, key, value)


def yaw_matrix(yaw_deg):
    """Return the (3, 3) rotation about +y by `yaw_deg` degrees (local -> world)."""
    a = math.radians(yaw_deg)
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


# --------------------------------------------------------------------------- materials

TEXTURE_KINDS = ("checker", "discs", "bricks", "squares")
#: side of a square of the ``squares`` texture, as a fraction of the cell size `scale`
SQUARE_FILL = 0.6


@dataclass(frozen=True, eq=False)
class Texture:
    """Procedural albedo on 2-D texture coordinates (scene units).

    Parameters
    ----------
    kind : {"checker", "discs", "bricks", "squares"}
    colors : (K, 3) array_like
        Linear albedos: checker uses 2, discs uses background + K-1 disc colours,
        bricks uses brick colour(s) then mortar as the last entry, squares uses background
        + K-1 square colours.
    scale : float
        Checker square / disc spacing / brick height / squares cell size, in scene units.
        A square of side ``SQUARE_FILL scale`` sits centred in every cell
        ``[i scale, (i + 1) scale) x [j scale, (j + 1) scale)``, so its edges are straight
        lines of texture coordinates.
    seed : int
        Seeds disc placement, per-brick colour variation and square colours.
    """

    kind: str
    colors: np.ndarray
    scale: float
    seed: int = 0

    def __post_init__(self):
        check_in(self.kind, "kind", TEXTURE_KINDS)
        colors = np.asarray(self.colors, dtype=np.float64)
        if colors.ndim != 2 or colors.shape[1] != 3 or colors.shape[0] < 2:
            raise ValueError(f"colors must be (K>=2, 3) albedos; got shape {colors.shape}")
        _set(self, colors=colors, scale=float(check_positive(self.scale, "scale", finite=True)))


def texture_albedo(texture, coords):
    """Evaluate `texture` at texture coordinates.

    Parameters
    ----------
    texture : Texture
    coords : (N, 2) ndarray
        Texture coordinates in scene units.

    Returns
    -------
    (N, 3) float64 ndarray
        Linear albedo.
    """
    coords = np.asarray(coords, dtype=np.float64)
    check_array(coords, "coords", shape=(None, 2))
    colors = texture.colors
    s = coords / texture.scale
    if texture.kind == "checker":
        parity = (np.floor(s[:, 0]).astype(np.int64) + np.floor(s[:, 1]).astype(np.int64)) & 1
        return colors[parity]
    if texture.kind == "bricks":
        row = np.floor(s[:, 1]).astype(np.int64)
        x = s[:, 0] / 2.0 + 0.5 * (row & 1)  # bricks twice as long as high, offset rows
        col = np.floor(x).astype(np.int64)
        mortar = (s[:, 1] - row < 0.08) | (x - col < 0.04)
        n_brick = len(colors) - 1
        rng = np.random.default_rng(texture.seed)
        shade = rng.uniform(0.85, 1.15, size=(64, 64))
        pick = ((row * 7 + col * 13) % n_brick + n_brick) % n_brick
        out = colors[pick] * shade[row % 64, col % 64][:, None]
        out[mortar] = colors[-1]
        return np.clip(out, 0.0, 1.0)
    if texture.kind == "squares":
        cell = np.floor(s).astype(np.int64)
        margin = (1.0 - SQUARE_FILL) / 2.0
        frac = s - cell
        inside = np.all((frac >= margin) & (frac < 1.0 - margin), axis=1)
        rng = np.random.default_rng(texture.seed)
        pick = rng.integers(1, len(colors), size=(32, 32))
        out = np.repeat(colors[:1], len(s), axis=0)
        out[inside] = colors[pick[cell[inside, 0] % 32, cell[inside, 1] % 32]]
        return out
    # discs: one disc (radius 0.3 scale) jittered in every cell of a 1-scale grid
    cell = np.floor(s).astype(np.int64)
    rng = np.random.default_rng(texture.seed)
    jitter = rng.uniform(-0.15, 0.15, size=(32, 32, 2))
    radius = rng.uniform(0.2, 0.38, size=(32, 32))
    pick = rng.integers(1, len(colors), size=(32, 32))
    ci, cj = cell[:, 0] % 32, cell[:, 1] % 32
    centre = cell + 0.5 + jitter[ci, cj]
    inside = np.sum((s - centre) ** 2, axis=1) < radius[ci, cj] ** 2
    out = np.repeat(colors[:1], len(s), axis=0)
    out[inside] = colors[pick[ci, cj][inside]]
    return out


@dataclass(frozen=True, eq=False)
class Material:
    """Surface reflectance: Lambertian albedo (or texture) plus a Blinn-Phong lobe.

    The BRDF is ``albedo/pi + specular * (shininess + 8) / (8 pi) * (n.h)**shininess``;
    it is symmetric in light and view directions (reciprocal).

    Parameters
    ----------
    albedo : (3,) array_like
        Linear diffuse albedo, used when `texture` is None.
    texture : Texture, optional
    specular : float
        Weight of the Blinn-Phong lobe (0 = matte).
    shininess : float
        Blinn-Phong exponent.
    """

    albedo: np.ndarray = (0.5, 0.5, 0.5)
    texture: Texture = None
    specular: float = 0.0
    shininess: float = 40.0

    def __post_init__(self):
        albedo = _vec(self.albedo, "albedo")
        if np.any(albedo < 0) or np.any(albedo > 1):
            raise ValueError(f"albedo: must lie in [0, 1], got {albedo}")
        if not 0 <= self.specular < 1:
            raise ValueError(f"specular must be in [0, 1); got {self.specular}")
        _set(self, albedo=albedo, shininess=float(check_positive(self.shininess, "shininess", finite=True)))


# --------------------------------------------------------------------------- objects


@dataclass(frozen=True, eq=False)
class Sphere:
    """Sphere; texture coordinates are (azimuth, polar angle) times the radius."""

    center: np.ndarray
    radius: float
    material: Material = field(default_factory=Material)

    def __post_init__(self):
        _set(self, center=_vec(self.center, "center"), radius=float(check_positive(self.radius, "radius", finite=True)))


@dataclass(frozen=True, eq=False)
class Box:
    """Box of `half_extents` (x, y, z) about `center`, yawed by `yaw_deg` about +y.

    Texture coordinates are (local x + local z, local y).
    """

    center: np.ndarray
    half_extents: np.ndarray
    yaw_deg: float = 0.0
    material: Material = field(default_factory=Material)

    def __post_init__(self):
        half = _vec(self.half_extents, "half_extents")
        if np.any(half <= 0):
            raise ValueError(f"half_extents must be positive; got {half}")
        _set(self, center=_vec(self.center, "center"), half_extents=half,
             yaw_deg=float(self.yaw_deg))

    @property
    def rotation(self):
        """(3, 3) local -> world rotation."""
        return yaw_matrix(self.yaw_deg)


@dataclass(frozen=True, eq=False)
class GroundPlane:
    """Infinite horizontal plane ``y = height`` facing +y; texture coordinates (x, z)."""

    height: float
    material: Material = field(default_factory=Material)

    def __post_init__(self):
        if not np.isfinite(self.height):
            raise ValueError(f"height must be finite; got {self.height}")
        _set(self, height=float(self.height))


@dataclass(frozen=True, eq=False)
class BackPlane:
    """Finite vertical rectangle, yawed about +y, facing ``normal = yaw(+z)``.

    Its plane coordinates are ``x = (X - center).axis_x``, ``y = (X - center).axis_y``
    with ``axis_x = yaw(+x)``, ``axis_y = +y`` (scene units); it is the calibration plane.
    """

    center: np.ndarray
    width: float
    height: float
    yaw_deg: float = 0.0
    material: Material = field(default_factory=Material)

    def __post_init__(self):
        _set(self, center=_vec(self.center, "center"), width=float(check_positive(self.width, "width", finite=True)),
             height=float(check_positive(self.height, "height", finite=True)), yaw_deg=float(self.yaw_deg))

    @property
    def axis_x(self):
        return yaw_matrix(self.yaw_deg)[:, 0]

    @property
    def axis_y(self):
        return np.array(UP)

    @property
    def normal(self):
        return yaw_matrix(self.yaw_deg)[:, 2]

    def plane_coords(self, points):
        """Return (N, 2) plane coordinates (x, y) of (N, 3) world `points`."""
        rel = np.asarray(points, dtype=np.float64) - self.center
        return np.stack([rel @ self.axis_x, rel @ self.axis_y], axis=-1)


# --------------------------------------------------------------------------- lights


@dataclass(frozen=True, eq=False)
class PointLight:
    """Isotropic point light; `intensity` (3,) is radiant intensity per RGB channel (W/sr)."""

    position: np.ndarray
    intensity: np.ndarray = (0.02, 0.02, 0.02)

    def __post_init__(self):
        _set(self, position=_vec(self.position, "position"),
             intensity=_vec(self.intensity, "intensity"))

    @property
    def center(self):
        return self.position


@dataclass(frozen=True, eq=False)
class DistantLight:
    """Directional light; `direction` points from the scene *toward* the light,
    `irradiance` (3,) is the irradiance on a surface facing it."""

    direction: np.ndarray
    irradiance: np.ndarray = (1.0, 1.0, 1.0)

    def __post_init__(self):
        _set(self, direction=_unit(self.direction, "direction"),
             irradiance=_vec(self.irradiance, "irradiance"))


#: shapes of an area light
AREA_SHAPES = ("disc", "square", "sphere", "tube")


@dataclass(frozen=True, eq=False)
class AreaLight:
    """Small isotropic area light: a disc or square perpendicular to `normal`, a sphere, or a
    tube (a uniform line source) along the first axis of the plane perpendicular to `normal`
    (``normal x up``: the mask plane's e_u when the mask faces the same way).

    `size` is the disc's or sphere's diameter, the square's side, the tube's length. Sampled
    with a fixed stratified pattern of point lights that share `intensity` (3,) (total radiant
    intensity, W/sr): ``samples_per_side**2`` for a disc, square or tube,
    ``samples_per_side**3`` for a sphere (see :func:`light_samples`).
    """

    position: np.ndarray
    normal: np.ndarray
    size: float
    shape: str = "disc"
    intensity: np.ndarray = (0.02, 0.02, 0.02)
    samples_per_side: int = 4

    def __post_init__(self):
        check_in(self.shape, "shape", AREA_SHAPES)
        if int(self.samples_per_side) < 1:
            raise ValueError(f"samples_per_side must be >= 1; got {self.samples_per_side}")
        _set(self, position=_vec(self.position, "position"),
             normal=_unit(self.normal, "normal"), size=float(check_positive(self.size, "size", finite=True)),
             intensity=_vec(self.intensity, "intensity"),
             samples_per_side=int(self.samples_per_side))

    @property
    def center(self):
        return self.position


def _frame(normal, up=UP):
    """Return unit (e_u, e_v) with e_u = normalize(n x up), e_v = n x e_u."""
    e_u = np.cross(normal, np.asarray(up, dtype=np.float64))
    norm = np.linalg.norm(e_u)
    if norm < 1e-9:
        raise ValueError("up: must not be parallel to the aim direction")
    e_u = e_u / norm
    return e_u, np.cross(normal, e_u)


def light_plane_axes(light):
    """Unit (e1, e2) of an area light's plane (e1: a tube's axis), as its samples use them."""
    return _frame(light.normal, UP if abs(light.normal[1]) < 0.99 else (1, 0, 0))


def _sphere_offsets(k, radius):
    """(k**3, 3) offsets inside a ball whose projection on any plane is a uniform disc.

    A sphere of uniform radiance casts the shadows of a uniform disc of its radius facing
    each scene point. Points in the ball with density ``1 / sqrt(radius**2 - r**2)``
    project to a uniform disc along every direction (its Abel transform is constant), so
    one fixed sample set is exact for every point: k shells at the radial strata's middles
    (``r = radius sin(theta)``, ``theta - sin(theta) cos(theta)`` uniform in
    ``[0, pi/2]``) times k**2 directions of a Fibonacci sphere, rotated per shell.
    """
    targets = (np.arange(k) + 0.5) / k * (np.pi / 2)
    theta = np.array([_invert_increasing(lambda t: t - np.sin(t) * np.cos(t), g, 0.0, np.pi / 2)
                      for g in targets])
    n = k * k
    z = 1.0 - (2.0 * np.arange(n) + 1.0) / n
    ring = np.sqrt(np.clip(1.0 - z * z, 0.0, None))
    golden = np.pi * (3.0 - np.sqrt(5.0))
    shells = []
    for i, t in enumerate(theta):
        phi = golden * np.arange(n) + 2.0 * np.pi * i / k
        unit = np.column_stack([ring * np.cos(phi), ring * np.sin(phi), z])
        shells.append(radius * np.sin(t) * unit)
    return np.concatenate(shells)


def _invert_increasing(func, value, low, high, steps=60):
    """x in [low, high] with func(x) = value, for an increasing func (bisection)."""
    for _ in range(steps):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if func(mid) < value else (low, mid)
    return 0.5 * (low + high)


def light_samples(light):
    """Return the light's samples.

    Parameters
    ----------
    light : PointLight, DistantLight or AreaLight

    Returns
    -------
    positions : (S, 3) ndarray or None
        Sample positions (None for a distant light).
    directions : (S, 3) ndarray or None
        Unit directions toward the light (distant light only, else None).
    weights : (S, 3) ndarray
        Intensity (point/area, W/sr) or irradiance (distant) of each sample.
    """
    if isinstance(light, PointLight):
        return light.position[None], None, light.intensity[None]
    if isinstance(light, DistantLight):
        return None, light.direction[None], light.irradiance[None]
    if isinstance(light, AreaLight) and light.shape == "sphere":
        pos = light.position + _sphere_offsets(light.samples_per_side, 0.5 * light.size)
        return pos, None, np.repeat(light.intensity[None] / len(pos), len(pos), axis=0)
    if isinstance(light, AreaLight):
        k = light.samples_per_side
        a, b = np.meshgrid((np.arange(k) + 0.5) / k, (np.arange(k) + 0.5) / k, indexing="ij")
        a, b = a.ravel(), b.ravel()
        e1, e2 = light_plane_axes(light)
        if light.shape == "disc":  # equal-area stratified polar mapping
            r = 0.5 * light.size * np.sqrt(a)
            phi = 2 * np.pi * b
            x, y = r * np.cos(phi), r * np.sin(phi)
        elif light.shape == "tube":  # k*k strata along e1 (the mask's e_u for the presets)
            x, y = ((np.arange(k * k) + 0.5) / (k * k) - 0.5) * light.size, np.zeros(k * k)
        else:
            x, y = (a - 0.5) * light.size, (b - 0.5) * light.size
        pos = light.position + x[:, None] * e1 + y[:, None] * e2
        weights = np.repeat(light.intensity[None] / len(pos), len(pos), axis=0)
        return pos, None, weights
    raise ValueError(f"light: unsupported light type {type(light).__name__}")


# --------------------------------------------------------------------------- cameras


@dataclass(frozen=True, eq=False)
class PinholeCamera:
    """Pinhole: ``X_cam = R (X - center)``, ``x = K[0,0] X/Z + K[0,2]`` (pixel-edge coords)."""

    K: np.ndarray
    R: np.ndarray
    center: np.ndarray
    width: int
    height: int

    def __post_init__(self):
        K = np.asarray(self.K, dtype=np.float64)
        R = np.asarray(self.R, dtype=np.float64)
        if K.shape != (3, 3) or R.shape != (3, 3):
            raise ValueError("K, R: expected (3, 3) matrices")
        if not np.allclose(R @ R.T, np.eye(3), atol=1e-9):
            raise ValueError("R: must be a rotation matrix")
        if int(self.width) < 1 or int(self.height) < 1:
            raise ValueError(f"width, height: must be positive, got {self.width}, {self.height}")
        _set(self, K=K, R=R, center=_vec(self.center, "center"),
             width=int(self.width), height=int(self.height))


@dataclass(frozen=True, eq=False)
class OrthographicCamera:
    """Orthographic camera looking along ``R[2]``; pixel-edge coords (x, y) map to the
    ray origin ``center + (x - width/2) pixel_size R[0] + (y - height/2) pixel_size R[1]``."""

    R: np.ndarray
    center: np.ndarray
    pixel_size: float
    width: int
    height: int

    def __post_init__(self):
        R = np.asarray(self.R, dtype=np.float64)
        if R.shape != (3, 3) or not np.allclose(R @ R.T, np.eye(3), atol=1e-9):
            raise ValueError("R: must be a (3, 3) rotation matrix")
        _set(self, R=R, center=_vec(self.center, "center"),
             pixel_size=float(check_positive(self.pixel_size, "pixel_size", finite=True)),
             width=int(self.width), height=int(self.height))


def look_at_camera(center, target, *, fov_x_deg, width, height, up=UP):
    """Return a PinholeCamera at `center` looking at `target` (principal point at the centre)."""
    center = _vec(center, "center")
    forward = _unit(_vec(target, "target") - center, "target - center")
    right = np.cross(forward, np.asarray(up, dtype=np.float64))
    if np.linalg.norm(right) < 1e-9:
        raise ValueError("up: must not be parallel to the viewing direction")
    right /= np.linalg.norm(right)
    down = np.cross(forward, right)
    check_in_interval(fov_x_deg, "fov_x_deg", 0, 180, closed="neither")
    focal = width / 2.0 / math.tan(math.radians(fov_x_deg) / 2.0)
    K = np.array([[focal, 0.0, width / 2.0], [0.0, focal, height / 2.0], [0.0, 0.0, 1.0]])
    return PinholeCamera(K=K, R=np.stack([right, down, forward]), center=center,
                         width=width, height=height)


def camera_rays(camera, x, y):
    """Rays through pixel-edge image coordinates.

    Parameters
    ----------
    camera : PinholeCamera or OrthographicCamera
    x, y : (N,) ndarray
        Pixel-edge coordinates (column, row): pixel (row r, col c) centre is (c + 0.5, r + 0.5).

    Returns
    -------
    origins, directions : (N, 3) ndarray
        Ray origins and unit directions in world coordinates.
    """
    x = np.asarray(x, dtype=np.float64).ravel()
    y = np.asarray(y, dtype=np.float64).ravel()
    if x.shape != y.shape:
        raise ValueError(f"x, y: shapes differ ({x.shape} vs {y.shape})")
    if isinstance(camera, PinholeCamera):
        pix = np.stack([x, y, np.ones_like(x)], axis=-1)
        d = pix @ np.linalg.inv(camera.K).T @ camera.R  # R^T K^-1 pix, row-wise
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        return np.broadcast_to(camera.center, d.shape).copy(), d
    if isinstance(camera, OrthographicCamera):
        s = camera.pixel_size
        o = (camera.center + ((x - camera.width / 2.0) * s)[:, None] * camera.R[0]
             + ((y - camera.height / 2.0) * s)[:, None] * camera.R[1])
        return o, np.broadcast_to(camera.R[2], o.shape).copy()
    if callable(getattr(camera, "rays", None)):  # virtual cameras (lab.virtual)
        return camera.rays(x, y)
    raise ValueError(f"camera: unsupported camera type {type(camera).__name__}")


def project(camera, points):
    """Project (N, 3) world `points`; return (N, 2) pixel-edge (x, y) and (N,) depth z_cam."""
    points = np.asarray(points, dtype=np.float64)
    if isinstance(camera, PinholeCamera):
        cam = (points - camera.center) @ camera.R.T
        with np.errstate(divide="ignore", invalid="ignore"):
            xy = cam[:, :2] / cam[:, 2:3]
        xy = xy * np.diag(camera.K)[:2] + camera.K[:2, 2]
        return xy, cam[:, 2]
    if isinstance(camera, OrthographicCamera):
        cam = (points - camera.center) @ camera.R.T
        xy = cam[:, :2] / camera.pixel_size + np.array([camera.width, camera.height]) / 2.0
        return xy, cam[:, 2]
    if callable(getattr(camera, "project", None)):  # virtual cameras (lab.virtual)
        return camera.project(points)
    raise ValueError(f"camera: unsupported camera type {type(camera).__name__}")


# --------------------------------------------------------------------------- mask plane, wire


@dataclass(frozen=True, eq=False)
class MaskPlane:
    """The plane the wire moves in (README 1.3).

    Attributes
    ----------
    origin : (3,) M0 = L + f n (point light) or a point on the light side of the scene (distant).
    normal : (3,) n, the light's aim direction (from the light toward the scene).
    e_u, e_v : (3,) e_u = normalize(n x up), e_v = n x e_u.
    delta : frame step in the plane (scene units) = one dual pixel.
    n_u, n_v : dual grid size (frames per sweep).
    focal : f, light-to-plane distance (point light); None for a distant light.
    """

    origin: np.ndarray
    normal: np.ndarray
    e_u: np.ndarray
    e_v: np.ndarray
    delta: float
    n_u: int
    n_v: int
    focal: float = None


@dataclass(frozen=True, eq=False)
class WireSweep:
    """One wire sweep: centre line ``p(t) = p0 + t velocity``, axis `direction`, t = 0..frames-1.

    `velocity` is perpendicular to `direction`; both lie in the plane the wire moves in
    (normal = the mask normal). `light` is the light the sweep is captured under (None = the
    scene's light).
    """

    axis: str
    p0: np.ndarray
    velocity: np.ndarray
    direction: np.ndarray
    frames: int
    radius: float
    length: float
    light: object = None


def make_mask_plane(light, *, target, frames, f=0.045, fov_deg=44.0, extent=None, up=UP):
    """Mask plane of a light aimed at `target`.

    Parameters
    ----------
    light : PointLight, AreaLight or DistantLight
    target : (3,) array_like
        Point the light is aimed at (point/area) or the centre of the swept region (distant).
    frames : int
        Frames per sweep = dual grid size N_u = N_v.
    f : float
        Light-to-mask-plane distance (point/area light) or target-to-plane distance
        toward the light (distant light).
    fov_deg : float
        Dual field of view (point/area light): ``frames delta = 2 f tan(fov/2)``.
    extent : float, optional
        Width ``frames delta`` of the swept region (distant light; required there).
    up : (3,) array_like

    Returns
    -------
    MaskPlane
    """
    frames = int(frames)
    if frames < 2:
        raise ValueError(f"frames must be >= 2; got {frames}")
    f = float(check_positive(f, "f", finite=True))
    target = _vec(target, "target")
    if isinstance(light, DistantLight):
        if extent is None:
            raise ValueError("extent: required for a distant light")
        n = -light.direction
        delta = float(check_positive(extent, "extent", finite=True)) / frames
        origin = target - f * n
        focal = None
    else:
        n = _unit(target - light.center, "target - light position")
        check_in_interval(fov_deg, "fov_deg", 0, 180, closed="neither")
        delta = 2 * f * math.tan(math.radians(fov_deg) / 2) / frames
        origin = light.center + f * n
        focal = f
    e_u, e_v = _frame(n, up)
    return MaskPlane(origin=origin, normal=n, e_u=e_u, e_v=e_v, delta=delta,
                     n_u=frames, n_v=frames, focal=focal)


def make_wire_sweeps(mask, *, radius=None, length=None):
    """The two perpendicular sweeps of README 1.3.

    Sweep u: wire parallel to e_v, moving ``delta e_u`` per frame; sweep v: parallel to e_u,
    moving ``delta e_v``; frame (N-1)/2 passes through M0.

    Parameters
    ----------
    mask : MaskPlane
    radius : float, optional
        Wire radius; default `delta` (a dip about two frames wide).
    length : float, optional
        Wire length; default 1.5 x the dual field diagonal (covers the whole field).

    Returns
    -------
    dict of str to WireSweep
        Keys ``"u"`` and ``"v"``.
    """
    radius = mask.delta if radius is None else float(check_positive(radius, "radius", finite=True))
    if length is None:
        length = 1.5 * math.hypot(mask.n_u, mask.n_v) * mask.delta
    length = float(check_positive(length, "length", finite=True))
    sweeps = {}
    for axis, e_move, e_wire, n in (("u", mask.e_u, mask.e_v, mask.n_u),
                                    ("v", mask.e_v, mask.e_u, mask.n_v)):
        velocity = mask.delta * e_move
        sweeps[axis] = WireSweep(axis=axis, p0=mask.origin - (n - 1) / 2.0 * velocity,
                                 velocity=velocity, direction=e_wire.copy(), frames=n,
                                 radius=radius, length=length)
    return sweeps


def dual_camera(mask, light):
    """The dual (shadow) camera: dual pixel (row j, col i) centre <-> u = i, v = j.

    A pinhole at the light centre with ``R`` rows (e_u, e_v, n) and
    ``K = [[f/delta, 0, N_u/2], [0, f/delta, N_v/2], [0, 0, 1]]`` for a point or area light;
    an orthographic camera on the mask plane looking along n for a distant light.
    """
    R = np.stack([mask.e_u, mask.e_v, mask.normal])
    if isinstance(light, DistantLight):
        return OrthographicCamera(R=R, center=mask.origin, pixel_size=mask.delta,
                                  width=mask.n_u, height=mask.n_v)
    k = mask.focal / mask.delta
    K = np.array([[k, 0.0, mask.n_u / 2.0], [0.0, k, mask.n_v / 2.0], [0.0, 0.0, 1.0]])
    return PinholeCamera(K=K, R=R, center=light.center, width=mask.n_u, height=mask.n_v)


def wire_shadow_time(points, sweep, light=None):
    """Analytic time at which the wire centre line shadows each point (README 1.3).

    ``t = -(P - L).(d x (p0 - L)) / ((P - L).(d x v))`` for a light centre L; for a
    distant light (toward-light direction l) ``t = (P - p0).(d x l) / (v.(d x l))``.

    Parameters
    ----------
    points : (N, 3) ndarray
    sweep : WireSweep
    light : PointLight, AreaLight or DistantLight, optional
        Area lights use their centre. Default: the sweep's own light (``sweep.light``).

    Returns
    -------
    (N,) float64 ndarray
        Fractional frame (not restricted to [0, frames-1]; NaN where undefined).
    """
    light = sweep.light if light is None else light
    if light is None:
        raise ValueError("light: the sweep carries no light; pass one")
    points = np.asarray(points, dtype=np.float64)
    d, v = sweep.direction, sweep.velocity
    with np.errstate(divide="ignore", invalid="ignore"):
        if isinstance(light, DistantLight):
            w = np.cross(d, light.direction)
            return (points - sweep.p0) @ w / (v @ w)
        rel = points - light.center
        return -(rel @ np.cross(d, sweep.p0 - light.center)) / (rel @ np.cross(d, v))
