"""Camera-specific checks: straight edges seen through thick glass are bent in the primal
view and straight in the estimated dual view; parallel edges stay parallel in the
orthographic camera; a third sweep lowers the dual-coordinate error on a noisy render."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from shadowcam.cameras.accuracy import (
    line_direction_spread,
    redundancy_gain,
    sample_coordinates,
    straightness_primal_dual,
)
from shadowcam.cameras.models import camera_coords_from_shadow_time
from shadowcam.lab.accuracy import dual_coord_errors
from shadowcam.synthetic.lab.edges import square_edge_points
from shadowcam.synthetic.lab.scenes import scene_from_description

SWEEPS = [{"name": "u"}, {"name": "v", "angle_deg": 90},
          {"name": "w", "angle_deg": 45, "speed": 1.0}]


def test_sample_coordinates_is_bilinear_and_keeps_holes():
    v, u = np.mgrid[0:5, 0:6].astype(np.float64)
    u[2, 2] = np.nan
    got = sample_coordinates(2 * u + 1, v, np.array([[0.5, 0.25], [4.75, 3.5], [2.5, 1.5], [6.0, 1.0]]))
    np.testing.assert_allclose(got[:2], [[2.0, 0.25], [10.5, 3.5]])
    assert np.isnan(got[2]).all() and np.isnan(got[3]).all()


def test_glass_unwarped_by_the_dual_view():
    description = {"scene": "tabletop_squares", "seed": 0, "height": 64, "width": 64, "frames": 32,
                   "optics": {"kind": "glass", "shape": "sphere"}}
    from shadowcam.lab.shadow_time import shadow_time_dataset, sweep_shadow_times
    from shadowcam.synthetic.lab.render import prepare_capture

    scene = scene_from_description(description)
    capture = prepare_capture(scene, supersample=2, calibration=False)
    shadow_time = shadow_time_dataset({n: sweep_shadow_times([capture.frames(n)], (64, 64))
                                       for n in capture.sweep_names})
    coords = camera_coords_from_shadow_time(shadow_time, description)
    edges = square_edge_points(scene)
    ok = edges.lit & edges.through_optics & np.all((edges.dual_uv >= 0) & (edges.dual_uv <= 31), axis=1)
    found = straightness_primal_dual(coords["u"].values, coords["v"].values, edges.camera_xy[ok],
                                     edges.label[ok])
    assert found["n_edges"] >= 6
    assert found["primal_rms"] > 1.5 and found["dual_rms"] <= 0.5, found


def test_line_direction_spread():
    t = np.linspace(0, 1, 10)
    lines = [np.column_stack([t, 0.5 * t + k]) for k in range(3)]
    labels = np.repeat(np.arange(3), 10)
    assert line_direction_spread(np.concatenate(lines), labels) < 1e-9
    tilted = np.column_stack([t, -2 * t]) @ np.array([[1.0, 0.0], [0.0, 1.0]])
    spread = line_direction_spread(np.concatenate([lines[0], tilted]), np.repeat([0, 1], 10))
    assert abs(spread - (np.degrees(np.arctan(0.5)) + np.degrees(np.arctan(2.0)))) < 1e-9
    with pytest.raises(ValueError, match="two edges"):
        line_direction_spread(lines[0], np.zeros(10, int))


def test_third_sweep_lowers_the_dual_coordinate_error_on_a_noisy_render(timed_capture):
    description = {"scene": "tabletop", "seed": 3, "height": 40, "width": 40, "frames": 32,
                   "sweeps": SWEEPS}
    _, gt, shadow_time, _ = timed_capture(description, noise_std=0.02)
    truth = gt["t_u"].values, gt["t_v"].values
    two = camera_coords_from_shadow_time(shadow_time, {**description, "sweeps": SWEEPS[:2]})
    three = camera_coords_from_shadow_time(shadow_time, description)
    common = two["valid"].values & three["valid"].values
    e2 = dual_coord_errors(two["u"].values, two["v"].values, *truth, valid=common)
    e3 = dual_coord_errors(three["u"].values, three["v"].values, *truth, valid=common)
    assert redundancy_gain(e2, e3) > 1.05, (e2, e3)


def _declared(v_speed=0.5):
    from shadowcam.cameras.models import declared_sweeps

    return declared_sweeps({"sweeps": [
        {"name": "u", "angle_deg": 0.0, "frames": 48},
        {"name": "v", "angle_deg": 90.0, "speed": v_speed, "frames": 96},
        {"name": "s", "angle_deg": 60.0, "speed": 1.0, "frames": 66}]})


def _exact_times(sweeps, shape=(48, 48), seed=0):
    from shadowcam.cameras.models import sweep_rows

    rng = np.random.default_rng(seed)
    u, v = rng.uniform(0, shape[1] - 1, 4000), rng.uniform(0, shape[0] - 1, 4000)
    rows = sweep_rows(sweeps, dual_shape=shape)
    return {s["name"]: (r[0] * u + r[1] * v + r[2]).reshape(40, 100) for s, r in zip(sweeps, rows)}


def test_sweep_geometry_from_exact_times_is_the_declaration():
    from shadowcam.cameras.accuracy import sweep_geometry_errors

    sweeps = _declared()
    times = _exact_times(sweeps)
    times["s"].flat[:40] += 7.0  # 1% wrong times (false dips) are trimmed
    result = sweep_geometry_errors(times, sweeps, dual_shape=(48, 48))["s"]
    assert abs(result["angle_error_deg"]) < 1e-6 and abs(result["speed_rel_error"]) < 1e-6


def test_sweep_geometry_sees_a_wrong_speed_declaration():
    """Times of v at half speed declared at unit speed: s looks slanted by
    atan2(sin 60 / 2, cos 60) - 60 = -19.1 deg and faster."""
    from shadowcam.cameras.accuracy import sweep_geometry_errors

    times = _exact_times(_declared(0.5))
    wrong = _declared(1.0)
    result = sweep_geometry_errors(times, wrong, dual_shape=(48, 48))["s"]
    expected = math.degrees(math.atan2(math.sin(math.radians(60)) / 2, 0.5)) - 60.0
    assert result["angle_error_deg"] == pytest.approx(expected, abs=1e-6)
    with pytest.raises(ValueError, match="at least three"):
        sweep_geometry_errors(times, wrong[:2], dual_shape=(48, 48))


@given(angle=st.floats(20.0, 160.0), speed=st.floats(0.3, 3.0), v_speed=st.floats(0.3, 3.0))
@settings(max_examples=40, deadline=None)
def test_camera_grid_map_takes_the_truth_times_to_the_linear_grid(angle, speed, v_speed):
    from shadowcam.cameras.accuracy import camera_grid_map
    from shadowcam.cameras.models import declared_sweeps, sweep_rows

    sweeps = declared_sweeps({"sweeps": [{"name": "u", "frames": 40},
                                         {"name": "w", "angle_deg": angle, "speed": speed, "frames": 50},
                                         {"name": "v", "angle_deg": 90, "speed": v_speed, "frames": 60}]})
    rows = sweep_rows(sweeps, dual_shape=(30, 40))
    u, v = np.meshgrid(np.linspace(-2, 41, 7), np.linspace(-1, 31, 5))
    t = {s["name"]: r[0] * u + r[1] * v + r[2] for s, r in zip(sweeps, rows)}
    grid = camera_grid_map({"method": "linear", "sweeps": "u w v", "sweep_rows": rows.ravel()})
    mapped = grid @ np.stack([t["u"].ravel(), t["v"].ravel(), np.ones(u.size)])
    np.testing.assert_allclose(mapped[:2] / mapped[2], [u.ravel(), v.ravel()], atol=1e-9)


def test_camera_grid_map_of_other_cameras():
    from shadowcam.cameras.accuracy import camera_grid_map

    np.testing.assert_array_equal(camera_grid_map({"method": "cross_slit", "sweeps": "u v"}), np.eye(3))
    assert camera_grid_map({"method": "cross_slit", "sweeps": "a b"}) is None
    assert camera_grid_map({"method": "linear", "sweeps": "u w", "sweep_rows": np.zeros(6)}) is None
    assert camera_grid_map({"method": "pushbroom", "sweeps": "u"}) is None


def test_redundant_sweeps_lower_the_dual_error_on_the_same_pixels(timed_capture):
    from shadowcam.cameras.accuracy import linear_redundancy

    description = {"scene": "tabletop", "seed": 3, "height": 40, "width": 40, "frames": 32,
                   "sweeps": [{"name": "u"}, {"name": "v", "angle_deg": 90},
                              {"name": "w", "angle_deg": 45, "speed": 1.0}]}
    _, gt, shadow_time, _ = timed_capture(description, noise_std=0.02)
    truth = {s: gt[f"t_{s}"].values for s in ("u", "v")}
    found = linear_redundancy(shadow_time, description, truth)
    assert found["sweeps_two"] == "u v" and found["n_pixels"] > 1000
    # two sweeps: (u, v) are the times themselves; the third adds an independent equation
    two = camera_coords_from_shadow_time(shadow_time, {**description, "sweeps": description["sweeps"][:2]},
                                         model="linear")
    keep = two["valid"].values & np.isfinite(truth["u"]) & np.isfinite(truth["v"])
    direct = np.sqrt(np.mean((two["u"].values - truth["u"])[keep] ** 2 + (two["v"].values - truth["v"])[keep] ** 2))
    assert found["rmse_two"] == pytest.approx(direct, rel=0.05)
    assert found["gain"] > 1.0 and found["reduction"] == pytest.approx(1 - 1 / found["gain"])
    with pytest.raises(ValueError, match="three or more"):
        linear_redundancy(shadow_time, {**description, "sweeps": description["sweeps"][:2]}, truth)


def test_straightness_check_reads_the_ground_truth_edges_and_sets_its_target():
    import xarray as xr

    from shadowcam.cameras.accuracy import DUAL_STRAIGHTNESS_TARGET, add_camera_checks, straightness_check

    v, u = np.mgrid[0:40, 0:40].astype(np.float64)
    # primal bent: the camera sees the straight lines x = 10, 20, 30 along a parabola;
    # the dual coordinates undo the bend exactly (u = x - bend(y))
    rows = np.arange(2.0, 38.0)
    bend = 0.01 * (rows - 20) ** 2
    xy = np.concatenate([np.column_stack([x + bend, rows]) for x in (10, 20, 30)])
    labels = np.repeat([0, 1, 2], len(rows))
    coords = xr.Dataset({"u": (("row", "col"), u - 0.01 * (v - 20) ** 2), "v": (("row", "col"), v)})
    gt = xr.Dataset({"edge_camera_xy": (("edge_point", "cam_xy"), xy), "edge_label": ("edge_point", labels),
                     "edge_lit": ("edge_point", np.ones(len(xy), bool)),
                     "edge_through_optics": ("edge_point", np.ones(len(xy), bool))})
    found, target = straightness_check(coords, gt)
    assert found["n_edges"] == 3 and found["primal_rms"] > 0.5 and found["dual_rms"] < 1e-2, found
    assert target["threshold"] == DUAL_STRAIGHTNESS_TARGET and target["pass"]
    assert straightness_check(coords, gt.drop_vars("edge_camera_xy")) == (None, None)
    report = {"targets": [], "all_targets_pass": False}
    add_camera_checks(report, None, gt, camera_model="perspective", description={"sweeps": []},
                      dual_coords=coords)
    assert report["straightness"] == found and report["all_targets_pass"]


def _squares_capture(light_kind):
    from shadowcam.synthetic.lab.render import prepare_capture
    from shadowcam.synthetic.lab.scenes import make_scene

    scene = make_scene("tabletop_squares", seed=3, height=64, width=64, frames=48,
                       light_kind=light_kind)
    return scene, prepare_capture(scene, supersample=1, calibration=False).ground_truth


@pytest.mark.parametrize("light_kind", ["distant", "point"])
def test_parallel_edges_of_the_exact_dual_view(light_kind):
    """Exact dual coordinates of the squares' edges (yawed back plane: edges at different
    depths): the orthographic dual (distant light) keeps them parallel and equal squares
    equal; the perspective dual (point light) does neither."""
    from shadowcam.cameras.accuracy import parallel_edges
    from shadowcam.synthetic.lab.scene import DistantLight

    from shadowcam.synthetic.lab.scenes import make_scene

    scene = make_scene("tabletop_squares", seed=3, height=64, width=64, frames=48,
                       light_kind=light_kind)
    edges = square_edge_points(scene)
    ok = edges.lit
    light = scene.light
    distant = isinstance(light, DistantLight)
    toward = light.direction if distant else light.center - edges.world[ok].mean(axis=0)
    found = parallel_edges(edges.dual_uv[ok], edges.world[ok], edges.label[ok],
                           toward_light=toward, light_position=None if distant else light.center)
    assert found["n_families"] == 2 and found["size_edges"] >= 8
    if distant:
        assert found["spread_deg"] < 1e-6 and abs(found["size_ratio"] - 1) < 1e-6
        assert found["depth_ratio"] is None
    else:  # near edges magnified: the ratio exceeds the depth ratio far / near (> 1)
        assert found["spread_deg"] > 2.0 and found["size_ratio"] > found["depth_ratio"] > 1.05
    with pytest.raises(ValueError, match="toward_light"):
        parallel_edges(edges.dual_uv[ok], edges.world[ok], edges.label[ok], toward_light=[0, 0, 0])
    with pytest.raises(ValueError, match="labels"):
        parallel_edges(edges.dual_uv[ok][:3], edges.world[ok][:3], edges.label[ok][:3],
                       toward_light=[0, 0, 1])


@pytest.mark.parametrize("light_kind", ["distant", "point"])
def test_parallelism_check_on_the_truth_times_sets_its_targets(light_kind):
    """The check reads the ground truth's edges and light; with the analytic times as the
    estimate (read bilinearly at the edges) the orthographic view passes both targets and
    the perspective one fails them."""
    import xarray as xr

    from shadowcam.cameras.accuracy import PARALLEL_TARGETS, add_camera_checks, parallelism_check

    _, gt = _squares_capture(light_kind)
    coords = xr.Dataset({"u": gt["t_u_all"], "v": gt["t_v_all"]})
    found, targets = parallelism_check(coords, gt)
    rows = {t["target"]: t for t in targets}
    assert set(rows) == set(PARALLEL_TARGETS)
    if light_kind == "distant":
        assert rows["dual_parallel_spread_deg"]["value"] <= 0.5
        assert rows["dual_size_ratio_error"]["value"] <= 0.01
        assert all(t["pass"] for t in targets)
        report = {"targets": [], "all_targets_pass": False}
        add_camera_checks(report, None, gt, camera_model="orthographic",
                          description={"sweeps": []}, dual_coords=coords)
        assert report["parallelism"] == found
    else:
        assert not any(t["pass"] for t in targets)
    assert parallelism_check(coords, gt.drop_vars("edge_world")) == (None, [])


@pytest.mark.parametrize("light_kind", ["distant", "point"])
def test_parallel_edges_on_two_depth_layers(light_kind):
    """Panels scene (a squares panel 0.1 in front of the squares back plane): the near and
    far groups are the two layers; the orthographic dual keeps the edges parallel and the
    layers' magnifications equal (exact coordinates), the perspective dual magnifies the
    near layer by about the depth ratio."""
    from shadowcam.cameras.accuracy import parallel_edges
    from shadowcam.synthetic.lab.scene import BackPlane, DistantLight
    from shadowcam.synthetic.lab.scenes import make_scene

    scene = make_scene("panels", seed=3, height=64, width=64, frames=48, light_kind=light_kind)
    planes = [o for o in scene.objects if isinstance(o, BackPlane)]
    assert len(planes) == 2
    edges = square_edge_points(scene)
    ok = edges.lit
    on_near = np.abs((edges.world - planes[1].center) @ planes[1].normal) < 1e-9
    assert on_near[ok].sum() >= 20 and (~on_near[ok]).sum() >= 20  # edges on both layers
    light = scene.light
    distant = isinstance(light, DistantLight)
    toward = light.direction if distant else light.center - edges.world[ok].mean(axis=0)
    found = parallel_edges(edges.dual_uv[ok], edges.world[ok], edges.label[ok],
                           toward_light=toward, light_position=None if distant else light.center)
    assert found["n_families"] == 2 and found["size_edges"] >= 8
    assert found["spread_se_deg"] < 1e-6  # exact points: no residual across the lines
    if distant:
        assert found["spread_deg"] < 1e-6 and abs(found["size_ratio"] - 1) < 1e-9
    else:
        assert found["spread_deg"] > 2.0
        assert found["depth_ratio"] > 1.2 and abs(found["size_ratio"] / found["depth_ratio"] - 1) < 0.05


def test_line_direction_standard_error_matches_the_scatter_of_fits():
    """The direction's standard error of a line fit equals the scatter of the fitted angle
    over noisy draws (1000 draws of 30 points, sigma 0.3 px, 30 px long): within 10%."""
    from shadowcam.cameras.accuracy import _robust_line

    rng = np.random.default_rng(5)
    t = np.linspace(-15, 15, 30)
    angles, errors = [], []
    for _ in range(1000):
        pts = np.stack([t, 0.3 * rng.standard_normal(30)], axis=1)
        _, direction, se = _robust_line(pts, k=1e9)
        angles.append(np.arctan(direction[1] / direction[0]))
        errors.append(se)
    expected = 0.3 / np.sqrt(np.sum(t**2))
    np.testing.assert_allclose(np.std(angles), expected, rtol=0.1)
    np.testing.assert_allclose(np.sqrt(np.mean(np.square(errors))), expected, rtol=0.1)


def test_two_depth_groups_split_layers_at_their_gap():
    from shadowcam.cameras.accuracy import _two_depth_groups

    depth = np.array([0.31, 0.30, 0.52, 0.29, 0.50, 0.55, 0.51, 0.33])
    np.testing.assert_array_equal(_two_depth_groups(depth), depth < 0.4)
    assert _two_depth_groups(np.arange(10.0)).sum() == 5  # a continuous range: its middle
