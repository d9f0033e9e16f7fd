"""Terrain heightfields for synthetic outdoor captures: procedural ridge/cliff, rays, horizons.

Conventions (as the shared outdoor data, ``/work/shared/data/README.md`` 2.3): world x = east,
y = north, z = up, metres; compass azimuth = ``atan2(east, north)``, clockwise from north.
The heightfield is stored on a regular grid in rotated ground coordinates ``(a, b)``:
``+a`` is the horizontal direction of compass azimuth ``axis_azimuth_deg`` (from the ridge
toward the cliff), ``+b`` is ``+a`` turned 90 deg counter-clockwise seen from above::

    x = a sin(az) - b cos(az),   y = a cos(az) + b sin(az)

The terrain surface is the **bilinear interpolant** of the grid heights; shading normals are
the bilinear interpolants of the node normals (central differences), like the smooth vertex
normals of a mesh. Everything that tests the terrain (view rays, shadow rays, horizons) uses
this one surface.

Offers
------
Heightfield : grid heights, albedo and normals with bilinear lookups (``height``,
    ``normal``, ``albedo``) at world (x, y).
RIDGE_DEFAULTS : shape parameters (metres) of the procedural ridge-and-cliff terrain.
make_ridge_terrain : seeded procedural terrain: a two-tier cliff with a bench and a bay,
    facing a higher ridge (saddle and horn on its crest) across a valley.
intersect_heightfield : first hit of rays with the terrain (Lipschitz-bounded marching
    + bisection), NaN for rays that leave the terrain (sky).
horizon_distances : the probe distances of the horizon search.
horizon_angles : elevation angle (rad) of the terrain horizon seen from points, per azimuth
    (geometrically spaced probes, refined around the best one).
"""

from dataclasses import dataclass, field

import numpy as np

from shadowcam._shared.validation import check_array, check_positive
from shadowcam.synthetic.lab.raycast import as_rays

#: Shape parameters of the procedural ridge terrain (metres, degrees). ``saddle`` is
#: (b centre, half width, depth), ``horn`` (a, b, height, radius), ``bay`` (b centre,
#: half width, recess depth), ``summit`` (a, b, height, radius).
RIDGE_DEFAULTS = {
    "axis_azimuth_deg": 58.0,
    "a_range": (-2800.0, 2600.0),
    "b_range": (-2600.0, 2600.0),
    "spacing": 5.0,
    "floor_z": 420.0,
    "floor_tilt": 0.015,
    "ridge_a": -1400.0,
    "ridge_height": 600.0,
    "ridge_w_cliffside": 380.0,
    "ridge_w_far": 650.0,
    "ridge_meander": 70.0,
    "saddle": (350.0, 230.0, 250.0),
    "horn": (-1450.0, -650.0, 220.0, 160.0),
    "cliff1_a": 0.0,
    "cliff1_height": 280.0,
    "cliff1_w": 18.0,
    "bench_width": 230.0,
    "bench_rise": 0.05,
    "cliff2_height": 300.0,
    "cliff2_w": 35.0,
    "bay": (-250.0, 320.0, 130.0),
    "plateau_rise": 260.0,
    "summit": (1500.0, 600.0, 420.0, 550.0),
    "detail_amp": 6.0,
}


def _sigmoid(x):
    return 0.5 * (1.0 + np.tanh(0.5 * x))


def _bilinear(grid, fa, fb):
    """Bilinear lookup of `grid` (nb, na[, C]) at fractional indices; clamped at the edges."""
    nb, na = grid.shape[:2]
    fa = np.clip(fa, 0.0, na - 1.000001)
    fb = np.clip(fb, 0.0, nb - 1.000001)
    ia = fa.astype(np.intp)
    ib = fb.astype(np.intp)
    wa = fa - ia
    wb = fb - ib
    if grid.ndim == 3:
        wa = wa[..., None]
        wb = wb[..., None]
    top = grid[ib, ia] * (1.0 - wa) + grid[ib, ia + 1] * wa
    bottom = grid[ib + 1, ia] * (1.0 - wa) + grid[ib + 1, ia + 1] * wa
    return top * (1.0 - wb) + bottom * wb


