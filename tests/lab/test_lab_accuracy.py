"""Tests of shadowcam.lab.accuracy on constructed inputs with known errors."""

import csv
import io
import json

import numpy as np
import pytest
import xarray as xr

from shadowcam.lab.accuracy import (
    accuracy_report,
    check_targets,
    dual_coord_errors,
    dual_image_errors,
    report_to_csv,
    report_to_json,
    shadow_time_errors,
)
from shadowcam.cameras.dual_coords import dual_coords_dataset, dual_coords_uniform
from shadowcam.cameras.dual_view import dual_view_dataset, resample_dual_view



def _truth(rows=40, cols=50, seed=0):
    rng = np.random.default_rng(seed)
    truth = rng.uniform(0, 95, (rows, cols))
    lit = np.ones((rows, cols), bool)
    lit[:4] = False  # unlit band
    truth[~lit] = np.nan
    truth[4:6, :10] = np.nan  # lit but outside the sweep: no GT time
    return truth, lit


def test_shadow_time_errors_known_offsets():
    truth, lit = _truth()
    est = truth.copy()
    has = lit & np.isfinite(truth)
    idx = np.flatnonzero(has)
    est.flat[idx[:100]] += 2.0  # 100 pixels 2 frames off
    est.flat[idx[100:150]] = np.nan  # 50 pixels without estimate
    est[0, :5] = 10.0  # 5 unlit pixels given a time
    out = shadow_time_errors(est, truth, lit=lit)
    n = has.sum()
    assert out["n_truth"] == n and out["n_evaluated"] == n - 50
    assert out["coverage"] == pytest.approx((n - 50) / n)
    assert out["frac_gt_1_frame"] == pytest.approx(100 / (n - 50))
    assert out["rmse"] == pytest.approx(np.sqrt(4 * 100 / (n - 50)))
    assert out["median"] == 0.0 and out["max"] == pytest.approx(2.0)
    assert out["false_time_rate"] == pytest.approx(5 / (~lit).sum())
    # lit pixels the shadow does not cross in the sweep: 20, none timed yet
    assert out["n_unswept"] == 20 and out["unswept_time_rate"] == 0.0
    est[4, :3] = 0.1  # 3 of them given a time
    assert shadow_time_errors(est, truth, lit=lit)["unswept_time_rate"] == pytest.approx(3 / 20)


def test_targets_pass_fail_per_noise_condition():
    truth, lit = _truth()
    rng = np.random.default_rng(1)
    est = truth + rng.normal(0, 0.1, truth.shape)  # p95 |N(0, 0.1)| = 0.196
    report = {"shadow_time": {"u": shadow_time_errors(est, truth, lit=lit)}}
    by_name = {t["target"]: t for t in check_targets(report, noise="noise_free")}
    assert not by_name["shadow_time_p95_frames"]["pass"]  # 0.196 > 0.1
    assert by_name["shadow_time_coverage"]["pass"] and by_name["false_time_rate"]["pass"]
    by_name = {t["target"]: t for t in check_targets(report, noise="raw12")}
    assert by_name["shadow_time_p95_frames"]["pass"]  # 0.196 <= 0.3
    assert by_name["shadow_time_p95_frames"]["value"] == pytest.approx(1.96 * 0.1, rel=0.1)


def test_dual_coord_errors_known_shift():
    tu, tv = np.meshgrid(np.arange(20.0), np.arange(10.0))
    out = dual_coord_errors(tu + 0.3, tv - 0.4, tu, tv)
    assert out["rmse"] == pytest.approx(0.5) and out["median"] == pytest.approx(0.5)
    assert out["rmse_u"] == pytest.approx(0.3) and out["coverage"] == 1.0


def test_dual_image_gain_fit_and_whole_image_holes():
    rng = np.random.default_rng(2)
    ref = rng.uniform(0.2, 1.0, (30, 30, 3))
    est = 0.5 * ref  # wrong exposure only: the gain fit removes it
    cov = np.ones((30, 30), bool)
    cov[:3] = False  # holes
    est[~cov] = np.nan
    vis = np.ones((30, 30), bool)
    out = dual_image_errors(est, cov, ref, dual_cam_visible=vis)
    assert out["gain"] == pytest.approx(2.0)
    assert out["rel_rmse_masked"] == pytest.approx(0.0, abs=1e-12)
    # whole image: holes count as zero -> error = energy of the missing rows
    expect = np.sqrt(np.sum(ref[:3] ** 2) / np.sum(ref**2))
    assert out["rel_rmse_whole"] == pytest.approx(expect)
    assert out["coverage_of_visible"] == pytest.approx(0.9)


