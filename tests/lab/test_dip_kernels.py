"""The tracker update (running minima of the half windows) against a test of every neighbour."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from shadowcam.lab import dip_kernels as _k
from shadowcam.lab.dip_tracker import DipTracker


def _fresh_state(n_p, n_c, half_window):
    k = 2 * half_window + 1
    return dict(raw=np.full((k + 2, n_p), np.nan, np.float32), smooth=np.full((k + 2, n_p), np.nan, np.float32),
                top_value=np.full((_k.TOP, n_p), np.inf, np.float32),
                top_frame=np.full((_k.TOP, n_p), -1, np.int64), window=np.full((k, n_p), np.nan, np.float32),
                signal_sum=np.zeros(n_p, np.int64), square_hi=np.zeros(n_p), square_lo=np.zeros(n_p),
                count=np.zeros(n_p, np.int64), invalid=np.zeros(n_p, np.int64),
                channel_sum=np.zeros((n_c, n_p), np.int64), saturated=np.zeros(n_p, bool))


def _reference_update(block, first_index, start, stop, half_window, saturation_level, state):
    """The update frame by frame in numpy: every centre against each smoothed value within the window.

    Slow reference of :func:`dip_kernels.track_block`: the candidate test
    compares the centre with the ``2 * half_window`` smoothed values around it
    (NaN decides nothing); the pixels that pass are inserted by the library's
    scalar helpers (no equal value around: directly; else the flat-run rules).
    Sums are the exact per-sample fixed point (:func:`quantise_sum`,
    :func:`split_square`).
    """
    h = half_window
    raw, smooth = state["raw"], state["smooth"]
    top_value, top_frame, window = state["top_value"], state["top_frame"], state["window"]
    r = raw.shape[0]
    n_t, _, n_c = block.shape
    slots = np.empty(2 * h + 3, np.uint64)
    for t in range(n_t):
        j = first_index + t
        x = block[t, :, 0].copy()
        with np.errstate(invalid="ignore"):  # inf - inf: NaN, as the kernel
            for c in range(1, n_c):
                x += block[t, :, c]
        x[~np.isfinite(x)] = np.nan
        raw[j % r] = x
        if j >= 1:
            before = (j - 2) % r if j >= 2 else (j - 1) % r
            smoothed = raw[(j - 1) % r] * np.float32(0.5)
            smoothed += np.float32(0.25) * raw[before]
            smoothed += np.float32(0.25) * raw[j % r]
            smooth[(j - 1) % r] = smoothed
        if start <= j < stop:
            ok = np.isfinite(x)
            state["signal_sum"] += _k.quantise_sum(x)
            hi, lo = _k.split_square(x)
            state["square_hi"] += hi
            state["square_lo"] += lo
            state["count"] += ok
            state["invalid"] += ~ok
            for c in range(n_c):
                v = block[t, :, c]
                state["saturated"] |= (v >= saturation_level) & (v < np.inf)
                state["channel_sum"][c] += _k.quantise_sum(x if n_c == 1 else v)
        centre = j - h - 1
        if start <= centre < stop and centre >= 0:
            _k._ring_slots(centre, h, r, slots)
            sc = smooth[slots[h + 1]].copy()
            hit = sc < top_value[_k.TOP - 1]
            for d in range(1, h + 1):
                hit &= ~(smooth[slots[h + 1 - d]] < sc) & ~(smooth[slots[h + 1 + d]] < sc)
            neighbours = smooth[np.r_[slots[1:h + 1], slots[h + 2:2 * h + 2]]]
            for p in np.flatnonzero(hit):
                if not (neighbours[:, p] == sc[p]).any():  # a strict minimum
                    if _k._insert(top_value, top_frame, p, sc[p], centre):
                        _k._copy_window(raw, p, centre, j + 1, h, window, slots)
                else:
                    _k._consider(raw, smooth, p, centre, j + 1, h, top_value, top_frame, window, slots)


def _feed_both(frames, blocks, start, stop, half_window, saturation_level=np.float32(0.999)):
    """Feed `frames` ``(T, P, C)`` in `blocks` to the kernel and to the reference; both states."""
    n_t, n_p, n_c = frames.shape
    first = max(0, start - DipTracker.padding(half_window))
    kernel, reference = _fresh_state(n_p, n_c, half_window), _fresh_state(n_p, n_c, half_window)
    bounds = [first] + sorted({b for b in blocks if first < b < n_t}) + [n_t]
    for b0, b1 in zip(bounds[:-1], bounds[1:]):
        block = np.ascontiguousarray(frames[b0:b1])
        _k.track_block(block, b0, start, stop, half_window, saturation_level, *kernel.values())
        _reference_update(block, b0, start, stop, half_window, saturation_level, reference)
    return kernel, reference


def _assert_states_equal(kernel, reference):
    for name, value in kernel.items():
        np.testing.assert_array_equal(value, reference[name], err_msg=name, strict=True)


# values on a coarse grid (ties, flat runs, plateaus longer than the window) with NaN and +-inf
_SAMPLE = st.one_of(st.integers(0, 6).map(float), st.sampled_from([np.nan, np.inf, -np.inf, 0.5, 1e6]))


@st.composite
def _sweeps(draw):
    half_window = draw(st.integers(1, 4))
    n_t = draw(st.integers(1, 40))
    n_p = draw(st.integers(1, 6))
    n_c = draw(st.integers(1, 3))
    frames = np.array(draw(st.lists(_SAMPLE, min_size=n_t * n_p * n_c, max_size=n_t * n_p * n_c)),
                      np.float32).reshape(n_t, n_p, n_c)
    start = draw(st.integers(0, n_t))
    stop = draw(st.integers(start, n_t + 3))
    blocks = draw(st.lists(st.integers(1, max(1, n_t - 1)), max_size=5))
    return frames, blocks, start, stop, half_window


@settings(max_examples=300, deadline=None)
@given(_sweeps())
def test_update_equals_the_window_test_bit_for_bit(sweep):
    frames, blocks, start, stop, half_window = sweep
    kernel, reference = _feed_both(frames, blocks, start, stop, half_window)
    _assert_states_equal(kernel, reference)


def test_update_equals_the_window_test_across_tiles_and_blocks():
    """3 tiles of pixels, a noisy wide and narrow dip, blocks that split the window's frame groups."""
    rng = np.random.default_rng(7)
    n_t, n_p = 90, 2 * _k.TILE + 37
    t = np.arange(n_t)[:, None]
    centre = rng.uniform(-5, n_t + 5, n_p)
    width = rng.choice([0.8, 6.0], n_p)
    signal = 100 - 60 * np.exp(-0.5 * ((t - centre) / width) ** 2) + rng.normal(0, 3, (n_t, n_p))
    frames = np.round(signal).astype(np.float32)[..., None]  # integer levels: ties within windows
    frames[rng.random(frames.shape) < 0.01] = np.nan
    for half_window, start, stop in ((4, 0, n_t), (3, 23, 61), (1, 5, 200)):
        kernel, reference = _feed_both(frames, [7, 16, 17, 50, 51, 52], start, stop, half_window)
        _assert_states_equal(kernel, reference)
        assert np.isfinite(kernel["top_value"][0]).mean() > 0.9  # the test does select minima
