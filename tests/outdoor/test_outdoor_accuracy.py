"""Outdoor accuracy statistics and the naive baseline detector."""

import numpy as np
import pytest

from shadowcam.outdoor.accuracy import NaiveBaseline, arrival_errors, check_targets


def test_arrival_errors_in_intervals():
    truth = np.array([[0.0, 100.0, 200.0, 300.0, np.nan]])
    estimate = np.array([[10.0, 100.0, 530.0, np.nan, 5.0]])
    stats = arrival_errors(estimate, truth, evaluate=np.ones_like(truth, bool), interval_s=50.0)
    assert stats["n_evaluated"] == 4 and stats["coverage"] == pytest.approx(0.75)
    assert stats["median_abs"] == pytest.approx(0.2) and stats["max_abs"] == pytest.approx(6.6)
    assert stats["frac_over_5"] == pytest.approx(1 / 3) and stats["frac_within_1"] == pytest.approx(2 / 3)
    targets = check_targets(stats, condition="nuisances")
    assert [t["pass"] for t in targets] == [True, False, False]


def test_naive_baseline_detects_the_first_frame_below_half():
    baseline = NaiveBaseline((1, 2), window=3)
    for t, values in enumerate([[1.0, 1.0], [1.0, 0.6], [0.4, 0.45], [0.1, 0.1]]):
        baseline.update(np.array([[[values[0]] * 3, [values[1]] * 3]]), float(t))
    assert baseline.arrival_s.tolist() == [[2.0, 2.0]]


def test_maps_of_a_shaken_first_frame_are_resampled_into_the_truth_camera():
    # truth: a smooth arrival map in the unshaken camera; the pipeline's map is in the first
    # frame's grid, which shows the truth moved by the first frame's shake (+row, +col)
    from shadowcam.outdoor.accuracy import edges_to_truth_camera, map_to_truth_camera

    rows, cols = np.indices((40, 60), dtype=np.float64)

    def truth(r, c):
        return 100.0 + 3.0 * r + 0.5 * c  # seconds; linear, so bilinear sampling is exact

    dy, dx = 0.7, -0.4
    first_frame_map = truth(rows - dy, cols - dx)
    first_frame_map[10, 10] = np.nan
    back = map_to_truth_camera(first_frame_map, shift_row=dy, shift_col=dx)
    inner = np.isfinite(back)
    assert inner.mean() > 0.9
    np.testing.assert_allclose(back[inner], truth(rows, cols)[inner], atol=1e-9)
    assert np.isnan(back[9:11, 9:12]).sum() >= 1  # the hole spreads to its bilinear neighbours
    # unresampled, the comparison would be off by the shake
    assert np.abs(first_frame_map - truth(rows, cols))[inner].min() > 1.5

    t = np.arange(5, dtype=np.float64)[:, None]
    edge_truth = 20.0 + 0.1 * np.arange(60)[None, :] + t  # (T, W) rows in the truth camera
    c = np.arange(60)[None, :]
    edge_first = 20.0 + 0.1 * (c - dx) + t + dy  # the same edge seen in the first frame
    got = edges_to_truth_camera(edge_first, shift_row=dy, shift_col=dx)
    ok = np.isfinite(got)
    assert ok[:, 1:].all() and not ok[:, 0].any()  # column 0 maps to -0.4: outside
    np.testing.assert_allclose(got[ok], np.broadcast_to(edge_truth, got.shape)[ok], atol=1e-9)


def test_pushbroom_errors_ignore_the_exposure_scale_and_find_colour_errors():
    from shadowcam.outdoor.accuracy import pushbroom_errors

    rng = np.random.default_rng(0)
    truth = rng.uniform(0.1, 1.0, (6, 5, 3))
    truth[0, 0] = np.nan  # no GT there
    exact = pushbroom_errors(3.0 * truth, truth)
    assert exact["n"] == 29 and exact["scale_to_gt"] == pytest.approx(3.0)
    assert exact["median_rel_error"] == pytest.approx(0.0, abs=1e-12)
    off = 3.0 * truth.copy()
    off[..., 0] *= 1.3  # red 30 % too strong
    worse = pushbroom_errors(off, truth)
    assert worse["median_rel_error"] > 0.01
    with pytest.raises(ValueError, match="pushbroom"):
        pushbroom_errors(truth[:3], truth)


def test_accuracy_condition_prefers_the_explicit_one():
    from shadowcam.outdoor.accuracy import accuracy_condition

    assert accuracy_condition({"ground_truth": {"noise": "clean"}}) == "clean"
    assert accuracy_condition({"ground_truth": {"noise": "raw12"}}) == "nuisances"
    assert accuracy_condition({}, "clean") == "clean"
    with pytest.raises(ValueError, match="condition"):
        accuracy_condition({}, "cloudy")


def test_accuracy_table_has_one_row_per_quantity_with_units_and_targets():
    import csv
    import io

    from shadowcam.outdoor.accuracy import report_to_csv

    def stats(median):
        return {"n_evaluated": 100, "coverage": 0.98765, "median_abs": median, "p95_abs": 1.0185755643609078,
                "max_abs": 12.49, "frac_over_5": 0.001047519283877726, "frac_within_1": 0.948, "median_signed": 0.02}

    errors = {name: {"pixel_centre": stats(m), "half_coverage": stats(m)}
              for name, m in (("combined", 0.14241332988455965), ("naive_baseline", 0.88))}
    targets = check_targets(errors["combined"]["pixel_centre"], condition="nuisances")
    report = {"errors": errors, "targets": targets, "all_targets_pass": True, "condition": "nuisances",
              "primary_estimator": "combined", "primary_definition": "pixel_centre", "interval_s": 52.667,
              "n_class3": 100, "false_arrivals": {"combined": {"sky": 0, "never_shadowed": 11}},
              "edge_row": {"n": 10, "median_abs_px": 0.0985, "p95_abs_px": 0.623, "found_fraction": 0.956},
              "dataset": "x"}
    table = list(csv.DictReader(io.StringIO(report_to_csv(report))))
    assert list(table[0]) == ["quantity", "value", "unit", "target", "pass"]
    quantities = [row["quantity"] for row in table]
    assert len(quantities) == len(set(quantities)) <= 40
    rows = {row["quantity"]: row for row in table}
    median = rows["arrival |error| median, combined"]
    assert (median["value"], median["unit"], median["target"], median["pass"]) == (
        "0.142", "interval", "<= 0.5", "yes")
    assert rows["arrival |error| > 5 intervals, combined"]["value"] == "0.105"
    assert rows["arrival |error| > 5 intervals, combined"]["unit"] == "%"
    assert rows["edge row |error| median"]["unit"] == "pixel"
    assert rows["median capture interval"]["value"] == "52.7" and rows["median capture interval"]["unit"] == "s"
