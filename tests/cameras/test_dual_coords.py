"""Tests of shadowcam.cameras.dual_coords: uniform model and calibration-plane fit."""

import json

import numpy as np
import pytest

from shadowcam.cameras.dual_coords import (
    DUAL_COORD_METHODS,
    DUAL_COORD_MODELS,
    apply_homography,
    dual_coords_calibration,
    dual_coords_dataset,
    dual_coords_uniform,
    fit_time_to_plane,
)

# camera (col, row) -> plane (x, y): a mildly projective view of the plane
CAM_TO_PLANE = np.array([[0.011, 0.0012, -0.3], [-0.0009, 0.0105, -0.25], [1e-4, 2e-4, 1.0]])


def _plane_points(rows=48, cols=64):
    r, c = np.mgrid[0:rows, 0:cols]
    xy = apply_homography(CAM_TO_PLANE, np.column_stack([c.ravel(), r.ravel()]).astype(float))
    return xy.reshape(rows, cols, 2)


def _times_from_plane(xy, time_to_plane):
    """Exact shadow times of plane points when (t_u, t_v) -> (x, y) is `time_to_plane`."""
    flat = xy.reshape(-1, 2)
    t = apply_homography(np.linalg.inv(time_to_plane), flat)
    return t.reshape(xy.shape)


# (t_u, t_v) -> (x, y): affine truth and projective truth (frames 0..~60)
AFFINE_TRUTH = np.array([[0.0105, 0.0011, -0.31], [-0.0013, 0.0098, -0.24], [0.0, 0.0, 1.0]])
PROJECTIVE_TRUTH = np.array([[0.0105, 0.0011, -0.31], [-0.0013, 0.0098, -0.24], [0.004, -0.003, 1.0]])


def test_uniform_default_is_one_dual_pixel_per_frame():
    rng = np.random.default_rng(0)
    t_u = rng.uniform(0, 95, (10, 12)).astype(np.float32)
    t_v = rng.uniform(0, 95, (10, 12)).astype(np.float32)
    t_u[0, 0] = np.nan
    u, v, valid, info = dual_coords_uniform(t_u, t_v, n_frames=(96, 96))
    assert u.dtype == np.float32
    np.testing.assert_array_equal(u[valid], t_u[valid])
    np.testing.assert_array_equal(v[valid], t_v[valid])
    assert not valid[0, 0] and np.isnan(u[0, 0])
    assert (info["dual_width"], info["dual_height"]) == (96, 96)


def test_uniform_stretch_maps_frame_edges_to_grid_edges():
    t_u = np.array([[-0.5, 95.5, 47.5]], dtype=np.float32)
    t_v = np.array([[-0.5, 95.5, 10.0]], dtype=np.float32)
    u, v, valid, info = dual_coords_uniform(t_u, t_v, n_frames=(96, 96), dual_shape=(48, 192),
                                            min_spread=0)
    np.testing.assert_allclose(u[0, :2], [-0.5, 191.5], atol=1e-5)
    np.testing.assert_allclose(v[0, :2], [-0.5, 47.5], atol=1e-5)
    np.testing.assert_allclose(u[0, 2], 95.5, atol=1e-5)  # the middle stays in the middle


def test_uniform_flags_parallel_sweeps():
    t = np.linspace(0, 90, 200).reshape(10, 20)
    with pytest.raises(ValueError, match="collinear"):
        dual_coords_uniform(t, 0.5 * t + 3 + 1e-3 * np.sin(t), n_frames=(96, 96))


def test_uniform_names_a_sweep_whose_times_never_change():
    t = np.linspace(0, 90, 200).reshape(10, 20)
    with pytest.raises(ValueError, match="sweep v .* too short"):
        dual_coords_uniform(t, np.full_like(t, 2.0), n_frames=(96, 5))


@pytest.mark.parametrize("truth, expected", [(AFFINE_TRUTH, "affine"),
                                             (PROJECTIVE_TRUTH, "homography")])
def test_calibration_fit_picks_simplest_sufficient_model(truth, expected):
    xy = _plane_points().reshape(-1, 2)
    times = _times_from_plane(xy, truth)
    fit = fit_time_to_plane(times, xy, unit_scale=0.01)
    assert fit.name == expected
    names = [c["name"] for c in fit.candidates]
    assert names == ["affine", "homography", "tps"]
    assert sum(c["chosen"] for c in fit.candidates) == 1
    assert fit.residual_rms < 1e-6  # exact data: exact recovery (in 0.01-plane units)
    if expected == "homography":
        affine = next(c for c in fit.candidates if c["name"] == "affine")
        assert affine["cv_rms"] > 0.1  # the projective part is visible to the affine model
    np.testing.assert_allclose(fit.model.matrix / fit.model.matrix[2, 2], truth, rtol=1e-7,
                               atol=1e-10)


