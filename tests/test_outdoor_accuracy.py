"""Outdoor accuracy statistics and the naive baseline detector."""

import numpy as np
import pytest

from shadowcam.outdoor_accuracy import NaiveBaseline, arrival_errors, check_targets


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
