"""Arrival-time accuracy on disc-sun renders (the real sun's penumbra), through the library.

Each case renders a small sunset time-lapse of the ridge scene with a 0.53 deg sun and every
nuisance (auto-exposure, shake, cloud, irregular and dropped frames), adds Poisson-Gaussian
sensor noise, runs the outdoor passes in process (photometry, edge tracking, arrival map) and
checks the ``nuisances`` targets against the exact ground truth (the penumbra's centre at the
pixel centre): median <= 0.5, p95 <= 2 intervals, under 1% of the class-3 pixels beyond 5.
"""

import numpy as np
import pytest

from shadowcam.outdoor.accuracy import PRIMARY_DEFINITION, arrival_errors, evaluate_arrivals, map_to_truth_camera
from shadowcam.outdoor.arrival import arrival_map
from shadowcam.outdoor.edges import track_edges
from shadowcam.outdoor.photometry import photometry_from_frames
from shadowcam.synthetic.outdoor.capture import noisy_frame_store, render_outdoor_capture
from shadowcam.synthetic.outdoor.render import SUN_DIAMETER_DEG, make_outdoor_scene

pytestmark = pytest.mark.slow


def _disc_sun_accuracy(*, height, width, frames, cloud, seed=3, elevations=(20.0, 1.5)):
    scene = make_outdoor_scene(seed=seed, height=height, width=width, start_elevation_deg=elevations[0],
                               end_elevation_deg=elevations[1])
    capture = render_outdoor_capture(scene, frames=frames, supersample=2, seed=seed,
                                     sun_diameter_deg=SUN_DIAMETER_DEG, cloud=cloud)
    truth = capture.ground_truth
    store = noisy_frame_store(capture, seed=seed)
    photometry = photometry_from_frames(store)
    arrival = arrival_map(photometry, track_edges(store, photometry))
    estimate = map_to_truth_camera(arrival["arrival_time_s"].values, shift_row=float(truth["shake_dy_px"][0]),
                                   shift_col=float(truth["shake_dx_px"][0]))
    interval = float(np.median(np.diff(capture.times_s)))
    report = evaluate_arrivals({"combined": estimate}, truth, interval_s=interval, condition="nuisances")
    penumbra = (truth["penumbra_end_time_s"] - truth["penumbra_start_time_s"]).values / interval
    return report, float(np.nanmedian(penumbra))


@pytest.mark.parametrize("case", [
    dict(height=64, width=96, frames=120, cloud=True),            # slow sunset, low resolution
    dict(height=64, width=96, frames=40, cloud="edge_crossing"),  # fast sunset, a cloud over the edge
    dict(height=96, width=144, frames=80, cloud="several"),       # three passing clouds
])
def test_disc_sun_renders_meet_the_nuisance_targets(case):
    report, penumbra_intervals = _disc_sun_accuracy(**case)
    assert penumbra_intervals > 0.5  # the penumbra lasts a sizeable part of an interval or more
    stats = report["errors"]["combined"][PRIMARY_DEFINITION]
    # coverage is no target (pixels without a time are reported, not counted as errors); with
    # several clouds it is the lowest, see docs/benchmarks.md (open problems)
    assert stats["coverage"] > 0.9
    failed = [t for t in report["targets"] if not t["pass"]]
    assert not failed, failed


@pytest.mark.parametrize("cloud", ["first_frame", "first_frame_whole"])
def test_a_cloud_over_the_lit_cliff_in_the_first_frame_gives_no_wrong_arrivals(cloud):
    # the pass's reference (frame 0) under a cloud that leaves in a few frames: over part of the
    # lit cliff (37 % of its class-3 pixels), or over all of it, where the lit gain took the cloud's level for the lit one until
    # it left and the tracker's lit levels rose with the relit pixels: 4.3 % beyond 5 intervals,
    # p95 3.0 before (docs/benchmarks.md, issue 15). Coverage is no target: pixels the cloud
    # leaves while it shades them get no time rather than a wrong one (0.73 over the whole cliff)
    report, _ = _disc_sun_accuracy(height=64, width=96, frames=40, cloud=cloud)
    stats = report["errors"]["combined"][PRIMARY_DEFINITION]
    assert stats["coverage"] > (0.9 if cloud == "first_frame" else 0.6)
    failed = [t for t in report["targets"] if not t["pass"]]
    assert not failed, failed


