"""Tests of shadowcam.synthetic.outdoor.truth on hand-made arrival maps (pushbroom definitions)."""

import numpy as np

from shadowcam.io.frame_times import time_to_frame
from shadowcam.synthetic.outdoor.truth import (classify, pushbroom_bins,
                                     pushbroom_edge, sample_rows)


def test_pushbroom_edge_of_a_rising_straight_edge():
    rows, cols = 10, 3
    t = np.arange(8, dtype=float) * 10.0
    # row r (top = 0) loses the sun at time 10 * (rows - r) - 15: lower rows first
    T = np.array([[10.0 * (rows - r) - 15.0] * cols for r in range(rows)])
    T[0] = np.inf     # never shadowed
    T[-1] = -np.inf   # shadowed at start
    sky = np.zeros((rows, cols), bool)
    edge, count, row = pushbroom_edge(T, sky, t)
    # at t = 40: rows with T > 40 are r <= 4 (T = 45 at r = 5? no: 10*(10-5)-15 = 35 <= 40)
    assert row[4, 0] == 4 and count[4, 0] == 1
    f = (T[4, 0] - 40.0) / (T[4, 0] - T[5, 0])
    np.testing.assert_allclose(edge[4], 4 + 0.5 + f)
    assert np.isclose(edge[0, 0], 8 + 0.5 + 0.5)  # lower neighbour shadowed at start: f = 0.5
    ref = np.arange(rows * cols * 3, dtype=float).reshape(rows, cols, 3)
    front = sample_rows(ref, row, edge - row - 0.5, np.isfinite(T[np.maximum(row, 0) + 1, 0]))
    np.testing.assert_allclose(front[4, 0], (1 - f) * ref[4, 0] + f * ref[5, 0])
    np.testing.assert_allclose(front[0, 0], ref[8, 0])  # row v only below a start shadow


def test_classes_bins_and_fractional_frames():
    lit = np.array([[1, 1, 0, 1], [1, 0, 0, 0], [1, 0, 1, 0]], bool).T  # (K=4, N=3)
    first = np.array([2, 1, 1])
    sky = np.array([False, False, True])
    c = classify(lit, first, sky)
    np.testing.assert_array_equal(c["shadow_class"], [3, 3, 0])
    np.testing.assert_array_equal(c["relit_after_arrival"], [True, False, True])
    t = np.array([0.0, 10.0, 30.0])
    np.testing.assert_allclose(time_to_frame([5.0, 20.0, 30.0], t, outside="nan"), [0.5, 1.5, 2.0])
    T = np.array([[5.0, 25.0], [np.inf, 30.0]])
    cls = np.array([[3, 3], [1, 3]])
    ref = np.ones((2, 2, 3))
    ref[0, 1] = 3.0
    mean, count = pushbroom_bins(T, cls, ref, t)
    np.testing.assert_array_equal(count, [[0, 0], [1, 0], [0, 2]])
    np.testing.assert_allclose(mean[2, 1], 2.0)
    assert np.isnan(mean[0, 0]).all()