def test_report_end_to_end_and_serialisation(tmp_path):
    truth_u, lit = _truth(seed=3)
    truth_v, _ = _truth(seed=4)
    truth_v[np.isnan(truth_u)] = np.nan
    st = xr.Dataset({"shadow_time": (("sweep", "row", "col"), np.stack([truth_u, truth_v + 0.05]))},
                    coords={"sweep": ["u", "v"]})
    gt = xr.Dataset({
        "t_u": (("row", "col"), truth_u), "t_v": (("row", "col"), truth_v),
        "lit": (("row", "col"), lit),
        "reciprocal": (("v", "u", "channel"), np.ones((96, 96, 3))),
        "dual_cam_visible": (("v", "u"), np.ones((96, 96), bool)),
    })
    u, v, valid, info = dual_coords_uniform(st["shadow_time"][0].values, st["shadow_time"][1].values,
                                            n_frames=(96, 96))
    dc = dual_coords_dataset(u, v, valid, info=info, method="uniform")
    dv = dual_view_dataset(np.full((96, 96, 3), 3.0, np.float32), np.ones((96, 96), bool),
                           method="mesh")
    report = accuracy_report(st, gt, dual_coords=dc, dual_view=dv, noise="noise_free")
    assert report["shadow_time"]["u"]["p95"] == 0.0
    assert report["shadow_time"]["v"]["median"] == pytest.approx(0.05, abs=1e-5)
    assert report["dual_coords"]["rmse"] == pytest.approx(0.05, abs=1e-4)
    assert report["dual_image"]["gain"] == pytest.approx(1 / 3)
    assert report["all_targets_pass"]  # 0.05 frame error < 0.1, full coverage, no false times
    parsed = json.loads(report_to_json(report))
    assert parsed["dual_image"]["rel_rmse_masked"] == pytest.approx(0.0, abs=1e-7)
    table = list(csv.DictReader(io.StringIO(report_to_csv(report))))
    assert list(table[0]) == ["quantity", "value", "unit", "target", "pass"]
    quantities = [row["quantity"] for row in table]
    assert len(quantities) == len(set(quantities))  # one row per quantity, targets included
    rows = {row["quantity"]: row for row in table}
    median = rows["shadow time |error| median, sweep v"]
    assert (median["value"], median["unit"]) == ("0.05", "frame")
    p95 = rows["shadow time |error| p95, sweep u"]
    assert (p95["target"], p95["pass"]) == ("<= 0.1", "yes")
    coverage = rows["shadow time coverage, sweep u"]
    assert (coverage["value"], coverage["unit"], coverage["target"]) == ("100", "%", ">= 98")
    assert all(row["unit"] or row["quantity"] in ("dual model", "noise condition", "all targets pass", "dataset")
               for row in table)
    assert rows["dual model"]["value"].startswith("uniform")  # the model the dual view was made with, and why
    mantissas = [row["value"].split("e")[0].replace("-", "").replace(".", "").lstrip("0") for row in table
                 if row["value"][:1].isdigit() and "." in row["value"]]
    assert mantissas and all(len(m) <= 3 for m in mantissas)  # three significant digits at most


def test_exact_gt_coordinates_give_the_dual_image_floor(shared_data):
    # exact times -> exact dual coords; the remaining dual-image error is the floor of
    # resampling + the near-light photometry (README 1.7) that a gain cannot remove
    gt = np.load(shared_data / "lab-dev" / "dev_spheres" / "gt.npz")
    img, cov = resample_dual_view(gt["reference_linear"], gt["t_u"], gt["t_v"], shape=(96, 96))
    out = dual_image_errors(img, cov, gt["reciprocal"], dual_cam_visible=gt["dual_cam_visible"])
    ratio = (gt["cos_C"] / gt["dist_C"] ** 2) / (gt["cos_L"] / gt["dist_L"] ** 2)
    img_c, cov_c = resample_dual_view(gt["reference_linear"] * ratio[..., None], gt["t_u"],
                                      gt["t_v"], shape=(96, 96))
    corr = dual_image_errors(img_c, cov_c, gt["reciprocal"], dual_cam_visible=gt["dual_cam_visible"])
    assert corr["rel_rmse_masked"] < out["rel_rmse_masked"]  # photometry explains part of it
    assert corr["rel_rmse_masked"] < 0.10
    assert out["rel_rmse_whole"] > out["rel_rmse_masked"]  # holes add error


