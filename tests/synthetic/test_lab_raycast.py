"""Tests of shadowcam.synthetic.lab.raycast against analytic intersections."""

import numpy as np
import pytest

from shadowcam.synthetic.lab.raycast import (
    intersect_box,
    intersect_scene,
    intersect_sphere,
    occluded,
    wire_occlusion_interval,
)
from shadowcam.synthetic.lab.scene import (
    BackPlane,
    GroundPlane,
    Material,
    PointLight,
    Sphere,
    make_mask_plane,
    make_wire_sweeps,
    wire_shadow_time,
    yaw_matrix,
)


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def test_sphere_hits_lie_on_the_sphere_at_the_near_root():
    rng = np.random.default_rng(0)
    c, r = np.array([0.1, -0.2, 0.3]), 0.25
    o = rng.normal(size=(200, 3)) * 2 + c
    o = o[np.linalg.norm(o - c, axis=1) > r]
    target = c + rng.normal(size=(len(o), 3)) * 0.1
    d = _unit(target - o)
    t = intersect_sphere(o, d, c, r)
    # rays aimed within 0.1 (sigma) of the centre almost all hit; check every finite hit
    hit = np.isfinite(t)
    assert hit.mean() > 0.9
    p = o[hit] + t[hit, None] * d[hit]
    np.testing.assert_allclose(np.linalg.norm(p - c, axis=1), r, atol=1e-12)
    # near root: the chord midpoint lies beyond the hit
    mid = ((c - o[hit]) * d[hit]).sum(1)
    assert np.all(t[hit] <= mid + 1e-12)
    # a ray from the centre leaves at distance r
    assert intersect_sphere(c[None], np.array([[0, 0, 1.0]]), c, r)[0] == pytest.approx(r)
    # a ray pointing away misses
    assert np.isinf(intersect_sphere(np.array([[0, 0, 2.0]]), np.array([[0, 0, 1.0]]),
                                     np.zeros(3), 1.0)[0])


def test_yawed_box_face_hits_and_normals():
    yaw = 30.0
    R = yaw_matrix(yaw)
    c, h = np.array([1.0, 0.5, -2.0]), np.array([0.2, 0.3, 0.4])
    # a ray along the box's local -z axis, from outside, hits the +z face at distance 1 - h_z
    o = (c + R @ np.array([0.05, 0.1, 1.0]))[None]
    d = (R @ np.array([0, 0, -1.0]))[None]
    t, n = intersect_box(o, d, c, h, R)
    assert t[0] == pytest.approx(1.0 - 0.4)
    np.testing.assert_allclose(n[0], R @ [0, 0, 1.0], atol=1e-12)
    # from inside, the exit face is hit with its outward normal
    t, n = intersect_box(c[None], (R @ [1.0, 0, 0])[None], c, h, R)
    assert t[0] == pytest.approx(0.2)
    np.testing.assert_allclose(n[0], R @ [1.0, 0, 0], atol=1e-12)
    # a ray passing beside the box misses
    o = (c + R @ np.array([0.25, 0.0, 1.0]))[None]
    assert np.isinf(intersect_box(o, d, c, h, R)[0][0])


def test_scene_picks_nearest_object_and_reports_albedo():
    objects = (GroundPlane(-1.0, Material((0.2, 0.3, 0.4))),
               Sphere((0, 0, -5.0), 1.0, Material((0.9, 0.1, 0.1))),
               BackPlane((0, 0, -10.0), 4.0, 4.0, 0.0, Material((0.5, 0.5, 0.5))))
    o = np.zeros((3, 3))
    d = _unit([[0, 0, -1.0], [0, -1.0, -1.0], [0.18, 0.12, -1.0]])
    hits = intersect_scene(objects, o, d)
    np.testing.assert_array_equal(hits.object_id, [1, 0, 2])
    assert hits.distance[0] == pytest.approx(4.0)
    assert hits.distance[1] == pytest.approx(np.sqrt(2))
    assert hits.distance[2] == pytest.approx(10.0 / d[2, 2] * -1)
    np.testing.assert_allclose(hits.normal[0], [0, 0, 1.0], atol=1e-12)
    np.testing.assert_allclose(hits.normal[1], [0, 1.0, 0])
    np.testing.assert_allclose(hits.albedo, [[0.9, 0.1, 0.1], [0.2, 0.3, 0.4], [0.5] * 3])
    # outside the finite back plane: miss
    miss = intersect_scene(objects[2:], np.zeros((1, 3)), _unit([[1.0, 0, -1.0]]))
    assert miss.object_id[0] == -1 and np.isinf(miss.distance[0])


def test_occlusion_respects_segment_length():
    objects = (Sphere((0, 0, -1.0), 0.1),)
    o = np.zeros((2, 3))
    d = np.array([[0, 0, -1.0], [0, 0, -1.0]])
    np.testing.assert_array_equal(occluded(objects, o, d, np.array([0.5, 2.0])), [False, True])
    np.testing.assert_array_equal(occluded(objects, o, d, np.inf), [True, True])


def test_wire_interval_centre_is_the_analytic_shadow_time_and_width_the_radius():
    light = PointLight((0.0, 0.0, 0.0))
    mask = make_mask_plane(light, target=(0, 0, -1.0), frames=50, f=0.1, fov_deg=40)
    sweeps = make_wire_sweeps(mask)
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(-0.2, 0.2, 100), rng.uniform(-0.2, 0.2, 100),
                           np.full(100, -1.0)])
    lp = np.broadcast_to(light.position, pts.shape)
    for s in sweeps.values():
        tc, half = wire_occlusion_interval(pts, lp, s, mask)
        np.testing.assert_allclose(tc, wire_shadow_time(pts, s, light), atol=1e-9)
        # at the interval edge, the distance from the wire axis to the segment equals r
        t_edge = tc + half
        for i in range(5):
            wire_pt = s.p0 + t_edge[i] * s.velocity
            seg = pts[i] - light.position
            w = np.cross(seg, s.direction)
            dist = abs((wire_pt - light.position) @ w) / np.linalg.norm(w)
            assert dist == pytest.approx(s.radius, rel=1e-9)
    # a light point behind the mask plane is not blocked (crossing outside the segment)
    beyond = np.array([[0.0, 0.0, 0.05]])
    tc, _ = wire_occlusion_interval(np.array([[0.0, 0.0, 0.2]]), beyond, sweeps["u"], mask)
    assert np.isnan(tc[0])
