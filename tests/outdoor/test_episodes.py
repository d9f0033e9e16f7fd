"""Dark episodes: the final shadow, transient shadows before it, one-frame shadows, shadowed from the start."""

import numpy as np
import pytest

from shadowcam.outdoor.episodes import ShadowEpisodes
from shadowcam.outdoor.tracking import track_frames


def _run(covers, times, eligible=None):
    covers = np.asarray(covers, dtype=np.float32)
    episodes = ShadowEpisodes(covers.shape[1:], eligible=np.ones(covers.shape[1:], bool) if eligible is None else eligible)
    for cover, t in zip(covers, times):
        episodes.update(cover, t)
    return episodes.result()


def test_the_final_episode_is_the_arrival_and_a_passing_shadow_is_an_event():
    times = np.arange(10) * 10.0
    cover = np.ones((10, 1, 1))
    cover[2:5] = 0.3  # a cloud: 0.3 lit from frame 2 to 4, relit at frame 5
    cover[7:] = 0.0  # the ridge shadow from frame 7 on
    cover[6] = 0.5 + 0.5 * 0.5  # crossing 0.5 at 65 s
    cover[7] = 0.0
    result = _run(cover, times)
    assert result["final_start_s"][0, 0] == pytest.approx(60.0 + 10.0 * 0.25 / 0.75)
    assert result["n_events"][0, 0] == 1
    assert result["event_start_s"][0, 0, 0] == pytest.approx(10.0 + 10.0 * 0.5 / 0.7)
    assert result["event_end_s"][0, 0, 0] == pytest.approx(40.0 + 10.0 * 0.2 / 0.7)
    assert result["event_depth"][0, 0, 0] == pytest.approx(0.7, abs=1e-6)
    assert result["final_depth"][0, 0] == pytest.approx(1.0)


def test_a_one_frame_shadow_counts_when_the_neighbours_agree_and_not_alone():
    times = np.arange(6) * 10.0
    cover = np.ones((6, 7, 7))
    cover[2, 1:4, 1:4] = 0.0  # a 3x3 patch shadowed for one frame
    cover[2, 5, 5] = 0.0  # one noisy pixel
    cover[5, 0, 6] = 0.0  # a shadow in the last frame (kept)
    result = _run(cover, times)
    assert (result["n_events"][1:4, 1:4] == 1).all()
    np.testing.assert_allclose(result["event_start_s"][1:4, 1:4, 0], 15.0)
    np.testing.assert_allclose(result["event_end_s"][1:4, 1:4, 0], 25.0)
    assert result["n_events"][5, 5] == 0 and np.isnan(result["final_start_s"][5, 5])
    assert result["final_start_s"][0, 6] == pytest.approx(45.0)
    assert np.isnan(result["final_start_s"][2, 2])  # relit: no arrival


def test_pixels_shadowed_from_the_start_or_not_eligible_get_no_arrival():
    times = np.arange(5) * 10.0
    cover = np.ones((5, 1, 3))
    cover[:, 0, 0] = 0.0  # dark in the first frame, relit in frame 2, dark again from frame 3
    cover[2, 0, 0] = 1.0
    cover[3:, 0, 1] = 0.0  # not eligible
    cover[3:, 0, 2] = 0.0  # eligible: arrives
    result = _run(cover, times, eligible=np.array([[True, False, True]]))
    assert np.isnan(result["final_start_s"][0, :2]).all() and result["final_start_s"][0, 2] == pytest.approx(25.0)
    assert (result["n_events"] == 0).all()


def test_a_cloud_over_the_lit_cliff_is_not_the_arrival(make_timelapse):
    scene = make_timelapse(seed=6, n_frames=40)
    frames = scene["frames"].copy()
    # the sun term dimmed to 0.3 (lit = albedo (1 + 0.1), clouded = albedo (0.3 + 0.1)) over a
    # block of pixels lit then, for frames 4-10: far above the edge and just above it
    block = np.zeros(frames.shape[1:3], bool)
    block[14:22, 10:40] = True
    block[30:40, 20:50] = True
    frames[4:11][:, block] *= np.float32(0.4 / 1.1)
    tracked = track_frames(iter(frames), _photometry(frames), scene["time_s"])
    truth = scene["arrival_s"]
    error = np.abs(tracked["coverage_arrival_s"] - truth) / scene["interval"]
    assert np.nanmax(error[block & np.isfinite(truth)]) <= 1.0
    high = np.zeros_like(block)
    high[14:22, 10:40] = True
    assert np.isnan(tracked["coverage_arrival_s"][high]).all()  # never reached by the ridge shadow
    assert (tracked["n_events"][high] == 1).all()
    np.testing.assert_allclose(tracked["event_depth"][high, 0], 0.7, atol=0.05)


def _photometry(frames):
    from shadowcam.outdoor.normalise import normalise_frames

    return normalise_frames(iter(frames))
