"""Cloud scenarios of the outdoor renderer: transient shadows of varied size, speed, border and number."""

import json

import numpy as np
import pytest

from shadowcam.synthetic.outdoor.capture import render_outdoor_capture
from shadowcam.synthetic.outdoor.clouds import CLOUD_SCENARIOS
from shadowcam.synthetic.outdoor.render import make_outdoor_scene

ROWS, COLS, FRAMES = 48, 64, 60
QUIET = dict(auto_exposure=False, shake_px=0.0, irregular_timing=False, dropped_frames=0)


@pytest.fixture(scope="module")
def scene():
    return make_outdoor_scene(seed=2, height=ROWS, width=COLS)


def _render(scene, cloud):
    return render_outdoor_capture(scene, frames=FRAMES, supersample=1, seed=2, cloud=cloud, **QUIET).ground_truth


@pytest.mark.parametrize("scenario", ["small_fast_hard", "large_slow_soft", "several"])
def test_transient_clouds_pass_over_the_lit_cliff_and_it_relights(scene, scenario):
    gt = _render(scene, scenario)
    record = json.loads(gt.attrs["cloud"])
    shaded = gt["cloud_attenuation"].values < 0.8  # (time, row, col)
    lit = gt["lit_center"].values
    passing = shaded & lit  # a cloud over a sunlit pixel
    assert passing.any()
    # each such pixel relights: lit and out of the cloud in a later frame
    t_last = len(gt["time"]) - 1 - np.argmax(passing[::-1], axis=0)
    pixels = passing.any(axis=0)
    relit = np.zeros_like(pixels)
    for k in range(len(gt["time"])):
        relit |= (k > t_last) & lit[k] & (gt["cloud_attenuation"].values[k] > 0.99)
    # (a large cloud also covers pixels the ridge shadow reaches before it has passed)
    assert relit[pixels].mean() > 0.5 and relit.sum() >= 20
    frames_shaded = shaded.sum(axis=0)[pixels]
    assert np.median(frames_shaded) < 0.5 * FRAMES  # transient, not the whole sequence
    assert len(record["clouds"]) == (3 if scenario == "several" else 1)


def test_scenarios_vary_size_speed_border_and_depth(scene):
    records = {name: json.loads(_render(scene, name).attrs["cloud"])["clouds"]
               for name in ("small_fast_hard", "large_slow_soft")}
    small, large = records["small_fast_hard"][0], records["large_slow_soft"][0]
    assert small["sigma_m"] < large["sigma_m"] / 3
    assert np.hypot(*small["velocity_xy_m_per_s"]) / small["sigma_m"] > 2 * np.hypot(*large["velocity_xy_m_per_s"]) / large["sigma_m"]
    assert small["rim_m"] <= 5.0 and "rim_m" not in large  # hard disk vs Gaussian


def test_a_cloud_crosses_the_ridge_shadow_edge_while_it_moves(scene):
    gt = _render(scene, "edge_crossing")
    frame = gt["arrival_frame"].values
    k = np.clip(np.round(np.nan_to_num(frame, nan=0.0)).astype(int), 0, FRAMES - 1)
    rows, cols = np.indices(frame.shape)
    at_arrival = gt["cloud_attenuation"].values[k, rows, cols]
    assert (np.isfinite(frame) & (at_arrival < 0.8)).sum() >= 5


def test_unknown_scenarios_and_no_room_are_rejected(scene):
    assert "drifting" in CLOUD_SCENARIOS
    with pytest.raises(ValueError, match="cloud"):
        render_outdoor_capture(scene, frames=4, supersample=1, seed=2, cloud="stormy", **QUIET)


@pytest.mark.parametrize("scenario, share", [("first_frame", (0.1, 0.6)), ("first_frame_whole", (0.95, 1.0))])
def test_a_first_frame_cloud_covers_the_lit_cliff_at_the_start_and_leaves(scene, scenario, share):
    """The reference frame is clouded (part of the lit cliff, or all of it) and the cloud is gone
    within about its 8 frames over a point (a margin of 4 frames for its rim)."""
    gt = _render(scene, scenario)
    shaded = gt["cloud_attenuation"].values < 0.9  # (time, row, col)
    lit = gt["lit_center"].values
    covered = (shaded[0] & lit[0]).sum() / lit[0].sum()
    assert share[0] <= covered <= share[1]
    assert not (shaded[12:] & lit[12:]).any()
