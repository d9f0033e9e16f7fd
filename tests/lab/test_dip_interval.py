"""Tests of the dip-interval pass: entry and exit of a dip of any width, against exact crossings."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from shadowcam.lab.dip_tracker import (DipTracker, IntervalTracker, half_depth, merge_intervals, track_intervals,
                                        window_intervals)


def trapezoid(n_frames, *, entry, plateau, ramp, depth=0.8, level=1.0, floor=0.0):
    """Signal ``(T,)``: lit `level` (+ `floor`), linear ramps of `ramp` frames down to ``level - depth``.

    The ramp down starts at ``entry - ramp / 2`` and the half-depth crossings are at
    ``entry`` and ``entry + ramp + plateau`` exactly; `floor` is light of a second
    source that the mask does not shadow.
    """
    t = np.arange(n_frames, dtype=np.float64)
    down = entry - ramp / 2
    up = entry + ramp / 2 + plateau
    coverage = np.clip((t - down) / ramp, 0, 1) * np.clip((up + ramp - t) / ramp, 0, 1)
    return floor + level - depth * coverage, entry, entry + ramp + plateau


def run(signal, threshold, centre, blocks=(7,)):
    """The interval of a 1-D signal (one pixel), fed in blocks cycling through `blocks`."""
    n = signal.shape[0]
    frames = signal.astype(np.float32)[:, None, None]
    tracker = IntervalTracker(np.array([[centre]]), np.array([[threshold]]), half_window=4, n_frames=n)
    i, k = 0, 0
    while i < n:
        size = blocks[k % len(blocks)]
        tracker.update(frames[i:i + size])
        i += size
        k += 1
    return tracker.result()


@settings(max_examples=60, deadline=None)
@given(plateau=st.integers(1, 200), ramp=st.integers(4, 12), phase=st.floats(0, 1),
       floor=st.floats(0, 2), block=st.integers(1, 40))
def test_entry_and_exit_are_the_exact_half_depth_crossings(plateau, ramp, phase, floor, block):
    n = plateau + 2 * ramp + 40
    signal, entry, exit_ = trapezoid(n, entry=20 + ramp / 2 + phase, plateau=plateau, ramp=ramp,
                                     floor=floor)
    centre = int(round((entry + exit_) / 2))
    interval = run(signal, floor + 1.0 - 0.4, centre, blocks=(block,))
    # linear ramps of >= 4 frames: the [1, 2, 1] smoothing keeps them, interpolation is exact
    np.testing.assert_allclose(interval.entry[0, 0], entry, atol=2e-4)
    np.testing.assert_allclose(interval.exit[0, 0], exit_, atol=2e-4)
    np.testing.assert_allclose(interval.at(0.5)[0, 0], (entry + exit_) / 2, atol=2e-4)
    assert not interval.entry_open[0, 0] and not interval.exit_open[0, 0]
    np.testing.assert_allclose(interval.entry_slope[0, 0], 0.8 / ramp, rtol=1e-3)


@settings(max_examples=40, deadline=None)
@given(plateau=st.integers(1, 200), at_start=st.booleans())
def test_a_dip_at_the_sweeps_end_is_open_on_that_side(plateau, at_start):
    n = plateau + 30
    # frame 0 on the plateau, or the signal never coming back up after it
    signal, entry, exit_ = trapezoid(n, entry=-2.5 if at_start else 15.0, plateau=plateau, ramp=4)
    if not at_start:
        signal[int(entry) + 4:] = 0.2
    centre = 0 if at_start else n - 1
    interval = run(signal, 0.6, centre)
    assert interval.entry_open[0, 0] == at_start
    assert interval.exit_open[0, 0] != at_start
    assert np.isnan(interval.entry[0, 0]) == at_start
    assert np.isnan(interval.exit[0, 0]) != at_start
    if at_start:
        np.testing.assert_allclose(interval.exit[0, 0], exit_, atol=2e-4)
    else:
        np.testing.assert_allclose(interval.entry[0, 0], entry, atol=2e-4)


@settings(max_examples=40, deadline=None)
@given(width=st.integers(6, 60), gap=st.integers(3, 60), second_depth=st.floats(0.2, 0.75))
def test_a_close_second_minimum_does_not_move_the_deepest_ones_interval(width, gap, second_depth):
    # two dips closer than their widths; the signal between them comes back above half depth
    n = 2 * width + gap + 60
    first, entry, exit_ = trapezoid(n, entry=20.0, plateau=width - 4, ramp=4, depth=0.8)
    second, _, _ = trapezoid(n, entry=exit_ + gap, plateau=width - 4, ramp=4, depth=second_depth)
    signal = first + second - 1.0
    interval = run(signal, 0.6, int(entry + 2))
    np.testing.assert_allclose([interval.entry[0, 0], interval.exit[0, 0]], [entry, exit_], atol=2e-4)


@settings(max_examples=40, deadline=None)
@given(plateau=st.integers(4, 200), where=st.floats(0, 1), inside=st.booleans())
def test_non_finite_samples_inside_are_counted_outside_ignored(plateau, where, inside):
    n = plateau + 60
    signal, entry, exit_ = trapezoid(n, entry=20.0, plateau=plateau, ramp=4)
    if inside:
        frame = int(entry + 3 + where * (exit_ - entry - 6))
    else:
        frame = int(exit_ + 4 + where * (n - exit_ - 6))
    signal[frame] = np.nan if where < 0.5 else np.inf
    # the deepest minimum (the centre) is a finite frame on the plateau, two frames from the bad one
    centre = frame + 2 if inside and frame + 2 < exit_ - 2 else (frame - 2 if inside else int(entry) + 3)
    interval = run(signal, 0.6, centre)
    if inside:
        # the non-finite sample spoils the smoothed values of its frame and both neighbours
        assert interval.invalid[0, 0] >= 1
    else:
        assert interval.invalid[0, 0] == 0
        np.testing.assert_allclose([interval.entry[0, 0], interval.exit[0, 0]], [entry, exit_], atol=2e-4)


def test_low_snr_entry_and_exit_errors_follow_the_noise_over_the_slope():
    # 2000 pixels, noise 5 % of the lit level, ramps of 6 frames, depth 0.5: the smoothed noise
    # (0.61 sigma) over the slope per frame gives each crossing's standard deviation
    rng = np.random.default_rng(4)
    n, ramp, depth, sigma = 300, 6, 0.5, 0.05
    signal, entry, exit_ = trapezoid(n, entry=100.3, plateau=40, ramp=ramp, depth=depth)
    frames = (signal[:, None, None] + rng.normal(0, sigma, (n, 40, 50))).astype(np.float32)
    tracker = DipTracker((40, 50), half_window=4)
    tracker.update(frames)
    summary = tracker.result()
    threshold = np.full((40, 50), 1.0 - depth / 2)
    interval = track_intervals([frames], summary, threshold=threshold)
    expected_std = 0.61 * sigma / (depth / ramp)
    for measured, truth in ((interval.entry, entry), (interval.exit, exit_)):
        errors = measured - truth
        assert np.isfinite(errors).mean() > 0.99
        assert abs(np.nanmedian(errors)) < 0.1
        assert np.nanstd(errors) < 1.6 * expected_std


@pytest.mark.parametrize("cuts", [[0, 17, 300], [0, 1, 2, 150, 151, 299, 300], [0, 100, 200, 300]])
def test_time_chunks_merge_bit_for_bit(cuts):
    rng = np.random.default_rng(1)
    n = 300
    signal, _, _ = trapezoid(n, entry=80.4, plateau=120, ramp=6)
    frames = (signal[:, None, None] + rng.normal(0, 0.05, (n, 6, 7))).astype(np.float32)
    frames[150, 2, 3] = np.nan
    tracker = DipTracker((6, 7), half_window=3)
    tracker.update(frames)
    summary = tracker.result()
    threshold = 0.5 * (summary.lit_level + summary.minimum_value)
    whole = track_intervals([frames], summary, threshold=threshold)
    parts = []
    for start, stop in zip(cuts[:-1], cuts[1:]):
        chunk = IntervalTracker(summary.minimum_frame, threshold, half_window=3, n_frames=n, owned=(start, stop))
        lo, hi = max(0, start - 2), min(n, stop + 2)
        for i in range(lo, hi, 5):
            chunk.update(frames[i:min(i + 5, hi)])
        parts.append(chunk.partial())
    merged = merge_intervals(parts[::-1], n_frames=n, threshold=threshold)
    for name in ("entry", "exit", "entry_slope", "exit_slope", "invalid", "entry_open", "exit_open",
                 "beyond_count", "beyond_sum", "beyond_square"):
        np.testing.assert_array_equal(getattr(merged, name), getattr(whole, name), err_msg=name)


def test_state_does_not_grow_with_the_frames():
    tracker = IntervalTracker(np.zeros((3, 4), int), np.ones((3, 4)), half_window=4, n_frames=5000)
    before = sum(v.nbytes for v in tracker._state.values())
    for _ in range(50):
        tracker.update(np.ones((100, 3, 4), np.float32))
    assert sum(v.nbytes for v in tracker._state.values()) == before
    assert tracker._carry.shape[0] == 2


def test_invalid_arguments_name_the_parameter():
    with pytest.raises(ValueError, match="owned"):
        IntervalTracker(np.zeros((2, 2), int), np.ones((2, 2)), half_window=4, n_frames=10, owned=(5, 5))
    with pytest.raises(ValueError, match="n_frames"):
        IntervalTracker(np.zeros((2, 2), int), np.ones((2, 2)), half_window=4, n_frames=0)
    tracker = IntervalTracker(np.zeros((2, 2), int), np.ones((2, 2)), half_window=4, n_frames=10)
    with pytest.raises(ValueError, match="block"):
        tracker.update(np.ones((3, 2, 3), np.float32))


def _tracked_trapezoid(plateau, ramp, phase, floor):
    """A trapezoid dip (depth 0.8) covering at most a third of the sweep (the level's
    correction is first order in the first pass's level error), tracked by the first pass
    and the interval pass: (first pass, corrected summary, interval, true entry, exit)."""
    from shadowcam.lab.dip_tracker import without_interval

    n = 3 * (plateau + 2 * ramp) + 60
    signal, entry, exit_ = trapezoid(n, entry=30 + ramp / 2 + phase, plateau=plateau, ramp=ramp,
                                     depth=0.8, floor=floor)
    frames = signal.astype(np.float32)[:, None, None]
    tracker = DipTracker((1, 1), half_window=4)
    tracker.update(frames)
    first = tracker.result()
    summary, interval = without_interval(first, track_intervals([frames], first))
    return first, summary, interval, entry, exit_


@settings(max_examples=30, deadline=None)
@given(plateau=st.integers(10, 200), ramp=st.integers(4, 10), phase=st.floats(0, 1), floor=st.floats(0, 1))
def test_wide_dip_half_depth_of_the_true_lit_level(plateau, ramp, phase, floor):
    # the tracker's lit level counts the plateau beyond its window as lit; without_interval
    # takes it out, and the crossings land on the true half depth
    first, summary, interval, entry, exit_ = _tracked_trapezoid(plateau, ramp, phase, floor)
    # what stays counted as lit: the ramps' frames at or above half depth, at most
    # ramp / 2 + 1 each side, removing at most depth / 2 each; the crossing moves by half
    # the level's error over the slope, plus up to 0.1 frame from the first-order move along
    # a smoothed ramp's corner
    bound = (ramp + 2) * 0.4 / summary.lit_count[0, 0]
    assert 0 <= 1.0 + floor - summary.lit_level[0, 0] <= bound
    assert summary.noise[0, 0] < 0.8 * np.sqrt(ramp / summary.lit_count[0, 0])
    np.testing.assert_allclose([interval.entry[0, 0], interval.exit[0, 0]], [entry, exit_],
                               atol=0.5 * bound / (0.8 / ramp) + 0.1)
    # and the first pass alone is off by the plateau
    assert 1.0 + floor - first.lit_level[0, 0] > bound


@settings(max_examples=30, deadline=None)
@given(plateau=st.integers(10, 200), ramp=st.integers(4, 10), phase=st.floats(0, 1), floor=st.floats(0, 1))
def test_wide_dip_lit_level_leaves_out_the_penumbra_ramps(plateau, ramp, phase, floor):
    # the ramp frames above half depth outside the window lack light too: with them taken
    # out the lit level is the unoccluded one to 1 % of the depth (the straight ramp through
    # the smoothed crossing; sampling of its ends), and the crossings land within 0.1 frame
    # of the exact ones (the first-order move along a short ramp's smoothed corner)
    first, summary, interval, entry, exit_ = _tracked_trapezoid(plateau, ramp, phase, floor)
    assert abs(1.0 + floor - summary.lit_level[0, 0]) <= 0.01 * 0.8
    np.testing.assert_allclose([interval.entry[0, 0], interval.exit[0, 0]], [entry, exit_], atol=0.1)


def full_pass(frames, summary, threshold):
    """The interval pass over every frame for every pixel (the reference)."""
    tracker = IntervalTracker(summary.minimum_frame, threshold, half_window=summary.half_window,
                              n_frames=summary.n_frames)
    tracker.update(frames)
    return tracker.result()


_INTERVAL_FIELDS = ("entry", "exit", "entry_slope", "exit_slope", "invalid", "entry_open", "exit_open",
                    "threshold", "beyond_count", "beyond_sum", "beyond_square")


@settings(max_examples=40, deadline=None)
@given(n=st.integers(3, 60), half_window=st.integers(1, 5), seed=st.integers(0, 2**16),
       nan_rate=st.sampled_from([0.0, 0.0, 0.02]))
def test_window_and_second_pass_equal_the_full_pass_bit_for_bit(n, half_window, seed, nan_rate):
    # dips of every width from none to wider than the window, anywhere (also cut by the sweep's
    # ends), with noise and the odd non-finite sample
    rng = np.random.default_rng(seed)
    shape = (6, 9)
    t = np.arange(n)[:, None, None]
    centre = rng.uniform(-3, n + 3, shape)
    width = rng.choice([0.0, 0.5, 1.5, 3.0, 8.0, 30.0], shape)
    depth = rng.uniform(0, 1, shape)
    frames = 1.0 - depth * (np.abs(t - centre) < width / 2) + rng.normal(0, 0.05, (n,) + shape)
    frames = frames.astype(np.float32)
    frames[rng.random(frames.shape) < nan_rate] = np.nan
    tracker = DipTracker(shape, half_window=half_window)
    tracker.update(frames)
    summary = tracker.result()
    reference = full_pass(frames, summary, half_depth(summary))
    interval = track_intervals(iter([frames]), summary)
    for name in _INTERVAL_FIELDS:
        np.testing.assert_array_equal(getattr(interval, name), getattr(reference, name), err_msg=name)


def test_dips_inside_the_window_need_no_second_pass():
    # a 2-frame dip under a 4-frame half window, noise free, away from the sweep's ends: every
    # crossing lies in the stored window, so the frames are not read again
    n, shape = 80, (5, 7)
    centre = 20 + np.arange(35).reshape(shape)
    frames = np.ones((n,) + shape, np.float32)
    for offset in (0, 1):
        np.put_along_axis(frames, (centre + offset)[None], 0.2, axis=0)
    tracker = DipTracker(shape, half_window=4)
    tracker.update(frames)
    summary = tracker.result()
    partial, resolved = window_intervals(summary, half_depth(summary))
    assert resolved.all()

    def unread():
        raise AssertionError("the frames were read again")
        yield

    interval = track_intervals(unread(), summary)
    reference = full_pass(frames, summary, half_depth(summary))
    for name in _INTERVAL_FIELDS:
        np.testing.assert_array_equal(getattr(interval, name), getattr(reference, name), err_msg=name)
    # smoothed [1, 2, 1] / 4 of a 2-frame dip of depth 0.8: 1, 0.8, 0.4, 0.4, 0.8, 1 around it;
    # lit level 1, smoothed minimum 0.4: half depth 0.7 is crossed a quarter of the way from
    # the 0.8 frame to the 0.4 frame (float32 threshold)
    np.testing.assert_allclose(interval.entry, centre - 0.75, atol=1e-6)
    np.testing.assert_allclose(interval.exit, centre + 1.75, atol=1e-6)


def test_a_dip_wider_than_the_window_is_left_to_the_second_pass():
    n = 120
    signal, entry, exit_ = trapezoid(n, entry=40.0, plateau=30, ramp=4)
    frames = signal.astype(np.float32)[:, None, None]
    tracker = DipTracker((1, 1), half_window=4)
    tracker.update(frames)
    summary = tracker.result()
    _, resolved = window_intervals(summary, half_depth(summary))
    assert not resolved.any()
    with pytest.raises(ValueError, match="threshold must have the summary's shape"):
        window_intervals(summary, np.zeros((2, 2)))
