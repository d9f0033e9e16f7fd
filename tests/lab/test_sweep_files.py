"""Shadow times straight from DNG files: parallel time chunks equal one pass, and are accurate."""

from dataclasses import fields

import numpy as np
import pytest

from shadowcam.lab.accuracy import shadow_time_errors
from shadowcam.evaluate.speed_benchmark import WireScene, write_sweep_dngs
from shadowcam.io.mosaic_reader import MosaicReader
from shadowcam.lab.dip_tracker import DipSummary, half_depth, track_intervals, window_intervals, without_interval
from shadowcam.lab.mosaic_signal import mosaic_signal
from shadowcam.lab.shadow_time import summary_shadow_times
from shadowcam.lab.sweep_files import chunk_bounds, sweep_shadow_times_from_files, track_files

# the library's WireScene, not the wire_sweep fixture: write_sweep_dngs renders its DNG files from it
SCENE = WireScene(height=48, width_px=64, n_frames=40, px_per_frame=2.5, t0=4.0, seed=3)


@pytest.fixture(scope="module")
def dng_paths(tmp_path_factory):
    return write_sweep_dngs(SCENE, tmp_path_factory.mktemp("dng"), workers=1)


def test_chunk_bounds_tile_the_frames():
    assert chunk_bounds(10, 3) == [(0, 3), (3, 7), (7, 10)]
    assert chunk_bounds(2, 4) == [(0, 1), (1, 2)]
    with pytest.raises(ValueError, match="n_chunks"):
        chunk_bounds(5, 0)


def test_two_worker_processes_equal_one_pass_bit_for_bit(dng_paths):
    one = track_files(dng_paths, workers=1, block_frames=7)
    two = track_files(dng_paths, workers=2, block_frames=3)
    for field in fields(DipSummary):
        a, b = getattr(one, field.name), getattr(two, field.name)
        if isinstance(a, np.ndarray):
            np.testing.assert_array_equal(a, b, err_msg=field.name, strict=True)
        else:
            assert a == b


def test_shadow_times_from_dng_files_match_the_exact_truth(dng_paths):
    result = sweep_shadow_times_from_files(dng_paths, workers=2)
    truth = SCENE.truth()
    errors = shadow_time_errors(result["shadow_time"], truth, lit=np.ones(truth.shape, bool))
    # 14-bit DNG with shot and read noise, 2.5 pixels per frame: edge_fit is sub-tenth-frame
    assert errors["coverage"] > 0.97
    assert errors["p95"] < 0.1
    assert result["n_frames"] == SCENE.n_frames


def test_rendered_frames_are_darkest_at_the_true_time():
    albedo = SCENE.albedo()
    truth = SCENE.truth()
    frames = np.stack([SCENE.frame(k, albedo)[..., 0] for k in range(SCENE.n_frames)])
    darkest = frames.argmin(axis=0)
    inside = np.isfinite(truth) & (truth > 2) & (truth < SCENE.n_frames - 3)
    assert np.abs(darkest - truth)[inside].max() <= 1.0


def test_a_shadow_wider_than_the_window_is_timed_from_a_second_read_of_the_files(tmp_path):
    # a 14-frame-wide shadow (the tracker's window is 9 frames): the crossings lie beyond the
    # window, so the files are read again for the interval, as the workflow's step measures it
    scene = WireScene(height=24, width_px=40, n_frames=60, px_per_frame=1.5, width=14.0, t0=4.0, seed=5)
    paths = write_sweep_dngs(scene, tmp_path, workers=1)
    result = sweep_shadow_times_from_files(paths, workers=2, block_frames=7)

    summary = track_files(paths, workers=1)
    reader = MosaicReader(paths[0])
    planes = []
    for path in paths:
        mosaic, levels = reader.read(path)
        planes.append(mosaic_signal(mosaic, pattern=levels["cfa_pattern"], black=levels["black_sites"],
                                    white=levels["white_sites"])[0])
    _, resolved = window_intervals(summary, half_depth(summary))
    assert resolved.mean() < 0.5
    summary, interval = without_interval(summary, track_intervals([np.stack(planes)], summary))
    reference = summary_shadow_times(summary, interval=interval, cfa_pattern=levels["cfa_pattern"])
    for name in ("shadow_time", "time_std", "reason", "entry_time", "exit_time"):
        np.testing.assert_array_equal(result[name], reference[name], err_msg=name)
    truth = scene.truth()
    inside = (truth > 7 + 2) & (truth < scene.n_frames - 1 - 7 - 2)  # the whole dip in the sweep
    errors = shadow_time_errors(result["shadow_time"], truth, lit=inside)
    # the interval's centre: half-depth crossings of hard edges under 14-bit noise
    assert errors["coverage"] > 0.95
    assert errors["p95"] < 0.3