@dataclass(frozen=True, eq=False)
class Heightfield:
    """A terrain heightfield on a regular (a, b) grid.

    Parameters
    ----------
    z : (nb, na) ndarray
        Heights (m) at nodes ``a = a0 + i spacing``, ``b = b0 + j spacing`` (row j, col i).
    albedo : (nb, na, 3) ndarray
        Linear diffuse reflectance at the nodes.
    a0, b0 : float
        Ground coordinates of node (0, 0), metres.
    spacing : float
        Node spacing, metres.
    axis_azimuth_deg : float
        Compass azimuth of ``+a``.

    Attributes
    ----------
    node_normals : (nb, na, 3) ndarray
        Unit normals at the nodes (central differences), world coordinates.
    lipschitz : float
        Bound of the bilinear surface's slope (rise per horizontal metre).
    z_max : float
        Highest node.
    """

    z: np.ndarray
    albedo: np.ndarray
    a0: float
    b0: float
    spacing: float
    axis_azimuth_deg: float
    node_normals: np.ndarray = field(init=False, repr=False)
    lipschitz: float = field(init=False)
    z_max: float = field(init=False)

    def __post_init__(self):
        z = np.asarray(self.z, dtype=np.float64)
        albedo = np.asarray(self.albedo, dtype=np.float64)
        if z.ndim != 2 or min(z.shape) < 2 or not np.all(np.isfinite(z)):
            raise ValueError(f"z must be a finite (nb, na) grid with nb, na >= 2; got {z.shape}")
        if albedo.shape != z.shape + (3,):
            raise ValueError(f"albedo: expected shape {z.shape + (3,)}, got {albedo.shape}")
        check_positive(self.spacing, "spacing")
        gb, ga = np.gradient(z, self.spacing)
        # world gradient from (a, b) gradient: d/dx = da/dx d/da + db/dx d/db
        s, c = np.sin(np.radians(self.axis_azimuth_deg)), np.cos(np.radians(self.axis_azimuth_deg))
        gx = ga * s - gb * c
        gy = ga * c + gb * s
        n = np.stack([-gx, -gy, np.ones_like(z)], axis=-1)
        n /= np.linalg.norm(n, axis=-1, keepdims=True)
        # bound of the bilinear surface's slope: per-cell differences along each axis
        la = np.abs(np.diff(z, axis=1)).max() / self.spacing
        lb = np.abs(np.diff(z, axis=0)).max() / self.spacing
        object.__setattr__(self, "z", z)
        object.__setattr__(self, "albedo", albedo)
        object.__setattr__(self, "node_normals", n)
        object.__setattr__(self, "lipschitz", float(np.hypot(la, lb)) * 1.001)
        object.__setattr__(self, "z_max", float(z.max()))

    def to_ab(self, x, y):
        """World (x, y) -> ground (a, b), metres."""
        s, c = np.sin(np.radians(self.axis_azimuth_deg)), np.cos(np.radians(self.axis_azimuth_deg))
        return x * s + y * c, -x * c + y * s

    def to_xy(self, a, b):
        """Ground (a, b) -> world (x, y), metres."""
        s, c = np.sin(np.radians(self.axis_azimuth_deg)), np.cos(np.radians(self.axis_azimuth_deg))
        return a * s - b * c, a * c + b * s

    def _index(self, x, y):
        a, b = self.to_ab(np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64))
        return (a - self.a0) / self.spacing, (b - self.b0) / self.spacing

    def inside(self, x, y):
        """True where world (x, y) lies inside the grid."""
        fa, fb = self._index(x, y)
        nb, na = self.z.shape
        return (fa >= 0) & (fa <= na - 1) & (fb >= 0) & (fb <= nb - 1)

    def height(self, x, y):
        """Terrain height (m) at world (x, y); edge values continue outside the grid."""
        fa, fb = self._index(x, y)
        return _bilinear(self.z, fa, fb)

    def normal(self, x, y):
        """(..., 3) unit shading normal at world (x, y) (bilinear node normals, renormalised)."""
        fa, fb = self._index(x, y)
        n = _bilinear(self.node_normals, fa, fb)
        return n / np.linalg.norm(n, axis=-1, keepdims=True)

    def albedo_at(self, x, y):
        """(..., 3) linear albedo at world (x, y)."""
        fa, fb = self._index(x, y)
        return _bilinear(self.albedo, fa, fb)