def test_calibration_end_to_end_recovers_plane_window_coordinates():
    cal_xy = _plane_points()
    cal_t = _times_from_plane(cal_xy, PROJECTIVE_TRUTH)
    # scene: other times inside the calibrated range
    rng = np.random.default_rng(3)
    scene_xy = cal_xy + rng.uniform(-0.02, 0.02, cal_xy.shape)
    scene_t = _times_from_plane(scene_xy, PROJECTIVE_TRUTH)
    window = (-0.3, -0.25, 0.5, 0.35)
    u, v, valid, reason, info = dual_coords_calibration(
        scene_t[..., 0], scene_t[..., 1], cal_t_u=cal_t[..., 0], cal_t_v=cal_t[..., 1],
        homography=CAM_TO_PLANE, dual_shape=(60, 80), plane_window=window,
        extrapolation_margin=1e9)
    assert info["model"] == "homography"
    assert valid.all() and (reason == 0).all()
    exp_u = (scene_xy[..., 0] - window[0]) / 0.01 - 0.5
    exp_v = (scene_xy[..., 1] - window[1]) / 0.01 - 0.5
    np.testing.assert_allclose(u, exp_u, atol=1e-3)  # float32 output of ~80 px
    np.testing.assert_allclose(v, exp_v, atol=1e-3)
    ds = dual_coords_dataset(u, v, valid, info=info, method="calibration", reason=reason)
    assert ds.attrs["model"] == "homography"
    assert [c["name"] for c in json.loads(ds.attrs["candidates"])] == ["affine", "homography", "tps"]
    assert ds["u"].dims == ("row", "col") and ds["u"].dtype == np.float32


def test_calibration_marks_extrapolated_scene_times():
    cal_xy = _plane_points()
    cal_t = _times_from_plane(cal_xy, AFFINE_TRUTH)
    scene_t = cal_t.copy()
    scene_t[0, 0, 0] = cal_t[..., 0].max() + 20  # far outside the calibrated range
    u, v, valid, reason, _ = dual_coords_calibration(
        scene_t[..., 0], scene_t[..., 1], cal_t_u=cal_t[..., 0], cal_t_v=cal_t[..., 1],
        homography=CAM_TO_PLANE, dual_shape=(50, 50))
    assert reason[0, 0] == 2 and not valid[0, 0] and np.isnan(u[0, 0])
    assert valid.sum() == valid.size - 1


def test_too_few_calibration_points_raise():
    xy = _plane_points()[:2, :3].reshape(-1, 2)[:7]  # 7 points < 6 + 2
    with pytest.raises(ValueError, match="too few"):
        fit_time_to_plane(_times_from_plane(xy, AFFINE_TRUTH), xy)


def test_collinear_calibration_points_raise():
    xy = _plane_points()[10].reshape(-1, 2)  # one camera row: points on a line of the plane
    xy = np.column_stack([xy[:, 0], 0.3 * xy[:, 0] + 0.1])
    with pytest.raises(ValueError, match="collinear"):
        fit_time_to_plane(_times_from_plane(xy, AFFINE_TRUTH), xy)


def test_nearly_parallel_sweeps_raise():
    xy = _plane_points().reshape(-1, 2)
    # sweep directions on the plane 5 degrees apart: t_u = x / d, t_v = (x cos5 + y sin5) / d
    angle = np.radians(5.0)
    t = np.column_stack([xy[:, 0], xy[:, 0] * np.cos(angle) + xy[:, 1] * np.sin(angle)]) / 0.01
    with pytest.raises(ValueError, match="parallel"):
        fit_time_to_plane(t, xy, min_spread=0.0)  # the angle check, not the spread check
    with pytest.raises(ValueError, match="collinear"):
        fit_time_to_plane(t, xy, min_spread=0.2)


def test_tables():
    assert list(DUAL_COORD_MODELS) == ["affine", "homography", "tps"]
    assert [m.n_params for m in DUAL_COORD_MODELS.values()] == sorted(
        m.n_params for m in DUAL_COORD_MODELS.values())
    assert set(DUAL_COORD_METHODS) == {"uniform", "calibration"}


def _shadow_time_dataset(t_u, t_v, n_frames=(20, 10), cal=False):
    import xarray as xr

    sweeps = ["u", "v"] + (["cal_u", "cal_v"] if cal else [])
    stack = np.stack([t_u, t_v] + ([t_u, t_v] if cal else []))
    return xr.Dataset({"shadow_time": (("sweep", "row", "col"), stack)}, coords={"sweep": sweeps},
                      attrs={"n_frames_u": n_frames[0], "n_frames_v": n_frames[1]})


