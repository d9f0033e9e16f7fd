"""Tests of shadowcam.synthetic.lab.optics and edges: camera rays bent by mirrors and thick
glass (paper section V), ground truth along the bent ray, straight edges in the dual view."""

import math

import numpy as np
import pytest

from shadowcam.cameras.straightness import edge_straightness
from shadowcam.synthetic.lab.edges import square_edge_points
from shadowcam.synthetic.lab.optics import (
    GlassSlab,
    GlassSphere,
    PlaneMirror,
    SphereMirror,
    camera_light_through_optics,
    camera_pixels_of_points,
    intersect_through_optics,
    reflect,
    refract,
    trace_through_optics,
)
from shadowcam.synthetic.lab.render import (
    pixel_centre_ground_truth,
    prepare_capture,
    render_image,
    render_reciprocal,
    trace_light_paths,
)
from shadowcam.synthetic.lab.scene import (
    PinholeCamera, PointLight, camera_rays, dual_camera, project,
)
from shadowcam.synthetic.lab.scenes import make_scene

H = W = 32
T = 24
GT_KEYS = ("P", "hit", "lit", "t_u_all", "t_v_all", "dist_C", "cos_C", "depth", "object_id")


def _gt(scene, camera=None, optics=()):
    return pixel_centre_ground_truth(scene.objects, camera or scene.camera, scene.light,
                                     scene.mask, scene.sweeps, optics=optics)


def test_reflection_and_snell_law_with_total_internal_reflection():
    n = np.array([[0.0, 0.0, 1.0]])
    a = math.radians(40)
    d = np.array([[math.sin(a), 0.0, -math.cos(a)]])
    assert np.allclose(reflect(d, n), [[math.sin(a), 0.0, math.cos(a)]], atol=1e-15)
    inside, ok = refract(d, n, 1.5)  # entering: sin r = sin i / 1.5
    assert ok[0] and math.isclose(inside[0, 0], math.sin(a) / 1.5, abs_tol=1e-15)
    out, ok = refract(inside, -n, 1.5)  # leaving through a parallel face: back to d
    assert ok[0] and np.allclose(out, d, atol=1e-15)
    steep = np.array([[math.sin(math.radians(50)), 0.0, math.cos(math.radians(50))]])
    _, ok = refract(steep, n, 1.5)  # leaving at 50 deg > critical angle 41.8 deg
    assert not ok[0]


def test_total_internal_reflection_marks_the_ray_as_no_hit():
    sphere = GlassSphere((0.0, 0.0, 0.0), 1.0, 1.5)
    origins = np.array([[0.9, 0.0, 0.0], [0.1, 0.0, 0.0]])
    dirs = np.array([[0.0, 1.0, 0.0], [0.0, 1.0, 0.0]])  # incidence sin = 0.9 and 0.1
    bent = trace_through_optics((sphere,), origins, dirs)
    assert not bent.valid[0] and np.all(np.isnan(bent.directions[0]))
    assert bent.valid[1] and bent.interactions[1] == 1


def test_thick_slab_shifts_a_ray_by_the_analytic_lateral_offset():
    thickness, index, i = 0.02, 1.5, math.radians(35)
    slab = GlassSlab((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), thickness, index)
    d = np.array([[math.sin(i), 0.0, -math.cos(i)]])
    o = np.array([[0.0, 0.0, 0.1]])
    bent = trace_through_optics((slab,), o, d)
    r = math.asin(math.sin(i) / index)
    assert bent.interactions[0] == 2 and np.allclose(bent.directions, d, atol=1e-14)
    offset = np.linalg.norm(np.cross(bent.origins[0] - o[0], d[0]))
    assert math.isclose(offset, thickness * math.sin(i - r) / math.cos(r), rel_tol=1e-12)
    assert math.isclose(bent.path_length[0],
                        (0.1 - thickness / 2) / math.cos(i) + thickness / math.cos(r),
                        rel_tol=1e-12)


