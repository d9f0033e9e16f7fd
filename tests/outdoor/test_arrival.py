"""Arrival maps: edge crossing exact for uniform motion; episodes resolved (relit, transient, ambiguous); reasons."""

import numpy as np
import pytest

from shadowcam.outdoor.arrival import (EVENT_KINDS, REASON_CODE, arrival_from_edges, combine_arrivals, event_table,
                                       resolve_episodes)


def test_edge_crossing_is_exact_for_a_linearly_moving_edge_with_irregular_times():
    time_s = np.array([0.0, 40.0, 100.0, 130.0, 250.0])
    speed = 0.05  # rows per second
    edge = 12.0 - speed * time_s[:, None] + np.zeros((1, 3))
    eligible = np.ones((14, 3), bool)
    arrival = arrival_from_edges(edge, time_s, eligible=eligible)
    centre = np.arange(14) + 0.5
    truth = np.where((centre < 12.0) & (centre >= 12.0 - speed * 250), (12.0 - centre) / speed, np.nan)
    np.testing.assert_allclose(arrival[:, 0], truth, atol=1e-9)


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


def test_an_episode_at_the_edge_is_the_arrival_of_a_relit_pixel_and_a_passing_one_is_transient():
    # three pixels of one column (rows 0, 1, 2), 2 earlier-episode slots; times in seconds
    time_s = np.arange(0.0, 100.0, 10.0)
    edge_row = np.full((10, 1), 9.0)
    edge_row[3:] = 0.8  # the edge passes row 0's centre between frames 2 and 3 (t = 20..30 s)
    final = np.array([[70.0], [80.0], [60.0]])
    starts = np.full((3, 1, 2), np.nan)
    starts[0, 0, 0] = 25.0  # row 0: shadowed when the edge passed, relit, shadowed again at 70 s
    starts[1, 0, 0] = 15.0  # row 1: darkened at 15 s while the edge was far below: a cloud
    starts[2, 0, 0] = 5.0  # row 2: as row 1, but the edge crossing agrees with no episode
    edge_s = np.array([[np.nan], [80.5], [40.0]])
    coverage, chosen, ambiguous = resolve_episodes(final, starts, edge_s, tolerance_s=3.0, edge_row=edge_row,
                                                   time_s=time_s)
    np.testing.assert_allclose(coverage[:2, 0], [25.0, 80.0])
    assert chosen[:, 0].tolist() == [0, 2, 2] and ambiguous[:, 0].tolist() == [False, False, True]
    assert np.isnan(coverage[2, 0])  # no confident wrong time
    ends = starts + 5.0
    events = event_table(final, np.full((3, 1), 0.95), starts, ends, np.full((3, 1, 2), 0.6), chosen=chosen,
                         ambiguous=ambiguous, eligible=np.ones((3, 1), bool))
    kinds = [EVENT_KINDS[k] for k in events["kind"]]
    assert events["row"].tolist() == [0, 0, 1, 1, 2, 2]
    assert kinds == ["arrival", "shadowed_again", "transient", "arrival", "ambiguous", "ambiguous"]
    np.testing.assert_allclose(events["start_s"], [25.0, 70.0, 15.0, 80.0, 5.0, 60.0])
    assert np.isnan(events["end_s"][[1, 3, 5]]).all() and events["end_s"][0] == 30.0


def test_combine_labels_relit_and_ambiguous_pixels():
    edge = np.array([[10.0, 50.0, 12.0]])
    cover = np.array([[10.5, np.nan, 12.2]])
    lit, sky = np.ones((1, 3), bool), np.zeros((1, 3), bool)
    arrival, reason = combine_arrivals(edge, cover, tolerance_s=2.0, sky=sky, lit_at_start=lit,
                                       relit=np.array([[True, False, False]]),
                                       ambiguous=np.array([[False, True, False]]))
    assert reason[0].tolist() == [REASON_CODE[n] for n in ("relit_after_arrival", "ambiguous_history", "edge_crossing")]
    assert np.isnan(arrival[0, 1]) and arrival[0, 0] == 10.0