def test_calibration_dual_grid_is_compared_like_for_like():
    # the calibration plane is reached from the mask plane (GT times) by a known
    # homography; exact times must give exact dual coordinates on the plane-window
    # grid, and a dual view sampled there must match the reciprocal resampled onto it
    from shadowcam.cameras.dual_coords import apply_homography, dual_coords_calibration

    times_to_plane = np.array([[0.0105, 0.0011, -0.31], [-0.0013, 0.0098, -0.24],
                               [0.004, -0.003, 1.0]])
    cam_to_plane = np.array([[0.011, 0.0012, -0.3], [-0.0009, 0.0105, -0.25], [1e-4, 2e-4, 1.0]])
    rows, cols = 48, 64
    r, c = np.mgrid[0:rows, 0:cols]
    plane_xy = apply_homography(cam_to_plane, np.column_stack([c.ravel(), r.ravel()]).astype(float))
    cal_t = apply_homography(np.linalg.inv(times_to_plane), plane_xy).reshape(rows, cols, 2)
    scene_t = cal_t + np.random.default_rng(5).uniform(-1.5, 1.5, cal_t.shape)
    window = (-0.3, -0.25, 0.5, 0.35)
    u, v, valid, reason, info = dual_coords_calibration(
        scene_t[..., 0], scene_t[..., 1], cal_t_u=cal_t[..., 0], cal_t_v=cal_t[..., 1],
        homography=cam_to_plane, dual_shape=(30, 40), plane_window=window,
        extrapolation_margin=1e9)
    dual_coords = dual_coords_dataset(u, v, valid, info=info, method="calibration", reason=reason)

    def scene_colour(t_u, t_v):
        return np.stack([1 + 0.5 * np.sin(t_u / 7) * np.cos(t_v / 9)] * 3, axis=-1)

    n = 96  # reciprocal grid: centre of column i is t_u = i
    tv, tu = np.mgrid[0:n, 0:n].astype(float)
    gt = xr.Dataset({
        "t_u": (("row", "col"), scene_t[..., 0]), "t_v": (("row", "col"), scene_t[..., 1]),
        "lit": (("row", "col"), np.ones((rows, cols), bool)),
        "t_cal_u": (("row", "col"), cal_t[..., 0]), "t_cal_v": (("row", "col"), cal_t[..., 1]),
        "plane_xy": (("row", "col", "plane_axis"), plane_xy.reshape(rows, cols, 2)),
        "reciprocal": (("v", "u", "channel"), scene_colour(tu, tv)),
        "dual_cam_visible": (("v", "u"), np.ones((n, n), bool)),
    })
    # the dual view a perfect pipeline gives: the scene colour at each grid centre's plane point
    j, i = np.mgrid[0:30, 0:40].astype(float)
    x = window[0] + (i + 0.5) * (window[2] - window[0]) / 40
    y = window[1] + (j + 0.5) * (window[3] - window[1]) / 30
    t = apply_homography(np.linalg.inv(times_to_plane), np.column_stack([x.ravel(), y.ravel()]))
    image = scene_colour(t[:, 0], t[:, 1]).reshape(30, 40, 3)
    dual_view = xr.Dataset({"dual_view": (("v", "u", "channel"), image),
                            "coverage": (("v", "u"), np.ones((30, 40), bool))})
    shadow_time = xr.Dataset({"shadow_time": (("sweep", "row", "col"),
                                              np.moveaxis(scene_t, -1, 0).astype(np.float32))},
                             coords={"sweep": ["u", "v"]})
    report = accuracy_report(shadow_time, gt, dual_coords=dual_coords, dual_view=dual_view)
    assert report["dual_coords"]["coverage"] == 1.0
    assert report["dual_coords"]["max"] < 1e-3  # float32 coordinates of ~40 px
    assert report["dual_image"]["n_mask"] > 0.9 * 30 * 40
    assert report["dual_image"]["rel_rmse_masked"] < 5e-3  # bilinear resampling only


