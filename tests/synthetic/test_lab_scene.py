"""Tests of shadowcam.synthetic.lab.scene: cameras, mask plane and sweeps, analytic shadow times."""

import numpy as np
import pytest

from shadowcam.synthetic.lab.scene import (

    AreaLight, BackPlane, DistantLight, PointLight, camera_rays, dual_camera, look_at_camera,

    make_mask_plane, make_wire_sweeps, project, light_samples, wire_shadow_time,

    texture_albedo, Texture,

)
from shadowcam.synthetic.lab.scenes import make_scene


def test_camera_rays_reproject_to_their_pixel():
    cam = look_at_camera((0.03, 0.085, 0.3), (0, -0.02, -0.03), fov_x_deg=42, width=48,
                         height=32)
    rng = np.random.default_rng(0)
    x, y = rng.uniform(0, 48, 100), rng.uniform(0, 32, 100)
    o, d = camera_rays(cam, x, y)
    xy, depth = project(cam, o + 0.7 * d)
    np.testing.assert_allclose(xy, np.stack([x, y], -1), atol=1e-9)
    assert np.all(depth > 0)
    # the optical axis goes through the image centre (pixel-edge convention)
    _, d0 = camera_rays(cam, [24.0], [16.0])
    np.testing.assert_allclose(d0[0], cam.R[2], atol=1e-12)
    # camera y axis points down in the world
    assert cam.R[1][1] < 0


def test_mask_plane_frame_follows_readme_conventions():
    light = PointLight((-0.06, 0.04, 0.335))
    mask = make_mask_plane(light, target=(0.0, -0.02, -0.03), frames=96, f=0.045, fov_deg=44)
    n = mask.normal
    np.testing.assert_allclose(mask.e_u, np.cross(n, (0, 1, 0)) / np.linalg.norm(
        np.cross(n, (0, 1, 0))), atol=1e-12)
    np.testing.assert_allclose(mask.e_v, np.cross(n, mask.e_u), atol=1e-12)
    np.testing.assert_allclose(mask.origin, light.position + 0.045 * n, atol=1e-12)
    assert mask.n_u * mask.delta == pytest.approx(2 * 0.045 * np.tan(np.radians(22)))
    sweeps = make_wire_sweeps(mask)
    for axis, move, wire in (("u", mask.e_u, mask.e_v), ("v", mask.e_v, mask.e_u)):
        s = sweeps[axis]
        np.testing.assert_allclose(s.velocity, mask.delta * move)
        np.testing.assert_allclose(s.direction, wire)
        # frame (N-1)/2 passes through M0
        np.testing.assert_allclose(s.p0 + 47.5 * s.velocity, mask.origin, atol=1e-12)
        assert s.radius == mask.delta


def test_shadow_time_equals_dual_pixel_of_the_mask_crossing():
    """t_u, t_v of a point are the dual-camera pixel coordinates of its direction (README 1.3)."""
    light = PointLight((0.1, 0.2, 0.3))
    mask = make_mask_plane(light, target=(0.0, 0.0, 0.0), frames=64, f=0.05)
    sweeps = make_wire_sweeps(mask)
    dual = dual_camera(mask, light)
    rng = np.random.default_rng(1)
    x, y = rng.uniform(0, 64, 50), rng.uniform(0, 64, 50)
    o, d = camera_rays(dual, x, y)
    points = o + rng.uniform(0.1, 0.5, 50)[:, None] * d
    np.testing.assert_allclose(wire_shadow_time(points, sweeps["u"], light), x - 0.5, atol=1e-9)
    np.testing.assert_allclose(wire_shadow_time(points, sweeps["v"], light), y - 0.5, atol=1e-9)


def test_distant_light_dual_camera_is_orthographic_and_matches_shadow_time():
    light = DistantLight((0.3, 1.0, 0.5))
    mask = make_mask_plane(light, target=(0, 0, 0), frames=40, f=0.5, extent=0.4)
    np.testing.assert_allclose(mask.normal, -light.direction)
    sweeps = make_wire_sweeps(mask)
    dual = dual_camera(mask, light)
    rng = np.random.default_rng(2)
    x, y = rng.uniform(0, 40, 30), rng.uniform(0, 40, 30)
    o, d = camera_rays(dual, x, y)
    np.testing.assert_allclose(d, np.broadcast_to(mask.normal, d.shape))
    points = o + rng.uniform(0.1, 1.0, 30)[:, None] * d
    np.testing.assert_allclose(wire_shadow_time(points, sweeps["u"], light), x - 0.5, atol=1e-9)
    np.testing.assert_allclose(wire_shadow_time(points, sweeps["v"], light), y - 0.5, atol=1e-9)


def test_area_light_samples_are_on_the_disc_and_sum_to_the_intensity():
    light = AreaLight((0, 0, 0), (0, 0, -1), 0.01, "disc", (0.02, 0.03, 0.04), 4)
    pos, dirs, w = light_samples(light)
    assert dirs is None and pos.shape == (16, 3)
    assert np.all(np.linalg.norm(pos, axis=1) <= 0.005 + 1e-12)
    np.testing.assert_allclose(pos[:, 2], 0, atol=1e-15)
    np.testing.assert_allclose(w.sum(0), light.intensity)
    np.testing.assert_allclose(pos.mean(0), 0, atol=1e-4)


def test_back_plane_coordinates_are_orthonormal():
    plane = BackPlane((0, 0.2, -0.1), 1.0, 0.5, 12.0)
    np.testing.assert_allclose(plane.normal, [np.sin(np.radians(12)), 0, np.cos(np.radians(12))])
    p = plane.center + 0.3 * plane.axis_x - 0.1 * plane.axis_y
    np.testing.assert_allclose(plane.plane_coords(p[None]), [[0.3, -0.1]], atol=1e-12)


def test_make_scene_is_seeded_and_validates():
    a = make_scene("tabletop", seed=1, height=32, width=32, frames=16)
    b = make_scene("tabletop", seed=1, height=32, width=32, frames=16)
    c = make_scene("tabletop", seed=2, height=32, width=32, frames=16)
    np.testing.assert_array_equal(a.objects[0].center, b.objects[0].center)
    assert not np.array_equal(a.objects[0].center, c.objects[0].center)
    with pytest.raises(ValueError, match="name"):
        make_scene("nope")
    with pytest.raises(ValueError, match="height"):
        make_scene("tabletop", height=31)


def test_checker_texture_alternates():
    tex = Texture("checker", [[0, 0, 0], [1, 1, 1]], 0.1)
    out = texture_albedo(tex, np.array([[0.05, 0.05], [0.15, 0.05], [0.15, 0.15]]))
    np.testing.assert_array_equal(out[:, 0], [0, 1, 0])