def test_slab_of_index_one_leaves_the_ground_truth_unchanged():
    scene = make_scene("tabletop", height=H, width=W, frames=T)
    cam = scene.camera
    slab = GlassSlab(cam.center + 0.1 * cam.R[2], cam.R[2] + 0.4 * cam.R[0], 0.03, 1.0)
    direct, through = _gt(scene), _gt(scene, optics=(slab,))
    assert np.array_equal(direct["hit"], through["hit"])
    assert np.array_equal(direct["object_id"], through["object_id"])
    for key in ("P", "t_u_all", "t_v_all", "dist_C", "cos_C", "depth"):
        np.testing.assert_allclose(through[key], direct[key], atol=1e-9, rtol=0, err_msg=key)


def test_flat_mirror_ground_truth_is_that_of_the_mirrored_camera():
    """A camera looking back at a plane mirror 0.05 behind it sees what a camera 0.1
    further back, looking forward, sees (its virtual camera)."""
    scene = make_scene("tabletop", height=H, width=W, frames=T)
    cam = scene.camera
    f = cam.R[2]
    flip = np.eye(3) - 2 * np.outer(f, f)
    real = PinholeCamera(cam.K, cam.R @ flip, cam.center, W, H)
    virtual = PinholeCamera(cam.K, cam.R, cam.center - 0.1 * f, W, H)
    mirror = PlaneMirror(cam.center - 0.05 * f, f)
    seen, expected = _gt(scene, real, (mirror,)), _gt(scene, virtual)
    assert expected["hit"].mean() > 0.9 and expected["lit"].mean() > 0.5
    for key in GT_KEYS:
        np.testing.assert_allclose(seen[key], expected[key], atol=1e-6, rtol=0, err_msg=key)


def _edge_straightness(optics, size):
    scene = make_scene("tabletop_squares", height=size, width=size, frames=T, optics=optics)
    edges = square_edge_points(scene)
    ok = edges.lit & np.all((edges.dual_uv >= 0) & (edges.dual_uv <= T - 1), axis=1)
    if optics is not None:
        ok &= edges.through_optics
    primal = edge_straightness(edges.camera_xy[ok], labels=edges.label[ok], min_points=5)
    dual = edge_straightness(edges.dual_uv[ok], labels=edges.label[ok], min_points=5)
    return primal, dual


def test_edges_are_straight_in_both_views_without_optics():
    primal, dual = _edge_straightness(None, 64)
    assert np.isfinite(primal.rms).sum() >= 10
    assert primal.overall_rms < 1e-6 and dual.overall_rms < 1e-6


@pytest.mark.parametrize("optics, size, bent_px", [
    ({"kind": "mirror"}, 256, 1.5),  # measured 2.4 px RMS (max 3.5 px) at 256 px
    ({"kind": "glass", "shape": "sphere"}, 64, 1.5),  # measured 2.3 px RMS (max 3.9 px)
])
def test_optics_bend_edges_in_the_primal_view_but_not_in_the_dual_view(optics, size, bent_px):
    primal, dual = _edge_straightness(optics, size)
    assert np.isfinite(primal.rms).sum() >= 8
    assert primal.overall_rms > bent_px
    assert dual.overall_rms < 0.05


def test_make_scene_selects_optics_and_defaults_to_none():
    assert make_scene("tabletop", height=8, width=8, frames=4).optics == ()
    mirror = make_scene("tabletop", height=8, width=8, frames=4, optics={"kind": "mirror"})
    assert isinstance(mirror.optics[0], SphereMirror)
    glass = make_scene("tabletop", height=8, width=8, frames=4,
                       optics={"kind": "glass", "shape": "slab", "index": 1.33})
    assert isinstance(glass.optics[0], GlassSlab) and glass.optics[0].index == 1.33
    with pytest.raises(ValueError, match="optics"):
        make_scene("tabletop", height=8, width=8, frames=4, optics={"kind": "lens"})
    with pytest.raises(ValueError, match="index"):
        make_scene("tabletop", height=8, width=8, frames=4, optics={"kind": "glass", "index": 0.5})


