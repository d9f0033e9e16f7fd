"""The static grid mask under a moving light (virtual camera array): exact geometry."""

import numpy as np
import pytest

from shadowcam.synthetic.lab.light_motion import (
    array_camera, light_positions, make_grid_mask, render_camera_array, static_wire_shadow_time,
)
from shadowcam.synthetic.lab.render import pixel_centre_ground_truth
from shadowcam.synthetic.lab.scene import DistantLight, project
from shadowcam.synthetic.lab.scenes import make_scene

ROWS, COLS = 2, 3


@pytest.fixture(scope="module")
def scene():
    return make_scene("tabletop", height=32, width=32, frames=24)


@pytest.fixture(scope="module")
def capture(scene):
    return render_camera_array(scene, n_rows=ROWS, n_cols=COLS, spacing_frames=6.0,
                               supersample=2)


@pytest.fixture(scope="module")
def points(scene):
    gt = pixel_centre_ground_truth(scene.objects, scene.camera, scene.light, scene.mask, {})
    return gt["P"], gt["hit"]


def test_crossing_is_a_pinhole_camera_of_the_wire_times(scene, capture, points):
    """The pair (time of vertical wire j, time of horizontal wire i) of a point is its
    projection by array_camera(i, j), to float64 rounding."""
    P, _ = points
    n_u, n_v = capture.sizes["t_u"], capture.sizes["t_v"]
    grid = make_grid_mask(scene.mask, n_rows=ROWS, n_cols=COLS, spacing_frames=6.0)
    checked = 0
    for i in range(ROWS):
        for j in range(COLS):
            cam = array_camera(grid, i, j, frames_u=n_u, frames_v=n_v)
            xy, depth = project(cam, P.reshape(-1, 3))
            t_u = capture["t_vertical_wire"].values[j].ravel()
            t_v = capture["t_horizontal_wire"].values[i].ravel()
            ok = np.isfinite(t_u) & np.isfinite(t_v)
            assert ok.sum() > 100 and np.all(depth[ok] > 0)
            np.testing.assert_allclose(xy[ok, 0] - 0.5, t_u[ok], atol=1e-9)
            np.testing.assert_allclose(xy[ok, 1] - 0.5, t_v[ok], atol=1e-9)
            checked += 1
    assert checked == ROWS * COLS


def test_array_is_rectified_and_disparity_follows_depth(scene, capture, points):
    """Columns j, j' of the array: disparity (x_j - x_j') (1 + g / d) / delta for a point at
    depth d beyond the mask plane (g: light to mask distance)."""
    P, _ = points
    mask = scene.mask
    grid = make_grid_mask(mask, n_rows=ROWS, n_cols=COLS, spacing_frames=6.0)
    t = capture["t_vertical_wire"].values
    d = (P - mask.origin) @ mask.normal
    expected = (grid.cols[2] - grid.cols[0]) * (1 + mask.focal / d) / mask.delta
    ok = np.isfinite(t[2]) & np.isfinite(t[0])
    np.testing.assert_allclose(t[2][ok] - t[0][ok], expected[ok], rtol=1e-9)
    assert np.ptp(expected[ok]) > 0.5  # the scene's depth range shows in the disparity


def test_frames_are_dark_at_the_wire_times(capture):
    """Each wire's shadow reaches a point at its exact time: the frame nearest that time is
    darker than the frames 3 before and after (wires 6 frames apart; lit points only)."""
    for frames, times in ((capture["frames_horizontal"], capture["t_vertical_wire"]),
                          (capture["frames_vertical"], capture["t_horizontal_wire"])):
        signal = frames.values.sum(-1)
        n = signal.shape[0]
        for t in times.values:
            y, x = np.nonzero(np.isfinite(t) & (t >= 3) & (t <= n - 4))
            k = np.rint(t[y, x]).astype(int)
            at = signal[k, y, x]
            around = 0.5 * (signal[k - 3, y, x] + signal[k + 3, y, x])
            bright = around > 0.2 * np.median(around)
            assert bright.sum() > 100
            assert np.mean(at[bright] < 0.7 * around[bright]) > 0.97


def test_reciprocal_view_sees_the_point_at_its_wire_times(scene, capture, points):
    """Camera (i, j)'s reciprocal render shows, at dual pixel (t_v, t_u) of a point, that
    point (the camera is oriented and scaled as the times say)."""
    P, _ = points
    from shadowcam.synthetic.lab.render import render_reciprocal
    from shadowcam.synthetic.lab.scene import PointLight

    n_u, n_v = capture.sizes["t_u"], capture.sizes["t_v"]
    grid = make_grid_mask(scene.mask, n_rows=ROWS, n_cols=COLS, spacing_frames=6.0)
    cam = array_camera(grid, 1, 2, frames_u=n_u, frames_v=n_v)
    dual = render_reciprocal(scene.objects, scene.camera, PointLight(grid.crossing(1, 2)), None,
                             supersample=1, dual=cam)
    t_u, t_v = capture["t_vertical_wire"].values[2], capture["t_horizontal_wire"].values[1]
    ok = np.isfinite(t_u) & np.isfinite(t_v)
    col, row = np.rint(t_u[ok]).astype(int), np.rint(t_v[ok]).astype(int)
    seen = dual["dual_P"][row, col]
    hit = dual["dual_hit"][row, col]
    # within one dual pixel's footprint at the point's distance from the crossing
    reach = np.linalg.norm(P[ok] - grid.crossing(1, 2), axis=1) * scene.mask.delta / scene.mask.focal
    near = np.linalg.norm(seen - P[ok], axis=1) <= 1.5 * reach
    assert hit.mean() > 0.95 and near[hit].mean() > 0.9


def test_static_wire_time_matches_brute_force(scene):
    """The closed form against a search for the light position coplanar with wire and point."""
    rng = np.random.default_rng(3)
    positions = light_positions(scene.light, make_grid_mask(scene.mask), "horizontal")
    wire, direction = scene.mask.origin, scene.mask.e_v
    pts = scene.mask.origin + scene.mask.normal * 0.2 + rng.normal(0, 0.01, (50, 3))
    t = static_wire_shadow_time(pts, wire, direction, positions)
    step = positions[1] - positions[0]
    for p, tk in zip(pts, t):
        light = positions[0] + tk * step
        assert abs(np.cross(p - wire, direction) @ (light - wire)) < 1e-12


def test_refuses_a_distant_light():
    scene = make_scene("tabletop", height=16, width=16, frames=16, light_kind="distant")
    with pytest.raises(ValueError, match="point"):
        make_grid_mask(scene.mask)
    assert isinstance(scene.light, DistantLight)
