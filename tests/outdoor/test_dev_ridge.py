"""The issue's accuracy targets on the shared Mitsuba time-lapse dev_ridge (real nuisances).

Runs both streaming passes in-process on the 120 PNG frames (decoded one at a
time), builds the arrival map like the workflow does, and checks it against the
GT pixel-centre arrival with the "nuisances" targets (median <= 0.5, p95 <= 2,
< 1% beyond 5 median intervals), plus the registration against the recorded
shake and the naive baseline computed by the same evaluation code
(shared/data/README.md section 2.8: about 82% within one interval).
"""

from pathlib import Path

import numpy as np
import pytest

from shadowcam.outdoor.arrival import arrivals
from shadowcam.io.decode import iter_frames
from shadowcam.io.ground_truth import load_ground_truth
from shadowcam.outdoor.keyframes import interpolate_edges, select_keyframes
from shadowcam.io.manifest import load_manifest
from shadowcam.outdoor.accuracy import NaiveBaseline, evaluate_arrivals
from shadowcam.outdoor.normalise import normalise_frames
from shadowcam.outdoor.tracking import track_frames

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def run(shared_data):  # the repository manifest reads the shared dev data
    manifest = load_manifest(REPO / "data_manifest" / "dev_ridge.yaml")
    sweep = manifest["sweeps"]["timelapse"]
    time_s = np.asarray(sweep["times_s"])

    def frames():
        return (image for _, image, _ in iter_frames(sweep["paths"]))

    photometry = normalise_frames(frames())
    tracked = track_frames(frames(), photometry, time_s)
    key = select_keyframes(tracked["confidence"], tracked["edge_row"])
    edges, _ = interpolate_edges(tracked["edge_row"], tracked["confidence"], time_s, is_keyframe=key)
    interval = float(np.median(np.diff(time_s)))
    arrival = arrivals(edges, time_s, tracked, sky=photometry["sky"], lit_at_start=photometry["lit_at_start"],
                       tolerance_s=1.5 * interval)["arrival_s"]
    baseline = NaiveBaseline(arrival.shape)
    for frame, t in zip(frames(), time_s):
        baseline.update(frame, t)
    truth = load_ground_truth(manifest)
    report = evaluate_arrivals({"combined": arrival, "naive_baseline": baseline.arrival_s}, truth,
                               interval_s=interval, condition="nuisances")
    return photometry, truth, report


def test_dev_ridge_meets_the_nuisance_targets(run):
    _, _, report = run
    stats = report["errors"]["combined"]["pixel_centre"]
    assert report["all_targets_pass"], report["targets"]
    assert stats["coverage"] >= 0.99
    # the half-coverage definition gives the same picture
    assert report["errors"]["combined"]["half_coverage"]["median_abs"] <= 0.5


def test_dev_ridge_beats_the_naive_baseline(run):
    _, _, report = run
    ours, naive = report["errors"]["combined"]["pixel_centre"], report["errors"]["naive_baseline"]["pixel_centre"]
    assert 0.75 <= naive["frac_within_1"] <= 0.88  # README 2.8: 82% within one frame
    assert ours["frac_within_1"] > naive["frac_within_1"] + 0.1
    assert ours["median_abs"] < 0.5 * naive["median_abs"]


def test_dev_ridge_registration_and_sky(run):
    photometry, truth, _ = run
    shake = np.stack([truth["shake_dy_px"].values, truth["shake_dx_px"].values], axis=1)
    error = photometry["shift"] - (shake - shake[0])
    assert np.sqrt(np.mean(error**2)) < 0.05 and np.abs(error).max() < 0.15  # pixels; shake rms 0.26
    sky = truth["sky_mask"].values
    assert (photometry["sky"] & ~sky).sum() == 0 and (sky & ~photometry["sky"]).sum() < 0.03 * sky.sum()
