"""Tests of the dip-interval and viewpoint accuracy against exact ground truth."""

import numpy as np
import pytest
import xarray as xr

from shadowcam.lab.accuracy import add_interval_checks, interval_errors, viewpoint_image_errors

ROWS, COLS = 6, 8


def _truth(rng):
    entry = rng.uniform(5, 20, (ROWS, COLS))
    data = {"lit": (("row", "col"), np.ones((ROWS, COLS), bool))}
    for sweep in ("u", "v"):
        data[f"interval_entry_{sweep}"] = (("row", "col"), entry)
        data[f"interval_exit_{sweep}"] = (("row", "col"), entry + 8.0)
    image = rng.uniform(0.1, 1.0, (5, 7, 3))
    data.update(reciprocal_entry=(("v", "u", "channel"), image),
                dual_cam_visible_entry=(("v", "u"), np.ones((5, 7), bool)))
    return xr.Dataset(data)


def _shadow_time(entry, exit_):
    dims = ("sweep", "row", "col")
    zeros = np.zeros((2, ROWS, COLS))
    return xr.Dataset({"interval_entry": (dims, entry), "interval_exit": (dims, exit_), "shadow_time": (dims, zeros),
                       "time_std": (dims, zeros), "confidence": (dims, zeros + 1)},
                      coords={"sweep": ["u", "v"]})


def test_interval_errors_are_the_offsets_and_missing_pixels_lower_the_coverage():
    truth = _truth(np.random.default_rng(0))
    entry = np.stack([truth["interval_entry_u"].values, truth["interval_entry_v"].values])
    exit_ = entry + 8.0
    # sweep u: entry 0.25 late, exit 0.75 early -> centre 0.25 early; one pixel without an interval
    est_entry, est_exit = entry.copy(), exit_.copy()
    est_entry[0] += 0.25
    est_exit[0] -= 0.75
    est_entry[0, 0, 0] = np.nan
    report = interval_errors(_shadow_time(est_entry, est_exit), truth)
    u, v = report["u"], report["v"]
    assert u["n_truth"] == ROWS * COLS and u["coverage"] == pytest.approx(1 - 1 / (ROWS * COLS))
    assert u["entry"]["p95"] == pytest.approx(0.25) and u["exit"]["p95"] == pytest.approx(0.75)
    assert u["centre"]["p95"] == pytest.approx(0.25)
    assert v["coverage"] == 1.0 and v["entry"]["max"] == v["centre"]["max"] == v["exit"]["max"] == 0.0


def test_only_dips_whole_within_the_sweep_are_counted():
    # a dip whose penumbra starts before frame 0 or ends after the last frame has no
    # measurable entry or exit: it is not part of the truth
    truth = _truth(np.random.default_rng(5))
    for sweep in ("u", "v"):
        truth[f"penumbra_first_{sweep}"] = truth[f"interval_entry_{sweep}"] - 3.0
        truth[f"penumbra_last_{sweep}"] = truth[f"interval_exit_{sweep}"] + 3.0
    entry = np.stack([truth["interval_entry_u"].values] * 2)
    shadow_time = _shadow_time(entry, entry + 8.0).assign_attrs(n_frames_u=30, n_frames_v=1000)
    first = truth["penumbra_first_u"].values
    last = truth["penumbra_last_u"].values
    report = interval_errors(shadow_time, truth)
    assert report["u"]["n_truth"] == int(((first >= 0) & (last <= 29)).sum()) < ROWS * COLS
    assert report["v"]["n_truth"] == int((first >= 0).sum())


def test_interval_errors_need_the_interval_pass():
    truth = _truth(np.random.default_rng(1))
    with pytest.raises(ValueError, match="interval_entry"):
        interval_errors(xr.Dataset({"shadow_time": (("sweep", "row", "col"), np.zeros((2, ROWS, COLS)))},
                                   coords={"sweep": ["u", "v"]}), truth)


def test_viewpoint_dual_view_is_scored_against_its_own_reciprocal_after_one_gain():
    truth = _truth(np.random.default_rng(2))
    shadow_time = _shadow_time(np.zeros((2, ROWS, COLS)), np.zeros((2, ROWS, COLS)))
    image = truth["reciprocal_entry"].values
    view = xr.Dataset({"dual_view": (("v", "u", "channel"), 0.5 * image),
                       "coverage": (("v", "u"), np.ones((5, 7), bool))})
    exact = viewpoint_image_errors(truth, "entry", shadow_time=shadow_time, dual_coords=None, dual_view=view)
    assert exact["gain"] == pytest.approx(2.0) and exact["rel_rmse_masked"] == pytest.approx(0.0, abs=1e-12)
    noisy = view.copy()
    noisy["dual_view"] = noisy["dual_view"] * (1 + 0.1 * np.random.default_rng(3).standard_normal(image.shape))
    assert 0.05 < viewpoint_image_errors(truth, "entry", shadow_time=shadow_time, dual_coords=None,
                                         dual_view=noisy)["rel_rmse_masked"] < 0.15
    assert "skipped" in viewpoint_image_errors(truth, "exit", shadow_time=shadow_time, dual_coords=None,
                                               dual_view=view)


def test_add_interval_checks_adds_sections_only_with_their_truth():
    truth = _truth(np.random.default_rng(4))
    entry = np.stack([truth["interval_entry_u"].values] * 2)
    shadow_time = _shadow_time(entry, entry + 8.0)
    report = add_interval_checks({}, shadow_time, truth)
    assert set(report) == {"interval"}
    bare = add_interval_checks({}, shadow_time, truth.drop_vars([k for k in truth if k.startswith("interval_")]))
    assert bare == {}