def test_long_penumbrae_at_a_photographers_cadence():
    # the sun 8.0 -> 7.2 deg in 96 frames: each pixel's penumbra lasts ~55 intervals, most ramps
    # begin before the first frame or end after the last; the nuisance targets are not met
    # (docs/benchmarks.md, "Outdoor arrival of a penumbra under way at the first frame"): bounds
    # at the figures reached (0.94 / 11.3 / 12.0 %, coverage 53 %: the ramps under way at the
    # first frame without a lit level get no time; with the law's fit of them 1.05 / 14.6 / 14.1 %,
    # 78 %)
    report, penumbra_intervals = _disc_sun_accuracy(height=128, width=192, frames=96, cloud=True,
                                                    elevations=(8.0, 7.2))
    assert penumbra_intervals > 40
    stats = report["errors"]["combined"][PRIMARY_DEFINITION]
    assert stats["median_abs"] <= 1.0 and stats["p95_abs"] <= 12.0 and stats["frac_over_5"] <= 0.125
    assert stats["coverage"] >= 0.5


def test_ramps_under_way_at_the_first_frame_keep_their_shadow_under_a_cloud_over_the_whole_window():
    # a 400x64 window of the 24 MP strip (the sun 8.0 -> 6.4 deg in 96 frames, penumbrae of tens of
    # intervals) under the drifting cloud, which covers all its lit ground in frames ~55-85: the
    # tracker took an edge found at the foot of the ridge's shadow (the ground shadowed from the
    # start below it) for the shadow's front, measured the shadowed rows above it as a passing
    # cloud's shade of 0.01-0.1 and divided it out, so those pixels relit and their lit level sank
    # to their shadow: the pixels under way at the first frame had p95 94 intervals, 50 % beyond 5
    # (docs/benchmarks.md, issue 15). Rows the previous frame left dark are no cloud's reference.
    scene = make_outdoor_scene(seed=3, height=4000, width=6000, start_elevation_deg=8.0, end_elevation_deg=6.4,
                               window=(1500, 3000, 400, 64))
    capture = render_outdoor_capture(scene, frames=96, supersample=1, seed=3, sun_diameter_deg=SUN_DIAMETER_DEG,
                                     cloud=True, shake_px=2.0)
    truth = capture.ground_truth
    store = noisy_frame_store(capture, seed=3)
    photometry = photometry_from_frames(store)
    arrival = arrival_map(photometry, track_edges(store, photometry))
    estimate = map_to_truth_camera(arrival["arrival_time_s"].values, shift_row=float(truth["shake_dy_px"][0]),
                                   shift_col=float(truth["shake_dx_px"][0]))
    interval = float(np.median(np.diff(capture.times_s)))
    class3 = truth["shadow_class"].values == 3
    begun = np.isfinite(truth["penumbra_start_time_s"].values)
    ended = np.isfinite(truth["penumbra_end_time_s"].values)
    true_arrival = truth["arrival_time_s"].values
    under_way = arrival_errors(estimate, true_arrival, evaluate=class3 & ~begun, interval_s=interval)
    whole = arrival_errors(estimate, true_arrival, evaluate=class3 & begun & ended, interval_s=interval)
    # bounds at the 4000-row strip's figures before the shade field (p95 12.4, 7.8 % beyond 5; this
    # window: 5.3 and 7.3 %) and at its whole penumbra's (0.45 / 2.2 / 0.1 % here)
    assert under_way["n_evaluated"] > 1000 and under_way["coverage"] > 0.1
    assert under_way["p95_abs"] <= 12.0 and under_way["frac_over_5"] <= 0.10, under_way
    assert whole["median_abs"] <= 1.0 and whole["p95_abs"] <= 3.0 and whole["frac_over_5"] <= 0.01, whole
