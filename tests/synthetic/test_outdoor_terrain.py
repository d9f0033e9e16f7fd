"""Tests of shadowcam.synthetic.outdoor.terrain: heightfield lookups, ray hits, horizons against analytic terrain."""

import numpy as np
import pytest

from shadowcam.synthetic.outdoor.terrain import (Heightfield, horizon_angles, intersect_heightfield,
                               make_ridge_terrain)


def _field(z, spacing=5.0, azimuth=58.0):
    z = np.asarray(z, dtype=np.float64)
    return Heightfield(z=z, albedo=np.full(z.shape + (3,), 0.3), a0=-1000.0, b0=-1000.0,
                       spacing=spacing, axis_azimuth_deg=azimuth)


def _grid(n=401, spacing=5.0):
    a = -1000.0 + spacing * np.arange(n)
    return np.meshgrid(a, a)  # (A, B) with rows = b, cols = a


def test_tilted_plane_height_and_normal_are_exact():
    A, B = _grid()
    terrain = _field(100.0 + 0.2 * A - 0.1 * B)
    rng = np.random.default_rng(0)
    a, b = rng.uniform(-900, 900, 200), rng.uniform(-900, 900, 200)
    x, y = terrain.to_xy(a, b)
    np.testing.assert_allclose(terrain.height(x, y), 100.0 + 0.2 * a - 0.1 * b, atol=1e-9)
    np.testing.assert_allclose(terrain.to_ab(x, y), (a, b), atol=1e-9)
    # gradient in world coordinates, from the (a, b) gradient
    s, c = np.sin(np.radians(58.0)), np.cos(np.radians(58.0))
    gx, gy = 0.2 * s - (-0.1) * c, 0.2 * c + (-0.1) * s
    expected = np.array([-gx, -gy, 1.0]) / np.linalg.norm([-gx, -gy, 1.0])
    np.testing.assert_allclose(terrain.normal(x, y), np.broadcast_to(expected, (200, 3)),
                               atol=1e-9)


def test_rays_hit_a_plane_at_the_analytic_distance():
    A, B = _grid()
    terrain = _field(np.full(A.shape, 50.0))
    rng = np.random.default_rng(1)
    n = 300
    origins = np.column_stack([rng.uniform(-200, 200, n), rng.uniform(-200, 200, n),
                               np.full(n, 80.0)])
    dirs = np.column_stack([rng.normal(size=n), rng.normal(size=n), -rng.uniform(0.05, 1, n)])
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    dist = intersect_heightfield(terrain, origins, dirs)
    expected = (80.0 - 50.0) / -dirs[:, 2]
    inside = terrain.inside(*(origins + expected[:, None] * dirs)[:, :2].T)
    np.testing.assert_allclose(dist[inside], expected[inside], rtol=1e-7)
    assert np.all(np.isnan(dist[~inside]))  # leave the grid: sky
    up = intersect_heightfield(terrain, origins, np.abs(dirs))
    assert np.all(np.isnan(up))


def test_ray_hit_is_the_first_one_on_a_ridged_terrain():
    terrain = make_ridge_terrain(seed=4)
    rng = np.random.default_rng(2)
    n = 200
    a0, b0 = rng.uniform(-1200, -900, n), rng.uniform(-300, 300, n)
    x0, y0 = terrain.to_xy(a0, b0)
    origins = np.column_stack([x0, y0, terrain.height(x0, y0) + 30.0])
    ta, tb = rng.uniform(0, 600, n), rng.uniform(-600, 600, n)
    tx, ty = terrain.to_xy(ta, tb)
    target = np.column_stack([tx, ty, terrain.height(tx, ty) + rng.uniform(-50, 250, n)])
    dirs = target - origins
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    dist = intersect_heightfield(terrain, origins, dirs)
    hit = ~np.isnan(dist)
    assert hit.mean() > 0.5
    p = origins[hit] + dist[hit, None] * dirs[hit]
    np.testing.assert_allclose(p[:, 2], terrain.height(p[:, 0], p[:, 1]), atol=1e-3)
    # dense check: every point before the hit is above the terrain
    s = np.linspace(0, 1, 4000)[None, :] * (dist[hit, None] - 0.01)
    q = origins[hit, None, :] + s[..., None] * dirs[hit, None, :]
    assert np.all(q[..., 2] >= terrain.height(q[..., 0], q[..., 1]) - 1e-6)


def test_horizon_of_a_wall_matches_its_elevation_angle():
    A, B = _grid(n=801, spacing=5.0)
    z = np.where(A > 600.0, 300.0, 0.0)  # a wall along b at a = 600..605 (bilinear ramp)
    terrain = _field(z, azimuth=0.0)     # +a = north, +b = west
    pts_a = np.array([-500.0, 0.0, 300.0])
    x, y = terrain.to_xy(pts_a, np.zeros(3))
    points = np.column_stack([x, y, np.zeros(3)])
    az = np.radians([0.0, 10.0, 180.0])
    h = horizon_angles(terrain, points, az, min_elevation_rad=np.radians(0.5),
                       max_elevation_rad=np.radians(80.0), bias=0.0)
    d_wall = 605.0 - pts_a  # the wall's top edge (first node at full height)
    # probes are a lower bound of the continuous maximum; at a sharp edge they fall short
    # by at most the refined probe spacing, 4 (ratio - 1) d / (2 refine) = d / 120
    for col, slant in ((0, 1.0), (1, np.cos(np.radians(10)))):
        exact = 300.0 * slant / d_wall
        got = np.tan(h[:, col])
        assert np.all(got <= exact * (1 + 1e-6))
        assert np.all(got >= exact * (1 - 1 / 120))
    np.testing.assert_allclose(h[:, 2], np.radians(0.5))  # nothing behind: clipped minimum


def test_ridge_terrain_is_seeded_and_has_a_cliff_below_a_higher_ridge():
    t1, t2 = make_ridge_terrain(seed=1), make_ridge_terrain(seed=1)
    np.testing.assert_array_equal(t1.z, t2.z)
    assert not np.array_equal(t1.z, make_ridge_terrain(seed=2).z)
    x, y = t1.to_xy(np.array([-1400.0, -50.0, 120.0, 600.0]), np.zeros(4))
    crest, foot, bench, top = t1.height(x, y)
    assert crest > bench > foot + 200.0 and top > crest  # plateau above the ridge crest
    assert np.all((t1.albedo > 0) & (t1.albedo < 1))
    with pytest.raises(ValueError, match="params"):
        make_ridge_terrain(seed=1, cliff_height=3.0)