def test_noise_condition_explicit_then_declared_then_synthetic_then_default():
    from shadowcam.lab.accuracy import noise_condition

    assert noise_condition({"ground_truth": {"noise": "raw12"}}, "noise_free") == ("noise_free", "--params")
    assert noise_condition({"ground_truth": {"noise": "raw12"}, "synthetic": {"noise": False}}) == (
        "raw12", "manifest ground_truth.noise")
    assert noise_condition({"synthetic": {"noise": True}}) == ("raw12", "manifest synthetic.noise")
    assert noise_condition({"synthetic": {"noise": False}}) == ("noise_free", "manifest synthetic.noise")
    assert noise_condition({}) == ("noise_free", "default")
def test_pushbroom_errors_against_the_exact_time_assembly():
    from shadowcam.cameras.pushbroom import assemble_pushbroom, edge_from_time_map
    from shadowcam.lab.accuracy import pushbroom_errors

    rng = np.random.default_rng(5)
    truth_time = np.tile(0.5 * np.arange(24.0), (10, 1))  # vertical wire: time grows along columns
    reference = rng.uniform(0.2, 1.0, (10, 24, 3))
    exact = assemble_pushbroom(reference, edge_from_time_map(truth_time, np.arange(12), along="row"), along="row")
    perfect = pushbroom_errors(3.0 * exact, truth_time, reference, along="row")
    assert perfect["rel_rmse"] < 1e-12 and perfect["gain"] == pytest.approx(1 / 3)
    assert perfect["coverage"] == 1.0 and perfect["n_evaluated"] == np.isfinite(exact[..., 0]).sum()
    half = exact.copy()
    half[:, :5] = np.nan
    assert pushbroom_errors(half, truth_time, reference, along="row")["coverage"] == pytest.approx(0.5)
    late = assemble_pushbroom(reference, edge_from_time_map(truth_time - 1.0, np.arange(12), along="row"),
                              along="row")
    assert pushbroom_errors(late, truth_time, reference, along="row")["rel_rmse"] > 0.1
    with pytest.raises(ValueError, match="pushbroom must have the shape"):
        pushbroom_errors(exact[:, :5], truth_time, reference, along="row")


def test_accuracy_table_has_the_interval_and_viewpoint_rows():
    """Entry late by 0.2, exit late by 0.4 frame on every pixel: centre late by 0.3; the
    viewpoint rows carry their dual-image scores (or why they were skipped)."""
    from shadowcam.lab.accuracy import accuracy_table, interval_errors

    rows, cols = 6, 8
    true_entry = np.tile(np.arange(cols, dtype=float) + 10.0, (rows, 1))
    true_exit = true_entry + 3.0
    lit = np.ones((rows, cols), bool)
    lit[0] = False  # an unlit row is not counted
    gt = xr.Dataset({"lit": (("row", "col"), lit),
                     "interval_entry_u": (("row", "col"), true_entry),
                     "interval_exit_u": (("row", "col"), true_exit)})
    st = xr.Dataset({"interval_entry": (("sweep", "row", "col"), (true_entry + 0.2)[None]),
                     "interval_exit": (("sweep", "row", "col"), (true_exit + 0.4)[None])},
                    coords={"sweep": ["u"]}, attrs={"n_frames_u": 40})
    report = {"interval": interval_errors(st, gt),
              "viewpoints": {"entry": {"rel_rmse_masked": 0.25, "coverage_of_visible": 0.8, "n_mask": 300},
                             "exit": {"skipped": "no reciprocal render"}},
              "targets": [], "noise": "noise_free", "all_targets_pass": True}
    table = {row["quantity"]: row for row in csv.DictReader(io.StringIO(report_to_csv(report)))}
    assert len(table) == len(accuracy_table(report))  # one row per quantity
    assert table["dip interval: pixels whose whole dip lies in the sweep, sweep u"]["value"] == "40"
    assert (table["dip interval coverage, sweep u"]["value"], table["dip interval coverage, sweep u"]["unit"]) \
        == ("100", "%")
    for part, error in (("entry", 0.2), ("centre", 0.3), ("exit", 0.4)):
        for stat in ("median", "p95", "RMSE", "max"):
            row = table[f"dip interval {part} |error| {stat}, sweep u"]
            assert float(row["value"]) == pytest.approx(error, abs=1e-9) and row["unit"] == "frame"
    entry = table["dual view relative RMSE, GT valid mask, viewpoint entry"]
    assert (entry["value"], entry["unit"]) == ("25", "%")
    assert table["dual view coverage of what the camera sees, viewpoint entry"]["value"] == "80"
    assert table["dual pixels in the GT valid mask, viewpoint entry"]["value"] == "300"
    assert table["dual view, viewpoint exit"]["value"] == "skipped: no reciprocal render"