def test_front_function_uniform_motion_maps_frames_to_dual_pixels():
    from shadowcam.cameras.dual_coords import choose_dual_coords_method, dual_coords_from_shadow_time

    rows, cols = np.mgrid[0:6, 0:8].astype(np.float32)
    shadow_time = _shadow_time_dataset(cols * 2.0, rows, n_frames=(20, 10))
    assert choose_dual_coords_method(shadow_time, "auto", homography=np.eye(3)) == "uniform"
    dataset = dual_coords_from_shadow_time(shadow_time, method="uniform")
    assert (dataset.attrs["dual_width"], dataset.attrs["dual_height"]) == (20, 10)
    np.testing.assert_allclose(dataset["u"].values, cols * 2.0)
    np.testing.assert_allclose(dataset["v"].values, rows)
    narrow = dual_coords_from_shadow_time(shadow_time, method="uniform", dual_width=10)
    # half the grid: frame edges -0.5 .. 19.5 map onto dual edges -0.5 .. 9.5
    np.testing.assert_allclose(narrow["u"].values, (cols * 2.0 + 0.5) / 2 - 0.5, atol=1e-5)


def test_front_function_refuses_what_it_cannot_do():
    from shadowcam.cameras.dual_coords import choose_dual_coords_method, dual_coords_from_shadow_time

    shadow_time = _shadow_time_dataset(np.zeros((3, 3)), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="cal_u"):
        choose_dual_coords_method(shadow_time, "calibration", homography=np.eye(3))
    assert choose_dual_coords_method(_shadow_time_dataset(np.zeros((3, 3)), np.zeros((3, 3)), cal=True),
                                     homography=np.eye(3)) == "calibration"
    with pytest.raises(ValueError, match="n_frames"):
        dual_coords_from_shadow_time(shadow_time.assign_attrs(n_frames_u=0))
    with pytest.raises(ValueError, match="cal_u"):
        dual_coords_from_shadow_time(shadow_time, method="calibration", homography=np.eye(3))


def _calibration_capture(warp):
    """Scene = calibration plane; times from PROJECTIVE_TRUTH, warped by `warp`, noise 0.1 frame."""
    import xarray as xr

    times = _times_from_plane(_plane_points(), PROJECTIVE_TRUTH)
    times = warp(times) + np.random.default_rng(5).normal(0.0, 0.1, times.shape)
    t_u, t_v = times[..., 0], times[..., 1]
    stack = np.stack([t_u, t_v, t_u, t_v]).astype(np.float32)
    return xr.Dataset({"shadow_time": (("sweep", "row", "col"), stack)},
                      coords={"sweep": ["u", "v", "cal_u", "cal_v"]},
                      attrs={"n_frames_u": 96, "n_frames_v": 96})


def test_uniform_motion_is_chosen_when_the_calibration_plane_is_projective_within_noise():
    from shadowcam.cameras.dual_coords import dual_coords_from_shadow_time

    shadow_time = _calibration_capture(lambda t: t)
    dataset = dual_coords_from_shadow_time(shadow_time, method="calibration", homography=CAM_TO_PLANE)
    assert dataset.attrs["model"] == "uniform" and dataset.attrs["method"] == "uniform"
    t_u = shadow_time["shadow_time"].sel(sweep="u").values
    np.testing.assert_allclose(dataset["u"].values, t_u, atol=1e-5)  # frame index = dual column
    names = [c["name"] for c in json.loads(dataset.attrs["candidates"])]
    assert names[0] == "uniform" and "tps" in names
    assert "uniform" in dataset.attrs["model_choice"] and "tps" in dataset.attrs["model_choice"]


def test_calibration_plane_is_chosen_when_the_sweep_speed_is_not_uniform():
    from shadowcam.cameras.dual_coords import dual_coords_from_shadow_time

    # the wire accelerates: frame index is no longer proportional to mask position
    shadow_time = _calibration_capture(lambda t: t + 4.0 * np.sin(np.pi * t / 40.0))
    dataset = dual_coords_from_shadow_time(shadow_time, method="calibration", homography=CAM_TO_PLANE)
    assert dataset.attrs["method"] == "calibration" and dataset.attrs["model"] == "tps"
    candidates = {c["name"]: c for c in json.loads(dataset.attrs["candidates"])}
    assert candidates["homography"]["cv_rms"] > 3 * candidates["tps"]["cv_rms"]
    assert "tps" in dataset.attrs["model_choice"]


def test_front_function_fails_when_no_pixel_keeps_a_shadow_time():
    from shadowcam.cameras.dual_coords import dual_coords_from_shadow_time

    rows, cols = np.mgrid[0:6, 0:8].astype(np.float32)
    shadow_time = _shadow_time_dataset(cols * 2.0, rows, n_frames=(20, 10))
    shadow_time["confidence"] = shadow_time["shadow_time"] * 0 + 0.9
    # confidence lies in [0, 1]: a threshold of 5 leaves no pixel
    with pytest.raises(ValueError, match=r"0 of 48 camera pixels with dual coordinates .*48 without a shadow "
                                         r"time in sweep u.*min_confidence is 5"):
        dual_coords_from_shadow_time(shadow_time, method="uniform", min_confidence=5)
    dataset = dual_coords_from_shadow_time(shadow_time, method="uniform", min_confidence=0.5)
    assert dataset["valid"].values.all()
