"""Tests of shadowcam.report.outdoor_figures: the arrival map beside its ground truth and error."""

import numpy as np

from shadowcam.report.outdoor_figures import arrival_map_figure


def test_arrival_map_shows_ground_truth_and_error_on_the_same_grid():
    rows = np.arange(40, dtype=np.float64)[:, None] * np.ones((1, 60))
    truth = 600.0 + 30.0 * rows  # the shadow climbs one row per 30 s
    estimate = truth + 15.0
    estimate[30, 10] = truth[30, 10] + 90.0  # one pixel three intervals late
    sky = np.zeros((40, 60), bool)
    sky[:5] = True
    figure = arrival_map_figure(estimate, sky=sky, truth_s=truth, interval_s=30.0)
    panels = [axes for axes in figure.axes if axes.images and axes.get_label() != "<colorbar>"]
    titles = [axes.get_title() for axes in panels]
    assert len(panels) == 3 and "ground truth" in titles[1] and "error" in titles[2]
    shown = [np.ma.asarray(axes.images[0].get_array()) for axes in panels]
    assert all(s.shape == (40, 60) for s in shown)
    np.testing.assert_allclose(shown[1][20, 7], truth[20, 7] / 60.0)  # minutes
    assert shown[2][20, 7] == 0.5 and shown[2][30, 10] == 3.0  # error in capture intervals
    assert shown[2].mask[2, 3]  # sky has no error
