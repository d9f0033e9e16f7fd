"""Tests of the streaming dip tracker: exact, chunk-independent, bounded state."""

import numpy as np
import pytest

from shadowcam.dip_tracker import DipTracker


def _sweep(n_frames, dip_frames, shape=(4, 5), level=1.0, depth=0.9, seed=0, noise=0.0):
    rng = np.random.default_rng(seed)
    frames = np.full((n_frames,) + shape, level, np.float32)
    for frame in dip_frames:
        frames[frame] = level - depth
    return frames + rng.normal(0, noise, frames.shape).astype(np.float32)


def test_finds_the_dip_and_the_lit_level_without_it():
    frames = _sweep(50, [20, 21, 22])
    tracker = DipTracker(frames.shape[1:], half_window=3)
    tracker.update(frames)
    summary = tracker.result()
    assert np.all(summary.minimum_frame == 21)
    np.testing.assert_allclose(summary.lit_level, 1.0)
    np.testing.assert_allclose(summary.noise, 0.0, atol=1e-7)
    assert summary.window.shape == (7, 4, 5)
    np.testing.assert_allclose(summary.window[:, 0, 0], [1, 1, 0.1, 0.1, 0.1, 1, 1], rtol=1e-6)


@pytest.mark.parametrize("block", [1, 3, 7, 50])
def test_result_does_not_depend_on_block_size(block):
    frames = _sweep(50, [10, 11, 40], noise=0.05, seed=3)
    whole = DipTracker(frames.shape[1:], half_window=4)
    whole.update(frames)
    split = DipTracker(frames.shape[1:], half_window=4)
    for start in range(0, 50, block):
        split.update(frames[start:start + block])
    a, b = whole.result(), split.result()
    np.testing.assert_array_equal(a.window, b.window)
    np.testing.assert_array_equal(a.minimum_frame, b.minimum_frame)
    np.testing.assert_array_equal(a.lit_level, b.lit_level)
    np.testing.assert_array_equal(a.second_value, b.second_value)


def test_second_dip_a_window_away_is_recorded_and_shoulders_are_not():
    frames = _sweep(60, [9, 10, 11])
    frames[40] = 0.4  # a shallower second dip
    frames[13] = 0.8  # a shoulder of the first dip, inside its window
    tracker = DipTracker(frames.shape[1:], half_window=3)
    tracker.update(frames)
    summary = tracker.result()
    assert np.all(summary.minimum_frame == 10)
    assert np.all(summary.second_frame == 40)


def test_dip_at_the_sequence_edges_is_found_and_padded_with_nan():
    frames = _sweep(30, [29])
    tracker = DipTracker(frames.shape[1:], half_window=2)
    tracker.update(frames)
    summary = tracker.result()
    assert np.all(summary.minimum_frame == 29)
    assert np.isnan(summary.window[3:]).all() and np.isfinite(summary.window[:3]).all()


def test_long_sequences_keep_running_statistics_exact():
    # 10,000 frames of a large offset plus tiny noise: float32 sums would lose it
    rng = np.random.default_rng(1)
    shape = (2, 3)
    tracker = DipTracker(shape, half_window=2)
    noise = rng.normal(0, 1e-3, (10_000,) + shape).astype(np.float32)
    frames = (1000.0 + noise).astype(np.float32)
    for start in range(0, 10_000, 997):
        tracker.update(frames[start:start + 997])
    summary = tracker.result()
    expected = frames.astype(np.float64).std(axis=0, ddof=1)
    np.testing.assert_allclose(summary.noise, expected, rtol=0.05)


def test_non_finite_samples_are_counted_not_propagated():
    frames = _sweep(40, [19, 20, 21])
    frames[5, 0, 0] = np.nan
    frames[6, 0, 1] = np.inf
    tracker = DipTracker(frames.shape[1:], half_window=3)
    tracker.update(frames)
    summary = tracker.result()
    assert summary.invalid_count[0, 0] == 1 and summary.invalid_count[0, 1] == 1
    assert np.isfinite(summary.lit_level).all()
    assert np.all(summary.minimum_frame == 20)


def test_rejects_bad_input():
    with pytest.raises(ValueError, match="half_window"):
        DipTracker((3, 3), half_window=0)
    tracker = DipTracker((3, 3))
    with pytest.raises(ValueError, match="block"):
        tracker.update(np.zeros((2, 4, 4), np.float32))
    tracker.result()
    with pytest.raises(ValueError, match="after result"):
        tracker.update(np.zeros((1, 3, 3), np.float32))