def _smooth_noise(rng, shape, cell):
    """Value noise on `shape` nodes: a coarse random grid (one value per `cell` nodes), bicubic-ish
    (separable cubic spline) upsampled; zero mean, unit-ish amplitude."""
    from scipy.ndimage import zoom

    coarse = rng.standard_normal((shape[0] // cell + 3, shape[1] // cell + 3))
    fine = zoom(coarse, cell, order=3, mode="nearest")
    return fine[: shape[0], : shape[1]]


def make_ridge_terrain(*, seed=0, **params):
    """Procedural terrain: a two-tier cliff facing a higher ridge across a valley.

    The cliff (lower tier, bench, upper tier, recessed bay, plateau) runs along ``b`` at
    ``a ~ cliff1_a``; the ridge crest runs along ``b`` at ``a ~ ridge_a`` (toward the sun at
    sunset when ``axis_azimuth_deg`` ~ 58), with a saddle (notch) and a pointed horn, so its
    shadow edge on the cliff is not a straight line. A seeded small-scale relief and albedo
    texture (granite on steep faces, vegetation on gentle slopes, a few bright patches) make
    the scene non-uniform.

    Parameters
    ----------
    seed : int
        Seed of the detail relief, the ridge meander phase and the albedo texture.
    **params
        Overrides of :data:`RIDGE_DEFAULTS`.

    Returns
    -------
    Heightfield
    """
    unknown = set(params) - set(RIDGE_DEFAULTS)
    if unknown:
        raise ValueError(f"params: unknown terrain parameter(s) {sorted(unknown)}; "
                         f"known: {sorted(RIDGE_DEFAULTS)}")
    p = dict(RIDGE_DEFAULTS, **params)
    rng = np.random.default_rng([int(seed), 31])
    sp = float(p["spacing"])
    a = np.arange(p["a_range"][0], p["a_range"][1] + sp / 2, sp)
    b = np.arange(p["b_range"][0], p["b_range"][1] + sp / 2, sp)
    A, B = np.meshgrid(a, b)
    phase = rng.uniform(0, 2 * np.pi)

    z = p["floor_z"] + p["floor_tilt"] * A
    # ridge: asymmetric Gaussian cross-section, meandering crest, saddle and horn
    da = A - p["ridge_a"] - p["ridge_meander"] * np.sin(B / 700.0 + phase)
    width = np.where(da > 0, p["ridge_w_cliffside"], p["ridge_w_far"])
    sb, sw, sd = p["saddle"]
    crest = p["ridge_height"] - sd * np.exp(-0.5 * ((B - sb) / sw) ** 2)
    z = z + crest * np.exp(-0.5 * (da / width) ** 2)
    ha, hb, hh, hr = p["horn"]
    z = z + hh * np.exp(-0.5 * ((A - ha) ** 2 + (B - hb) ** 2) / hr**2)
    # cliff: two logistic steps around a bench, recessed by a bay
    bay_b, bay_w, bay_d = p["bay"]
    foot = p["cliff1_a"] + bay_d * np.exp(-0.5 * ((B - bay_b) / bay_w) ** 2)
    u1 = (A - foot) / p["cliff1_w"]
    u2 = (A - foot - p["bench_width"]) / p["cliff2_w"]
    z = z + p["cliff1_height"] * _sigmoid(u1) + p["cliff2_height"] * _sigmoid(u2)
    z = z + p["bench_rise"] * np.clip(A - foot, 0, p["bench_width"])
    z = z + p["plateau_rise"] * _sigmoid((A - foot - p["bench_width"] - 600.0) / 250.0)
    sa, sbb, sh, sr = p["summit"]
    z = z + sh * np.exp(-0.5 * ((A - sa) ** 2 + (B - sbb) ** 2) / sr**2)
    # seeded relief: a few metres at 40 m and 15 m scales
    cell40 = max(1, int(round(40.0 / sp)))
    cell15 = max(1, int(round(15.0 / sp)))
    z = z + p["detail_amp"] * (_smooth_noise(rng, z.shape, cell40)
                               + 0.4 * _smooth_noise(rng, z.shape, cell15))

    # albedo: steep granite vs gentle vegetation, bright patches, multiplicative texture
    gb, ga = np.gradient(z, sp)
    slope = np.hypot(ga, gb)
    steep = _sigmoid((slope - 0.9) / 0.15)[..., None]
    rock = np.array([0.34, 0.31, 0.28])
    veg = np.array([0.10, 0.13, 0.07])
    base = steep * rock + (1 - steep) * veg
    patches = _sigmoid((_smooth_noise(rng, z.shape, max(1, int(round(120.0 / sp)))) - 1.2) / 0.2)
    base = base + patches[..., None] * (np.array([0.55, 0.55, 0.55]) - base) * (1 - steep)
    texture = np.exp(0.18 * _smooth_noise(rng, z.shape, max(1, int(round(10.0 / sp))))
                     + 0.10 * rng.standard_normal(z.shape))
    albedo = np.clip(base * texture[..., None], 0.02, 0.9)
    return Heightfield(z=z, albedo=albedo, a0=float(a[0]), b0=float(b[0]), spacing=sp,
                       axis_azimuth_deg=float(p["axis_azimuth_deg"]))


def intersect_heightfield(terrain, origins, directions, *, min_step=0.5, bisect_steps=30,
                          max_iter=4000):
    """First intersection of rays with the terrain surface.

    The march uses the slope bound ``L`` of the bilinear surface: a ray at height gap ``g``
    above the terrain cannot reach it within ``g / (L |d_xy| - d_z)``, so it steps by that
    (at least `min_step`); a sign change of the gap is then bisected.

    Parameters
    ----------
    terrain : Heightfield
    origins, directions : (N, 3) ndarray
        Ray origins (above the terrain) and unit directions, world coordinates.
    min_step : float, keyword-only
        Smallest step (m); a terrain feature thinner than this along the ray may be missed.
    bisect_steps : int, keyword-only
        Bisection steps after bracketing (final bracket ``step / 2**bisect_steps``).
    max_iter : int, keyword-only
        Iteration limit of the march.

    Returns
    -------
    distance : (N,) ndarray
        Ray parameter of the hit (m), NaN for rays that leave the grid or rise above the
        highest terrain (sky).
    """
    origins, directions = as_rays(origins, directions)
    check_positive(min_step, "min_step")
    n = len(origins)
    dist = np.full(n, np.nan)
    s = np.zeros(n)
    hxy = np.hypot(directions[:, 0], directions[:, 1])
    rate = terrain.lipschitz * hxy - directions[:, 2]
    active = np.arange(n)
    prev = np.zeros(n)
    for _ in range(max_iter):
        if active.size == 0:
            break
        o, d = origins[active], directions[active]
        p = o + s[active, None] * d
        gap = p[:, 2] - terrain.height(p[:, 0], p[:, 1])
        hit = gap <= 0
        gone = (~hit) & ((~terrain.inside(p[:, 0], p[:, 1]))
                         | ((p[:, 2] > terrain.z_max) & (d[:, 2] >= 0)))
        if hit.any():
            idx = active[hit]
            lo, hi = prev[idx].copy(), s[idx].copy()
            oo, dd = origins[idx], directions[idx]
            for _ in range(bisect_steps):
                mid = 0.5 * (lo + hi)
                q = oo + mid[:, None] * dd
                below = q[:, 2] - terrain.height(q[:, 0], q[:, 1]) <= 0
                hi = np.where(below, mid, hi)
                lo = np.where(below, lo, mid)
            dist[idx] = hi
        keep = ~(hit | gone)
        active = active[keep]
        gap = gap[keep]
        r = rate[active]
        step = np.where(r > 0, gap / np.maximum(r, 1e-12), np.inf)
        step = np.clip(step, min_step, 200.0)
        prev[active] = s[active]
        s[active] += step
    return dist


def horizon_distances(terrain, *, ratio=1.05, first=1.0):
    """Horizontal probe distances (m) of :func:`horizon_angles`: geometric from `first` to the
    grid's diagonal, ``d[i+1] = ratio * d[i]``."""
    if not ratio > 1:
        raise ValueError(f"ratio must be > 1; got {ratio}")
    reach = float(np.hypot(*(np.array(terrain.z.shape) * terrain.spacing)))
    n = int(np.ceil(np.log(reach / first) / np.log(ratio))) + 1
    return first * ratio ** np.arange(n)


def horizon_angles(terrain, points, azimuths_rad, *, min_elevation_rad, max_elevation_rad,
                   bias=0.5, ratio=1.05, refine=12, candidates=2, block=1024, pairwise=False):
    """Elevation angle of the terrain horizon seen from `points` toward each azimuth.

    ``H(p, az) = atan(max_d (h(p + d e_az) - z_p - bias) / d)`` where ``d`` runs over the
    probe distances of :func:`horizon_distances` (inside the grid) plus `refine` evenly
    spaced distances on each side of each of the `candidates` best probes (between its
    second neighbours; each candidate outside the others' brackets), clipped to
    ``[min_elevation_rad, max_elevation_rad]``. At distance ``d`` the probes are
    ``(ratio - 1) d`` apart; on a smooth crest of curvature ``k`` the angle is then within
    ``k ((ratio - 1) d / refine)**2 / (8 d)`` rad of the continuous maximum. This sampled
    horizon *is* the shadow test of the renderer and of the ground truth, so both agree.

    Parameters
    ----------
    terrain : Heightfield
    points : (N, 3) ndarray
        World points (on the terrain).
    azimuths_rad : (A,) ndarray
        Compass azimuths (rad, clockwise from north); with `pairwise`, (N,): one per point.
    min_elevation_rad, max_elevation_rad : float, keyword-only
        Clip range of the result (only the sun's elevation range matters).
    bias : float, keyword-only
        Height (m) added to the points (shadow-ray origin offset).
    ratio : float, keyword-only
        Ratio of successive probe distances.
    refine : int, keyword-only
        Extra probes on each side of a best probe.
    candidates : int, keyword-only
        Number of best probes refined.
    block : int, keyword-only
        (point, azimuth) pairs processed at once (memory ~ block x probes x 40 bytes).
    pairwise : bool, keyword-only
        Horizon of point i toward azimuth i only.

    Returns
    -------
    (N, A) ndarray, or (N,) with `pairwise`
        Horizon elevation (rad).
    """
    points = np.asarray(points, dtype=np.float64)
    az = np.asarray(azimuths_rad, dtype=np.float64).ravel()
    check_array(points, "points", shape=(None, 3))
    if pairwise and len(az) != len(points):
        raise ValueError(f"azimuths_rad: pairwise needs one azimuth per point ({len(points)}), "
                         f"got {len(az)}")
    if not min_elevation_rad < max_elevation_rad:
        raise ValueError("min_elevation_rad: must be below max_elevation_rad")
    n, m = (len(points), 1) if pairwise else (len(points), len(az))
    sp = terrain.spacing
    pa, pb = terrain.to_ab(points[:, 0], points[:, 1])
    # unit horizontal direction of each azimuth in (a, b): rotate the world (east, north)
    da, db = terrain.to_ab(np.sin(az), np.cos(az))
    fa0 = np.repeat((pa - terrain.a0) / sp, m)
    fb0 = np.repeat((pb - terrain.b0) / sp, m)
    ea = da / sp if pairwise else np.tile(da / sp, n)
    eb = db / sp if pairwise else np.tile(db / sp, n)
    z0 = np.repeat(points[:, 2] + bias, m)
    dist = horizon_distances(terrain, ratio=ratio)
    # pad with a very low ring: probes leaving the grid read huge negative heights (ignored)
    grid = np.pad(terrain.z.astype(np.float32), 1, constant_values=-1e9)
    fa0 += 1.0
    fb0 += 1.0
    tan_max = np.tan(max_elevation_rad)
    best = np.empty(n * m)
    # a cheap first pass on every 6th probe: pairs already at the clip need no more work
    for lo in range(0, n * m, block):
        sl = slice(lo, min(lo + block, n * m))
        best[sl] = _probe(grid, fa0[sl], fb0[sl], ea[sl], eb[sl], z0[sl], dist[None, ::6])[0]
    todo = np.flatnonzero(best < tan_max)
    for lo in range(0, len(todo), block):
        sl = todo[lo:lo + block]
        tan_b, top = _probe(grid, fa0[sl], fb0[sl], ea[sl], eb[sl], z0[sl], dist[None, :],
                            candidates=candidates)
        # refine between the neighbours of each of the best probes
        frac = np.linspace(0.0, 1.0, 2 * refine + 1)
        d_lo = dist[np.maximum(top - 2, 0)]
        d_hi = dist[np.minimum(top + 2, len(dist) - 1)]
        fine = (d_lo[:, :, None] + (d_hi - d_lo)[:, :, None] * frac).reshape(len(sl), -1)
        tan_f, _ = _probe(grid, fa0[sl], fb0[sl], ea[sl], eb[sl], z0[sl], fine)
        best[sl] = np.maximum(tan_b, tan_f)
    best = np.clip(best, np.tan(min_elevation_rad), np.tan(max_elevation_rad))
    return np.arctan(best) if pairwise else np.arctan(best).reshape(n, m)


def _probe(grid, fa0, fb0, ea, eb, z0, dist, candidates=1):
    """Max over probes of ``(h - z0) / d`` and the indices of the `candidates` best probes.

    `grid` is the height grid padded with a ring of very low values, `fa0`, `fb0` index it;
    `dist` is (1, S) (shared) or (B, S). float32 bilinear lookups on the flattened grid
    (the hot loop of the renderer). Returns ``(B,)`` maxima and ``(B, candidates)`` indices
    of the best probes, each outside the bracket (index +-2) of the better ones.
    """
    nb, na = grid.shape
    dist = np.asarray(dist, dtype=np.float32)
    fa = fa0.astype(np.float32)[:, None] + dist * ea.astype(np.float32)[:, None]
    fb = fb0.astype(np.float32)[:, None] + dist * eb.astype(np.float32)[:, None]
    np.clip(fa, 0, na - 1.001, out=fa)
    np.clip(fb, 0, nb - 1.001, out=fb)
    ia = fa.astype(np.int32)
    ib = fb.astype(np.int32)
    fa -= ia
    fb -= ib
    flat = grid.ravel()
    idx = ib * na + ia
    top = flat[idx]
    top += (flat[idx + 1] - top) * fa
    idx += na
    bottom = flat[idx]
    bottom += (flat[idx + 1] - bottom) * fa
    top += (bottom - top) * fb
    top -= z0.astype(np.float32)[:, None]
    top /= dist
    rows = np.arange(len(top))
    k = np.empty((len(top), candidates), dtype=np.intp)
    k[:, 0] = np.argmax(top, axis=1)
    best = top[rows, k[:, 0]].astype(np.float64)
    for c in range(1, candidates):  # next best probe outside the earlier ones' brackets
        for j in (-2, -1, 0, 1, 2):
            top[rows, np.clip(k[:, c - 1] + j, 0, top.shape[1] - 1)] = -np.inf
        k[:, c] = np.argmax(top, axis=1)
    return best, k