def test_uncertain_times_are_counted_and_stay_in_the_score():
    truth = np.arange(20, dtype=float).reshape(4, 5)
    estimate = truth + 0.01
    estimate[0, :2] += 2.0  # two wrong times that say so
    std = np.full((4, 5), 0.05)
    std[0, :2] = 1.0
    lit = np.ones((4, 5), bool)
    out = shadow_time_errors(estimate, truth, lit=lit, time_std=std)
    assert out["n_evaluated"] == 20 and out["n_uncertain"] == 2
    assert out["p95_confident"] == pytest.approx(0.01, abs=1e-9)
    assert out["p95"] == pytest.approx(np.percentile(np.abs(estimate - truth), 95))
    assert "n_uncertain" not in shadow_time_errors(estimate, truth, lit=lit)
    with pytest.raises(ValueError, match="time_std"):
        shadow_time_errors(estimate, truth, lit=lit, time_std=std[:2])


def test_interval_errors_score_the_penumbras_outer_edges():
    """First contact early by 0.1, last release late by 0.3 frame, one pixel without them."""
    from shadowcam.lab.accuracy import accuracy_table, interval_errors

    rows, cols = 4, 5
    true_entry = np.tile(np.arange(cols, dtype=float) + 10.0, (rows, 1))
    true_exit, true_first, true_last = true_entry + 8.0, true_entry - 4.0, true_entry + 12.0
    gt = xr.Dataset({"lit": (("row", "col"), np.ones((rows, cols), bool)),
                     "interval_entry_u": (("row", "col"), true_entry), "interval_exit_u": (("row", "col"), true_exit),
                     "penumbra_first_u": (("row", "col"), true_first), "penumbra_last_u": (("row", "col"), true_last)})
    first = true_first - 0.1
    first[0, 0] = np.nan
    st = xr.Dataset({"interval_entry": (("sweep", "row", "col"), true_entry[None]),
                     "interval_exit": (("sweep", "row", "col"), true_exit[None]),
                     "penumbra_first": (("sweep", "row", "col"), first[None]),
                     "penumbra_last": (("sweep", "row", "col"), (true_last + 0.3)[None])},
                    coords={"sweep": ["u"]}, attrs={"n_frames_u": 40})
    stats = interval_errors(st, gt)["u"]
    assert stats["n_outer_truth"] == 20 and stats["outer_coverage"] == pytest.approx(19 / 20)
    assert stats["first"]["p95"] == pytest.approx(0.1) and stats["last"]["max"] == pytest.approx(0.3)
    table = {row["quantity"]: row for row in accuracy_table({"interval": {"u": stats}})}
    assert table["penumbra first |error| p95, sweep u"]["unit"] == "frame"
    assert table["penumbra outer edges coverage, sweep u"]["value"] == "95"
    # without the law's edges in the shadow times: no outer rows
    assert "first" not in interval_errors(st.drop_vars(["penumbra_first", "penumbra_last"]), gt)["u"]
    # a source never half hidden (a wire narrower than it): no half-depth truth, the outer edges scored
    never = gt.assign(interval_entry_u=gt["interval_entry_u"] * np.nan, interval_exit_u=gt["interval_exit_u"] * np.nan)
    stats = interval_errors(st, never)["u"]
    assert stats["n_truth"] == 0 and stats["n_outer_truth"] == 20 and stats["first"]["p95"] == pytest.approx(0.1)
