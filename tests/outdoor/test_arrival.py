"""Arrival maps: edge crossing and coverage crossing are exact for uniform motion; reasons."""

import numpy as np
import pytest

from shadowcam.outdoor.arrival import REASON_CODE, CoverageCrossing, arrival_from_edges, combine_arrivals


def test_edge_crossing_is_exact_for_a_linearly_moving_edge_with_irregular_times():
    time_s = np.array([0.0, 40.0, 100.0, 130.0, 250.0])
    speed = 0.05  # rows per second
    edge = 12.0 - speed * time_s[:, None] + np.zeros((1, 3))
    eligible = np.ones((14, 3), bool)
    arrival = arrival_from_edges(edge, time_s, eligible=eligible)
    centre = np.arange(14) + 0.5
    truth = np.where((centre < 12.0) & (centre >= 12.0 - speed * 250), (12.0 - centre) / speed, np.nan)
    np.testing.assert_allclose(arrival[:, 0], truth, atol=1e-9)


def test_coverage_crossing_interpolates_linearly_and_keeps_the_first():
    crossing = CoverageCrossing((1, 2), eligible=np.ones((1, 2), bool), confirm=False)
    confirmed = CoverageCrossing((1, 2), eligible=np.ones((1, 2), bool))
    for t, c in [(0.0, [1.0, 1.0]), (10.0, [0.7, 0.2]), (30.0, [0.3, 0.9]), (40.0, [0.0, 0.0])]:
        crossing.update(np.array([c]), t)
        confirmed.update(np.array([c]), t)
    # pixel 0: 0.7 -> 0.3 between 10 s and 30 s crosses 0.5 at 20 s; pixel 1: first drop, 1.0 -> 0.2
    np.testing.assert_allclose(crossing.arrival_s, [[20.0, 10.0 * 0.5 / 0.8]])
    # confirmed: pixel 1's one-frame dip is ignored; its crossing 0.9 -> 0.0 in the last interval is kept
    np.testing.assert_allclose(confirmed.arrival_s, [[20.0, 30.0 + 10.0 * 0.4 / 0.9]])
    with pytest.raises(ValueError, match="increase"):
        crossing.update(np.zeros((1, 2)), 40.0)


def test_combine_prefers_agreeing_edges_and_labels_reasons():
    edge = np.array([[10.0, 10.0, np.nan, 5.0, 1.0]])
    cover = np.array([[10.5, 30.0, 12.0, np.nan, np.nan]])
    sky = np.array([[False, False, False, False, True]])
    lit = np.array([[True, True, True, True, True]])
    arrival, reason = combine_arrivals(edge, cover, tolerance_s=2.0, sky=sky, lit_at_start=lit)
    np.testing.assert_allclose(arrival[0, :4], [10.0, 30.0, 12.0, 5.0])
    assert np.isnan(arrival[0, 4])
    assert reason[0].tolist() == [REASON_CODE[n] for n in
                                  ("edge_crossing", "coverage_crossing", "coverage_crossing", "edge_crossing", "sky")]



def test_arrival_map_of_a_tracked_capture_matches_its_exact_arrivals(make_timelapse):
    import xarray as xr

    from shadowcam.outdoor.arrival import arrival_map
    from shadowcam.outdoor.datasets import photometry_dataset
    from shadowcam.outdoor.edges import track_edges
    from shadowcam.outdoor.normalise import normalise_frames

    scene = make_timelapse(width=40, n_frames=30, seed=5)
    frames = xr.Dataset({"image": (("time", "row", "col", "channel"), np.asarray(scene["frames"]))},
                        coords={"time_s": ("time", scene["time_s"])})
    photometry = photometry_dataset(normalise_frames(iter(scene["frames"])), scene["time_s"])
    arrival = arrival_map(photometry, track_edges(frames, photometry))
    found = np.isfinite(arrival["arrival_time_s"].values) & np.isfinite(scene["arrival_s"])
    assert found.sum() > 0.5 * np.isfinite(scene["arrival_s"]).sum()
    error = np.abs(arrival["arrival_time_s"].values - scene["arrival_s"])[found] / scene["interval"]
    assert np.median(error) < 0.25  # capture intervals (the clean-capture target)
    frame = arrival["arrival_frame"].values[found]
    assert frame.min() >= 0 and frame.max() <= len(scene["time_s"]) - 1
    assert arrival["reason"].attrs["flag_meanings"].split()[0] == "edge_crossing"
    with pytest.raises(ValueError, match="tolerance_intervals"):
        arrival_map(photometry, track_edges(frames, photometry), tolerance_intervals=0)