def test_capture_through_glass_dips_at_the_ground_truth_time():
    scene = make_scene("tabletop_squares", height=H, width=W, frames=T,
                       optics={"kind": "glass", "shape": "sphere"})
    capture = prepare_capture(scene, supersample=1, calibration=False)
    gt = capture.ground_truth
    assert capture.homography is None
    frames = capture.frames("u").sum(-1)
    t = gt["t_u"].values
    good = np.isfinite(t) & (capture.reference.sum(-1) > 1e-3 * capture.reference.sum(-1).max())
    assert good.sum() > 0.3 * H * W
    rows, cols = np.nonzero(good)
    nearest = frames[np.rint(t[good]).astype(int), rows, cols]
    assert np.all(nearest < 0.5 * capture.reference.sum(-1)[good])


def _dual(scene, camera=None, optics=()):
    return render_reciprocal(scene.objects, camera or scene.camera, scene.light, scene.mask,
                             supersample=1, optics=optics)


def _assert_same_dual_visibility(seen, expected):
    """Visibility through optics equals the closed form (up to 0.5 % of dual pixels on
    silhouettes and the image border); the camera pixels agree to 1e-3 pixel."""
    vis, ref = seen["dual_cam_visible"], expected["dual_cam_visible"]
    assert ref.mean() > 0.3
    assert np.mean(vis != ref) <= 0.005
    both = vis & ref
    np.testing.assert_allclose(seen["dual_cam_xy"][both], expected["dual_cam_xy"][both],
                               atol=1e-3, rtol=0)


def test_dual_visibility_through_a_slab_of_index_one_is_the_direct_one():
    scene = make_scene("tabletop", height=H, width=W, frames=T)
    cam = scene.camera
    slab = GlassSlab(cam.center + 0.1 * cam.R[2], cam.R[2] + 0.4 * cam.R[0], 0.03, 1.0)
    _assert_same_dual_visibility(_dual(scene, optics=(slab,)), _dual(scene))


def test_dual_visibility_in_a_flat_mirror_is_that_of_the_mirrored_camera():
    scene = make_scene("tabletop", height=H, width=W, frames=T)
    cam = scene.camera
    f = cam.R[2]
    flip = np.eye(3) - 2 * np.outer(f, f)
    real = PinholeCamera(cam.K, cam.R @ flip, cam.center, W, H)
    virtual = PinholeCamera(cam.K, cam.R, cam.center - 0.1 * f, W, H)
    mirror = PlaneMirror(cam.center - 0.05 * f, f)
    _assert_same_dual_visibility(_dual(scene, real, (mirror,)), _dual(scene, virtual))


def test_dual_points_seen_through_glass_are_at_their_camera_pixel():
    """Through a glass sphere: the bent ray of a visible dual point's camera pixel meets
    that point first (to 1e-6 of its distance), and conversely the camera's lit pixel
    centres away from silhouettes land, in the dual camera, on visible dual pixels."""
    scene = make_scene("tabletop_squares", height=48, width=48, frames=T,
                       optics={"kind": "glass", "shape": "sphere"})
    dual = _dual(scene, optics=scene.optics)
    vis = dual["dual_cam_visible"]
    assert 0.2 < vis.mean() < 1.0
    xy = dual["dual_cam_xy"][vis]
    assert np.all((xy >= -0.5) & (xy <= 47.5))
    origins, dirs = camera_rays(scene.camera, xy[:, 0] + 0.5, xy[:, 1] + 0.5)
    hits, _ = intersect_through_optics(scene.objects, scene.optics, origins, dirs)
    target = dual["dual_P"][vis]
    scale = np.linalg.norm(target - scene.camera.center, axis=1)
    assert np.all(np.linalg.norm(hits.point - target, axis=1) <= 1e-6 * scale)
    gt = _gt(scene, optics=scene.optics)
    obj = gt["object_id"]
    inner = np.zeros_like(gt["lit"])
    inner[1:-1, 1:-1] = np.all([obj[1 + dr:47 + dr, 1 + dc:47 + dc] == obj[1:-1, 1:-1]
                                for dr in (-1, 0, 1) for dc in (-1, 0, 1)], axis=0)
    lit = gt["lit"] & inner
    uv, _ = project(dual_camera(scene.mask, scene.light), gt["P"][lit])
    u, v = np.floor(uv).astype(int).T
    on_grid = (u >= 0) & (u < T) & (v >= 0) & (v < T)
    assert on_grid.sum() > 100
    assert vis[v[on_grid], u[on_grid]].mean() >= 0.97


