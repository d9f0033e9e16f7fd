"""Tests of the area-light capture description (wire radius, light shape, size, samples), the
sphere light's samples and the viewpoint reciprocal camera."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from shadowcam.synthetic.lab.raycast import wire_occlusion_interval
from shadowcam.synthetic.lab.scene import AreaLight, dual_camera, light_samples, project
from shadowcam.synthetic.lab.scenes import make_scene, scene_from_description
from shadowcam.synthetic.lab.viewpoint_camera import viewpoint_camera


def _description(**keys):
    return {"scene": "tabletop", "seed": 2, "height": 16, "width": 16, "frames": 32, "light": "area", **keys}


def test_description_keys_set_the_wire_radius_and_the_area_light():
    scene = scene_from_description(_description(wire_radius_frames=4,
                                                area_light={"shape": "sphere", "size": 0.01, "samples": 3}))
    assert all(s.radius == pytest.approx(4 * scene.mask.delta, rel=1e-12) for s in scene.sweeps.values())
    assert (scene.light.shape, scene.light.size, scene.light.samples_per_side) == ("sphere", 0.01, 3)
    assert len(light_samples(scene.light)[0]) == 27  # k**3 for a sphere
    # omitted keys keep the preset's disc and wire
    default = scene_from_description(_description())
    partial = scene_from_description(_description(area_light={"samples": 6}))
    assert (partial.light.shape, partial.light.size) == (default.light.shape, default.light.size)
    assert partial.sweeps["u"].radius == default.sweeps["u"].radius == default.mask.delta


@pytest.mark.parametrize("keys, message", [
    ({"wire_radius_frames": 0}, "wire_radius_frames"),
    ({"wire_radius_frames": float("nan")}, "wire_radius_frames"),
    ({"area_light": {"shape": "strip"}}, "area_light.shape"),
    ({"area_light": {"size": -1.0}}, "area_light.size"),
    ({"area_light": {"samples": 0}}, "area_light.samples"),
    ({"area_light": {"samples": 2.5}}, "area_light.samples"),
    ({"area_light": {"radius": 0.01}}, "area_light: unknown"),
    ({"area_light": {"shape": "disc"}, "light": "point"}, "area_light: describes an area light"),
])
def test_bad_description_keys_are_refused_naming_the_key(keys, message):
    with pytest.raises(ValueError, match=message):
        scene_from_description(_description(**keys))


@settings(max_examples=20, deadline=None)
@given(k=st.integers(2, 7), direction=st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda d: np.linalg.norm(d) > 0.1))
def test_sphere_samples_project_to_a_uniform_disc_along_any_direction(k, direction):
    # a uniform-radiance sphere casts the shadows of a uniform disc of its radius: the
    # projected samples have mean 0 and mean squared radius R^2 / 2 (the disc's), whatever
    # the direction; the stratified set reaches that to about 1 / k^2 relative
    light = AreaLight((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 2.0, "sphere", samples_per_side=k)
    positions = light_samples(light)[0]
    d = np.asarray(direction) / np.linalg.norm(direction)
    flat = positions - np.outer(positions @ d, d)
    assert np.all(np.linalg.norm(positions, axis=1) <= 1.0 + 1e-12)
    assert np.abs(flat.mean(axis=0)).max() < 0.05
    assert np.mean(np.sum(flat**2, axis=1)) == pytest.approx(0.5, abs=0.6 / k**2)


def test_a_tube_spans_the_u_sweep_and_is_a_point_to_the_v_sweep():
    # a tube along e_u: the u sweep's dip spreads over the tube's projection (penumbra as long
    # as the tube seen through the mask), the v sweep's stays a point light's (the wire
    # parallel to the tube hides all of it at once)
    from shadowcam.synthetic.lab.area_truth import area_light_times

    scene = make_scene("tabletop", height=16, width=16, frames=48, light_kind="area", wire_radius_frames=3,
                       area_light={"shape": "tube", "size": 0.006, "samples": 3})
    positions = light_samples(scene.light)[0]
    along = (positions - scene.light.center) @ scene.mask.e_u
    np.testing.assert_allclose(along.max() - along.min(), 0.006 * (1 - 1 / 9), rtol=1e-9)
    np.testing.assert_allclose((positions - scene.light.center) @ scene.mask.e_v, 0.0, atol=1e-12)
    points = _points()
    spread = {}
    for name in ("u", "v"):
        first, _ = area_light_times(points, scene.sweeps[name], scene.mask, scene.light, fraction=0.0)
        half, _ = area_light_times(points, scene.sweeps[name], scene.mask, scene.light, fraction=0.5)
        spread[name] = np.nanmedian(half - first)
    assert spread["u"] > 1.0 and spread["v"] < 1e-6


@pytest.fixture(scope="module")
def wide_scene():
    return make_scene("tabletop", height=16, width=16, frames=48, light_kind="area", wire_radius_frames=4)


def _points(n=300, seed=0):
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(-0.08, 0.08, n), rng.uniform(-0.05, 0.1, n), rng.uniform(-0.1, 0.02, n)])


@pytest.mark.parametrize("fraction", [0.0, 0.25, 0.5, 1.0])
def test_viewpoint_rays_pass_through_the_points_they_project(wide_scene, fraction):
    source = wide_scene.light.center + np.array([0.002, -0.001, 0.0005])
    camera = viewpoint_camera(wide_scene.sweeps, ("u", "v"), source, fraction, wide_scene.mask)
    points = _points()
    xy, depth = camera.project(points)
    origins, directions = camera.rays(xy[:, 0], xy[:, 1])
    rel = points - origins
    off_ray = rel - np.sum(rel * directions, axis=1)[:, None] * directions
    assert np.all(depth > 0) and np.all(np.sum(rel * directions, axis=1) > 0)
    np.testing.assert_allclose(np.linalg.norm(off_ray, axis=1), 0.0, atol=1e-12)
    # the time at the fraction across the blocked interval of the line to the source
    centre, half = wire_occlusion_interval(points, np.broadcast_to(source, points.shape),
                                           wide_scene.sweeps["u"], wide_scene.mask)
    np.testing.assert_allclose(xy[:, 0] - 0.5, centre + (2 * fraction - 1) * half, atol=1e-9)


def test_centre_viewpoint_from_the_light_is_the_standard_dual_camera(wide_scene):
    camera = viewpoint_camera(wide_scene.sweeps, ("u", "v"), wide_scene.light.center, 0.5, wide_scene.mask)
    points = _points()
    xy, _ = camera.project(points)
    standard, _ = project(dual_camera(wide_scene.mask, wide_scene.light), points)
    np.testing.assert_allclose(xy, standard, atol=1e-9)


def test_entry_and_exit_viewpoints_are_the_edges_a_wire_radius_either_side(wide_scene):
    # the wire's leading edge reaches a line r / |v.w| frames before its axis: about the
    # radius in mask steps (4), more at the field's edges where the lines slant
    points = _points()
    times = {f: viewpoint_camera(wide_scene.sweeps, ("u", "v"), wide_scene.light.center, f,
                                 wide_scene.mask).project(points)[0] for f in (0.0, 0.5, 1.0)}
    shift = times[0.5] - times[0.0]
    np.testing.assert_allclose(times[1.0] - times[0.5], shift, atol=1e-9)
    assert np.all(shift >= 4.0 - 1e-9) and np.all(shift <= 4.0 * 1.15)


def test_viewpoint_camera_refuses_bad_arguments(wide_scene):
    with pytest.raises(ValueError, match="fraction"):
        viewpoint_camera(wide_scene.sweeps, ("u", "v"), wide_scene.light.center, 1.5, wide_scene.mask)
    with pytest.raises(ValueError, match="names"):
        viewpoint_camera(wide_scene.sweeps, ("u", "u"), wide_scene.light.center, 0.5, wide_scene.mask)
    with pytest.raises(ValueError, match="source"):
        viewpoint_camera(wide_scene.sweeps, ("u", "v"), [0.0, 1.0], 0.5, wide_scene.mask)


@pytest.mark.parametrize("shape", ["disc", "sphere"])
def test_area_light_capture_carries_interval_truth_and_viewpoint_renders(shape):
    from shadowcam.synthetic.lab.area_truth import area_light_times
    from shadowcam.synthetic.lab.render import prepare_capture

    scene = make_scene("tabletop", height=16, width=16, frames=24, light_kind="area", wire_radius_frames=3,
                       area_light={"shape": shape, "samples": 3})
    gt = prepare_capture(scene, supersample=1, calibration=False).ground_truth
    points = gt["P"].values.reshape(-1, 3).astype(np.float64)
    entry, exit_ = area_light_times(points, scene.sweeps["v"], scene.mask, scene.light, fraction=0.5)
    np.testing.assert_allclose(gt["interval_entry_v"].values.ravel(), entry, atol=1e-4, equal_nan=True)
    np.testing.assert_allclose(gt["interval_exit_v"].values.ravel(), exit_, atol=1e-4, equal_nan=True)
    assert np.nanmin(gt["interval_entry_u"] - gt["penumbra_first_u"]) > 0
    for name in ("entry", "centre", "exit"):
        assert gt[f"reciprocal_{name}"].dims == ("v", "u", "channel")
        assert gt[f"dual_cam_visible_{name}"].values.any()
    # the centre viewpoint from the light's centre is the standard reciprocal render
    np.testing.assert_allclose(gt["reciprocal_centre"].values, gt["reciprocal"].values, rtol=1e-5, atol=1e-7)
    point = make_scene("tabletop", height=16, width=16, frames=24, light_kind="point")
    assert not any(k.startswith("reciprocal_") for k in prepare_capture(point, supersample=1,
                                                                        calibration=False).ground_truth)


def test_extreme_point_views_give_the_penumbras_outer_edges():
    # the corner of the continuous disc's bounding box, through the leading edges, is the
    # view whose times are the disc's first contact in both sweeps (area_truth at fraction
    # 0); the opposite corner through the trailing edges its last release
    from shadowcam.synthetic.lab.area_truth import area_light_times
    from shadowcam.synthetic.lab.render import _extreme_point_views

    scene = make_scene("tabletop", height=16, width=16, frames=48, light_kind="area", wire_radius_frames=4)
    views = _extreme_point_views(scene)
    points = _points()
    for name, pick in (("penumbra_first", 0), ("penumbra_last", 1)):
        source, fraction, _ = views[name]
        xy, _ = viewpoint_camera(scene.sweeps, ("u", "v"), source, fraction, scene.mask).project(points)
        for column, sweep in enumerate(("u", "v")):
            truth = area_light_times(points, scene.sweeps[sweep], scene.mask, scene.light, fraction=0.0)[pick]
            np.testing.assert_allclose(xy[:, column] - 0.5, truth, atol=1e-9)
    # the corner of the bounding square of the disc: sqrt(2) radii from its centre, off the disc
    corner = views["penumbra_first"][0]
    assert np.linalg.norm(corner - scene.light.center) == pytest.approx(np.sqrt(2) * 0.5 * scene.light.size)
    # a square keeps its samples: the corner of their bounding box
    square = make_scene("tabletop", height=16, width=16, frames=48, light_kind="area", wire_radius_frames=4,
                        area_light={"shape": "square", "samples": 4})
    offset = _extreme_point_views(square)["penumbra_first"][0] - square.light.center
    assert np.linalg.norm(offset) == pytest.approx(np.sqrt(2) * 0.5 * 0.006 * (1 - 1 / 4))
