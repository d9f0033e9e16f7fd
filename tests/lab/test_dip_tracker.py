"""Tests of the streaming dip tracker: exact, chunk-independent, bounded state."""

from dataclasses import fields

import numpy as np
import pytest

from shadowcam.lab.dip_tracker import DipPartial, DipSummary, DipTracker, merge_partials


@pytest.fixture(scope="module")
def dip_sweep(wire_sweep):
    """Scalar (T, rows, cols) frames at `level`, dipping by `depth` in each of `dip_frames` (every pixel)."""
    def make(n_frames, dip_frames, shape=(4, 5), level=1.0, depth=0.9, seed=0, noise=0.0):
        frames, _ = wire_sweep(n_frames=n_frames, centres=list(dip_frames), width=1.0, shape=shape,
                               level=level, depth=depth, seed=seed, noise=noise)
        return frames
    return make


def test_finds_the_dip_and_the_lit_level_without_it(dip_sweep):
    frames = dip_sweep(50, [20, 21, 22])
    tracker = DipTracker(frames.shape[1:], half_window=3)
    tracker.update(frames)
    summary = tracker.result()
    assert np.all(summary.minimum_frame == 21)
    np.testing.assert_allclose(summary.lit_level, 1.0)
    np.testing.assert_allclose(summary.noise, 0.0, atol=1e-7)
    assert summary.window.shape == (7, 4, 5)
    np.testing.assert_allclose(summary.window[:, 0, 0], [1, 1, 0.1, 0.1, 0.1, 1, 1], rtol=1e-6)


@pytest.mark.parametrize("block", [1, 3, 7, 50])
def test_result_does_not_depend_on_block_size(block, dip_sweep):
    frames = dip_sweep(50, [10, 11, 40], noise=0.05, seed=3)
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


def test_second_dip_a_window_away_is_recorded_and_shoulders_are_not(dip_sweep):
    frames = dip_sweep(60, [9, 10, 11])
    frames[40] = 0.4  # a shallower second dip
    frames[13] = 0.8  # a shoulder of the first dip, inside its window
    tracker = DipTracker(frames.shape[1:], half_window=3)
    tracker.update(frames)
    summary = tracker.result()
    assert np.all(summary.minimum_frame == 10)
    assert np.all(summary.second_frame == 40)


def test_dip_at_the_sequence_edges_is_found_and_padded_with_nan(dip_sweep):
    frames = dip_sweep(30, [29])
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


def test_non_finite_samples_are_counted_not_propagated(dip_sweep):
    frames = dip_sweep(40, [19, 20, 21])
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


def _summaries_equal(a, b):
    for field in fields(DipSummary):
        x, y = getattr(a, field.name), getattr(b, field.name)
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype, field.name
            np.testing.assert_array_equal(x, y, err_msg=field.name, strict=True)
        else:
            assert x == y, field.name


def _chunked(frames, bounds, *, half_window, block=5):
    """Partials of the chunks [bounds[i], bounds[i+1]), each fed its padded range in blocks."""
    n = len(frames)
    pad = DipTracker.padding(half_window)
    partials = []
    for start, stop in zip(bounds[:-1], bounds[1:]):
        tracker = DipTracker(frames.shape[1:3], half_window=half_window, owned=(start, stop))
        lo, hi = max(0, start - pad), min(n, stop + pad)
        for first in range(lo, hi, block):
            tracker.update(frames[first:min(first + block, hi)], first_index=first)
        partials.append(tracker.partial())
    return partials


def _hard_sweep(dip_sweep, seed=5):
    """Colour frames with dips at chunk boundaries, second dips, ties, a ramp and NaNs."""
    frames = dip_sweep(64, [], shape=(6, 7), noise=0.02, seed=seed)
    frames[:, 0, 0] = 1.0  # exact ties everywhere
    frames[19:22, 1] -= 0.8  # dip centred on a boundary at 20
    frames[30:33, 2] -= 0.7
    frames[50, 2] -= 0.5  # a second dip
    frames[:, 3, 3] = np.linspace(1, 0.2, 64)  # a ramp: no second dip
    frames[0, 4] -= 0.9  # dip at the first frame
    frames[63, 5] -= 0.9  # and at the last
    frames[20, 5, 5] = np.nan
    frames[7, 4, 6] = np.inf
    frames[9, 5, 4] = -np.inf
    frames[16:24, 0, 2:] = 0.3  # flat minimum (smoothed: frames 17..22), across boundary 20
    frames[28:40, 0, 4:] = 0.2  # flat minimum longer than the window (smoothed: 29..38)
    frames[42:52, 3, :3] = 1.0
    frames[[44, 49], 3, :3] = 0.1  # two equal dips 5 frames apart (half_window 3)
    rng = np.random.default_rng(seed)
    tint = rng.uniform(0.2, 0.5, (1, 1, 1, 3)).astype(np.float32)
    return frames[..., None] * tint


@pytest.mark.parametrize("bounds", [
    [0, 64], [0, 20, 64], [0, 3, 7, 8, 20, 21, 33, 64], list(range(0, 65, 4)), [0, 31, 32, 64],
])
def test_merged_chunks_equal_the_single_pass_bit_for_bit(bounds, dip_sweep):
    frames = _hard_sweep(dip_sweep)
    whole = DipTracker(frames.shape[1:3], half_window=3)
    whole.update(frames)
    expected = whole.result()
    # shuffled order: the merge does not depend on it
    partials = _chunked(frames, bounds, half_window=3)[::-1]
    _summaries_equal(merge_partials(partials, n_frames=64), expected)


