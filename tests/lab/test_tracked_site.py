"""Tests of the own-site values kept by the dip tracker (``DipTracker(own_site=True)``, RAW files)."""

from dataclasses import fields

import numpy as np
import pytest

from shadowcam.lab.dip_tracker import DipPartial, DipTracker, merge_partials
from shadowcam.lab.site_signal import site_window_of_sums, site_window_sums, tracked_site_window

N_FRAMES, HALF = 64, 3


@pytest.fixture(scope="module")
def sweep(wire_sweep):
    """Signal ``(T, 6, 8)`` with noisy dips (some at the sweep's ends), the sites' own values, non-finite samples."""
    centres = np.linspace(1.0, N_FRAMES - 2.0, 48).reshape(6, 8)
    signal, _ = wire_sweep(n_frames=N_FRAMES, centres=[centres], width=2.0, shape=(6, 8), level=1.8,
                           depth=0.8, seed=4, noise=0.02)
    rng = np.random.default_rng(5)
    own = (signal * rng.uniform(0.25, 0.4, signal.shape[1:]) + rng.normal(0, 0.01, signal.shape)).astype(np.float32)
    signal = signal.astype(np.float32)
    own[10, 0, 0] = np.nan
    own[30, 1, 1] = np.inf
    signal[20, 2, 2] = np.nan  # own finite, neighbours' part not: that pixel has no neighbour statistics
    return signal, own


def _track(signal, own, owned=None, block=7):
    tracker = DipTracker(signal.shape[1:], half_window=HALF, owned=owned, own_site=True)
    pad = DipTracker.padding(HALF)
    first = 0 if owned is None else max(0, owned[0] - pad)
    last = N_FRAMES if owned is None else min(N_FRAMES, owned[1] + pad)
    for start in range(first, last, block):
        stop = min(start + block, last)
        tracker.update(signal[start:stop], first_index=start, own=own[start:stop])
    return tracker


def test_own_window_holds_the_own_values_at_the_windows_frames(sweep):
    signal, own = sweep
    summary = _track(signal, own).result()
    site = summary.tracked_site
    frames = summary.window_start[None] + np.arange(2 * HALF + 1)[:, None, None]
    inside = (frames >= 0) & (frames < N_FRAMES)
    expected = np.take_along_axis(own, np.clip(frames, 0, N_FRAMES - 1), axis=0)
    expected = np.where(inside & np.isfinite(expected), expected, np.nan)
    np.testing.assert_array_equal(site.window, expected)
    assert np.any(summary.window_start < 0) and np.any(summary.window_start + 2 * HALF >= N_FRAMES)


def test_lit_statistics_equal_a_pass_outside_the_window(sweep):
    """Against the direct sums over the frames outside each window (site_window_sums, float64).

    Tolerances: each own sample enters the exact sums rounded to 2**-32 and its square's
    low part to 2**-40 (dip_kernels), so the level moves by under 2**-33 and the variance
    by under 2**-41 (noise ~0.01 here: under 1e-10).
    """
    signal, own = sweep
    summary = _track(signal, own).result()
    colour = np.zeros(signal.shape[1:], np.int8)
    direct = site_window_of_sums([site_window_sums([(own, signal)], summary.window_start, 2 * HALF + 1)],
                                 summary, site_colour=colour)
    tracked = tracked_site_window(summary, colour)
    np.testing.assert_array_equal(tracked.count, direct.count)
    np.testing.assert_array_equal(tracked.colour, colour)
    assert np.isnan(tracked.neighbour_level[2, 2]) and np.isnan(direct.neighbour_level[2, 2])
    for name in ("level", "neighbour_level"):
        np.testing.assert_allclose(getattr(tracked, name), getattr(direct, name), rtol=0, atol=2.0**-33, err_msg=name)
    for name in ("noise", "neighbour_noise"):
        np.testing.assert_allclose(getattr(tracked, name), getattr(direct, name), rtol=0, atol=1e-10, err_msg=name)


@pytest.mark.parametrize("bounds", [[0, 20, 64], [0, 3, 7, 8, 20, 21, 33, 64], [0, 31, 32, 64]])
def test_merged_chunks_equal_the_single_pass_bit_for_bit(bounds, sweep):
    signal, own = sweep
    expected = _track(signal, own, block=64).result().tracked_site
    partials = [_track(signal, own, owned=(a, b), block=5).partial() for a, b in zip(bounds[:-1], bounds[1:])]
    merged = merge_partials(partials[::-1], n_frames=N_FRAMES).tracked_site
    for field in fields(merged):
        np.testing.assert_array_equal(getattr(merged, field.name), getattr(expected, field.name), err_msg=field.name)


def test_own_site_is_optional_and_round_trips(tmp_path, sweep):
    signal, own = sweep
    plain = DipTracker(signal.shape[1:], half_window=HALF)
    plain.update(signal)
    assert plain.result().tracked_site is None
    with pytest.raises(ValueError, match="own_site"):
        DipTracker(signal.shape[1:], half_window=HALF).update(signal, own=own)
    with pytest.raises(ValueError, match="own_site"):
        DipTracker(signal.shape[1:], half_window=HALF, own_site=True).update(signal)
    with pytest.raises(ValueError, match="own must have shape"):
        DipTracker(signal.shape[1:], half_window=HALF, own_site=True).update(signal, own=own[:3])
    with pytest.raises(ValueError, match="tracked_site"):
        tracked_site_window(plain.result(), np.zeros(signal.shape[1:], np.int8))
    for tracker, name in ((_track(signal, own), "own.npz"), (DipTracker(signal.shape[1:], half_window=HALF), "plain.npz")):
        if not tracker.own_site:
            tracker.update(signal)
        tracker.partial().save(tmp_path / name)
        loaded = DipPartial.load(tmp_path / name)
        for field in fields(DipPartial):
            a, b = getattr(loaded, field.name), getattr(tracker.partial(), field.name)
            assert (a is None) == (b is None), field.name
            if a is not None:
                np.testing.assert_array_equal(a, b, err_msg=field.name)
