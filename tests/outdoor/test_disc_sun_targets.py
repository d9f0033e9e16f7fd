"""Arrival-time accuracy on disc-sun renders (the real sun's penumbra), through the library.

Each case renders a small sunset time-lapse of the ridge scene with a 0.53 deg sun and every
nuisance (auto-exposure, shake, cloud, irregular and dropped frames), adds Poisson-Gaussian
sensor noise, runs the outdoor passes in process (photometry, edge tracking, arrival map) and
checks the ``nuisances`` targets against the exact ground truth (the penumbra's centre at the
pixel centre): median <= 0.5, p95 <= 2 intervals, under 1% of the class-3 pixels beyond 5.
"""

import numpy as np
import pytest

from shadowcam.outdoor.accuracy import PRIMARY_DEFINITION, evaluate_arrivals, map_to_truth_camera
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