def test_flat_minima_are_centred_close_equal_dips_seen_and_minus_inf_ignored(dip_sweep):
    frames = _hard_sweep(dip_sweep)
    tracker = DipTracker(frames.shape[1:3], half_window=3)
    tracker.update(frames)
    summary = tracker.result()
    # an even flat run 17..22: its later middle; a run longer than the window: h after its start
    assert np.all(summary.minimum_frame[0, 2:4] == 20)
    assert np.all(summary.minimum_frame[0, 4:] == 32) and np.all(summary.second_frame[0, 4:] == 20)
    # equal dips closer than a window: the earlier is the minimum, the later the second
    assert np.all(summary.minimum_frame[3, :3] == 44) and np.all(summary.second_frame[3, :3] == 49)
    assert np.all(summary.second_value[3, :3] == summary.minimum_value[3, :3])
    # -inf is counted, not taken for the deepest dip
    assert summary.minimum_frame[5, 4] == 63 and summary.invalid_count[5, 4] == 1


def test_second_dip_is_a_local_minimum_a_window_away_and_a_ramp_has_none(dip_sweep):
    frames = _hard_sweep(dip_sweep)
    tracker = DipTracker(frames.shape[1:3], half_window=3)
    tracker.update(frames)
    summary = tracker.result()
    assert np.all(summary.minimum_frame[2] == 31)
    assert np.all(summary.second_frame[2] == 50)
    assert summary.second_value[3, 3] == np.inf and summary.minimum_frame[3, 3] == 63
    np.testing.assert_allclose(summary.channel_sum.sum(axis=2), np.nansum(
        np.where(np.isfinite(frames), frames, 0), axis=(0, 3)), rtol=1e-6)
    assert summary.invalid_count[5, 5] == 1 and summary.invalid_count[4, 6] == 1


def test_partial_round_trips_through_an_atomic_file(tmp_path, dip_sweep):
    frames = _hard_sweep(dip_sweep)
    partials = _chunked(frames, [0, 25, 64], half_window=2)
    paths = []
    for i, part in enumerate(partials):
        path = tmp_path / f"chunk{i}.npz"
        part.save(path)
        paths.append(path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["chunk0.npz", "chunk1.npz"]
    loaded = [DipPartial.load(p) for p in paths]
    _summaries_equal(merge_partials(loaded, n_frames=64), merge_partials(partials, n_frames=64))


def test_merge_rejects_gaps_and_short_feeds(dip_sweep):
    frames = _hard_sweep(dip_sweep)
    partials = _chunked(frames, [0, 20, 40, 64], half_window=2)
    with pytest.raises(ValueError, match="tile"):
        merge_partials([partials[0], partials[2]], n_frames=64)
    with pytest.raises(ValueError, match="n_frames"):
        merge_partials(partials, n_frames=70)
    short = DipTracker(frames.shape[1:3], half_window=2, owned=(0, 20))
    short.update(frames[:21])
    with pytest.raises(ValueError, match="fed frames up to"):
        merge_partials([short.partial(), *partials[1:]], n_frames=64)
    tracker = DipTracker(frames.shape[1:3], half_window=2, owned=(20, 40))
    with pytest.raises(ValueError, match="first_index"):
        tracker.update(frames[20:30], first_index=20)


@pytest.mark.parametrize("scale", [1.0, 3e5])  # 3e5: above 2**17, summed one sample at a time
@pytest.mark.parametrize("block", [7, 40])
def test_fixed_point_sums_are_exact_for_small_and_large_samples(scale, block):
    from shadowcam.lab.dip_kernels import quantise_sum, split_square

    rng = np.random.default_rng(7)
    frames = (rng.random((70, 3, 5, 3)) * scale).astype(np.float32)
    frames[5, 1, 2, 1] = np.nan
    tracker = DipTracker(frames.shape[1:3], half_window=2)
    for start in range(0, 70, block):
        tracker.update(frames[start:start + block])
    partial = tracker.partial()
    signal = frames[..., 0] + frames[..., 1] + frames[..., 2]  # float32, in channel order
    np.testing.assert_array_equal(partial.signal_sum, quantise_sum(signal).sum(axis=0))
    np.testing.assert_array_equal(partial.channel_sum, quantise_sum(frames).sum(axis=0))
    np.testing.assert_array_equal(partial.count, np.isfinite(signal).sum(axis=0))
    hi, lo = split_square(signal)
    np.testing.assert_array_equal(partial.square_hi, hi.sum(axis=0))
    np.testing.assert_array_equal(partial.square_lo, lo.sum(axis=0))


def test_window_sums_match_the_running_sums_arithmetic():
    """What merge_partials takes out of the running sums is what they added for those samples."""
    from shadowcam.lab.dip_kernels import quantise_sum, split_square, window_sums

    rng = np.random.default_rng(3)
    window = (rng.random((9, 50)) * np.array([1.0] * 25 + [3e5] * 25)).astype(np.float32)
    window[2, 4], window[0, 7], window[5, 8] = np.nan, np.inf, -np.inf
    keep = rng.random(50) < 0.8
    count, fixed_sum, square_hi, square_lo = window_sums(window, keep)
    hi, lo = split_square(window)
    np.testing.assert_array_equal(count, np.where(keep, np.isfinite(window).sum(axis=0), 0))
    np.testing.assert_array_equal(fixed_sum, np.where(keep, quantise_sum(window).sum(axis=0), 0))
    np.testing.assert_array_equal(square_hi, np.where(keep, hi.sum(axis=0), 0))
    np.testing.assert_array_equal(square_lo, np.where(keep, lo.sum(axis=0), 0))