def test_camera_pixels_of_points_hides_occluded_points_and_validates():
    scene = make_scene("tabletop", height=H, width=W, frames=T)
    cam = scene.camera
    slab = (GlassSlab(cam.center + 0.1 * cam.R[2], cam.R[2], 0.03, 1.5),)
    gt = _gt(scene, optics=slab)
    seen_point = gt["P"][H // 2, W // 2]
    # a point on the ray's far side, behind the surface it meets: hidden
    behind = seen_point + 0.05 * (seen_point - cam.center) / np.linalg.norm(seen_point - cam.center)
    xy, seen = camera_pixels_of_points(scene.objects, slab, cam, np.array([seen_point, behind]))
    assert seen.tolist() == [True, False]
    np.testing.assert_allclose(xy[0], [W // 2, H // 2], atol=1e-3)
    with pytest.raises(ValueError, match="points"):
        camera_pixels_of_points(scene.objects, slab, cam, np.zeros((3, 2)))
    with pytest.raises(ValueError, match="tolerance"):
        camera_pixels_of_points(scene.objects, slab, cam, np.zeros((1, 3)), tolerance=0)


def _reciprocal_lit_by(scene, light):
    """Reciprocal render of `scene`'s dual view lit by `light` (no optics), supersample 1."""
    paths = trace_light_paths(scene.objects, dual_camera(scene.mask, scene.light), light,
                              supersample=1)
    return render_image(paths)


def _assert_same_radiance(seen, expected, visible):
    """Equal to 1e-4 relative where the camera sees the dual point (its pixels emit), on
    at least 30 % of the dual pixels, with light on most of them."""
    assert visible.mean() > 0.3
    scale = expected[visible].max()
    assert (expected[visible].sum(-1) > 1e-3 * scale).mean() > 0.5
    np.testing.assert_allclose(seen[visible], expected[visible], atol=1e-4 * scale, rtol=1e-4)


def test_reciprocal_light_in_a_flat_mirror_is_the_mirrored_camera_point_light():
    """The camera's reciprocal light reflected in a plane mirror 0.05 behind it is a point
    light 0.1 further back (the mirrored centre): same irradiance (the ray-tube Jacobian of
    a flat mirror is that of the unfolded distance) and the same shadows."""
    scene = make_scene("tabletop", height=H, width=W, frames=T)
    cam = scene.camera
    f = cam.R[2]
    flip = np.eye(3) - 2 * np.outer(f, f)
    real = PinholeCamera(cam.K, cam.R @ flip, cam.center, W, H)
    mirror = PlaneMirror(cam.center - 0.05 * f, f)
    seen = _dual(scene, real, (mirror,))
    expected = _reciprocal_lit_by(scene, PointLight(cam.center - 0.1 * f,
                                                    scene.light.intensity))
    _assert_same_radiance(seen["reciprocal"], expected, seen["dual_cam_visible"])


def test_reciprocal_light_through_a_slab_of_index_one_is_the_direct_one():
    scene = make_scene("tabletop", height=H, width=W, frames=T)
    cam = scene.camera
    slab = GlassSlab(cam.center + 0.1 * cam.R[2], cam.R[2] + 0.4 * cam.R[0], 0.03, 1.0)
    seen, direct = _dual(scene, optics=(slab,)), _dual(scene)
    _assert_same_radiance(seen["reciprocal"], direct["reciprocal"], seen["dual_cam_visible"])


def test_camera_light_through_optics_gain_is_inverse_square_without_bending():
    """Through a slab of index 1 each point gets one branch with gain 1/d^2 from the camera
    centre and the direction back to it; a point behind an occluder gets nothing."""
    scene = make_scene("tabletop", height=H, width=W, frames=T)
    cam = scene.camera
    slab = (GlassSlab(cam.center + 0.1 * cam.R[2], cam.R[2], 0.03, 1.0),)
    gt = _gt(scene, optics=slab)
    points = gt["P"][gt["hit"]][::7]
    to_light, gain, _ = camera_light_through_optics(scene.objects, slab, cam, points)
    reached = gain > 0
    assert reached.any(axis=1).mean() > 0.95 and np.all(reached.sum(axis=1) <= 1)
    g = gain.sum(axis=1)
    rel = cam.center - points
    d = np.linalg.norm(rel, axis=1)
    ok = g > 0
    np.testing.assert_allclose(g[ok], 1.0 / d[ok] ** 2, rtol=1e-3)
    direction = np.nansum(np.where(reached[..., None], to_light, 0.0), axis=1)
    np.testing.assert_allclose(direction[ok], rel[ok] / d[ok, None], atol=1e-6)
    behind = points[:1] + 0.5 * (points[:1] - cam.center)  # past the surface it lies on
    _, gain_behind, _ = camera_light_through_optics(scene.objects, slab, cam, behind)
    assert np.all(gain_behind == 0)
    with pytest.raises(ValueError, match="points"):
        camera_light_through_optics(scene.objects, slab, cam, np.zeros((3, 2)))


@pytest.mark.parametrize("inside_px", [0.01, 0.03])
def test_ray_tube_at_a_mirror_rim_is_the_branch_density_not_the_jump(inside_px):
    # a disc mirror's rim cuts the ray tube: a ray inside it by less than the difference
    # step must get the tube of the mirrored camera (the whole-plane mirror), to the first-order
    # error of a one-sided difference (1e-4), not a difference taken across the rim (the ray
    # beside the mirror goes elsewhere)
    from shadowcam.synthetic.lab.optics import _bent_offset, _tube_area

    focal, dist, radius, step = 400.0, 0.2, 0.02, 0.05
    cam = PinholeCamera(K=[[focal, 0, 32.0], [0, focal, 32.0], [0, 0, 1]], R=np.eye(3),
                        center=(0.0, 0.0, 0.0), width=64, height=64)
    disc = PlaneMirror((0.0, 0.0, dist), (0.0, 0.0, 1.0), radius)
    plane = PlaneMirror((0.0, 0.0, dist), (0.0, 0.0, 1.0))
    x = np.array([32.0 + focal * radius / dist - inside_px, 32.0])
    y = np.array([32.0, 32.0 - focal * radius / dist + inside_px])
    _, _, bent = _bent_offset((disc,), cam, np.zeros((2, 3)), x, y)
    assert (bent.interactions == 1).all()
    target = bent.origins + 0.3 * bent.directions
    rim = _tube_area((disc,), cam, target, x, y, step)
    whole = _tube_area((plane,), cam, target, x, y, step)
    np.testing.assert_allclose(rim, whole, rtol=1e-4)
    # the mirrored camera's tube at distance L = dist / cos + 0.3 from its centre: L^2 times
    # the solid angle per pixel cos^3 / f^2
    cos = focal / np.hypot(focal, np.hypot(x - 32.0, y - 32.0))
    length = dist / cos + 0.3
    np.testing.assert_allclose(whole, length**2 * cos**3 / focal**2, rtol=1e-6)
