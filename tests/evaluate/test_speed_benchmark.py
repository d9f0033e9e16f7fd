"""The speed benchmark's per-stage figures: what they count, on a small rendered DNG sweep."""

import numpy as np

from shadowcam.evaluate.speed_benchmark import WireScene, _minimal_tracker, stage_ns, write_sweep_dngs
from shadowcam.lab.dip_tracker import DipTracker, half_depth, window_intervals
from shadowcam.lab.mosaic_signal import mosaic_signal
from shadowcam.io.mosaic_reader import MosaicReader


def test_minimal_tracker_counts_the_smoothed_values_below_the_bar():
    rng = np.random.default_rng(0)
    block = rng.random((7, 50)).astype(np.float32)
    worst = np.full(50, 0.5, np.float32)
    ring = np.zeros((3, 50), np.float32)
    hits = _minimal_tracker(block, ring, worst)
    # the ring starts at zeros: frame t's smoothed value uses frames t - 2, t - 1, t
    padded = np.concatenate([np.zeros((2, 50), np.float32), block])
    smooth = np.float32(0.5) * padded[1:-1] + np.float32(0.25) * (padded[:-2] + padded[2:])
    assert hits == int((smooth < worst).sum())


def test_stage_figures_of_a_small_sweep(tmp_path):
    scene = WireScene(height=48, width_px=64, n_frames=30, px_per_frame=3.0, t0=3.0, seed=2)
    paths = write_sweep_dngs(scene, tmp_path, workers=1)
    figures = stage_ns(paths, block_frames=8, repeats=1)
    assert figures["frames"] == 30 and figures["pixels"] == 48 * 64
    for key in ("decode", "signal", "track", "site_read", "minimal_track", "numpy_pass"):
        assert 0 < figures[key] < 1e6, key
    assert figures["own"] == 0
    first_pass = stage_ns(paths, block_frames=8, repeats=1, own_site_in_first_pass=True)
    assert 0 < first_pass["own"] < 1e6 and first_pass["site_read"] == 0
    # the pixels left to a second read are those the stored windows do not resolve
    reader = MosaicReader(paths[0])
    tracker = DipTracker((48, 64))
    for path in paths:
        mosaic, levels = reader.read(path)
        tracker.update(mosaic_signal(mosaic, pattern=levels["cfa_pattern"], black=levels["black_sites"],
                                     white=levels["white_sites"])[0])
    summary = tracker.result()
    _, resolved = window_intervals(summary, half_depth(summary))
    assert figures["interval_unresolved"] == int((~resolved).sum())
