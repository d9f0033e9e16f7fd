"""A light whose dip the sweep cannot show is flagged (``unresolved_dip``, ``shown`` False),
not timed on its noise minima; a dip just above the noise is timed."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.special import ndtr
from scipy.stats import binom

from shadowcam.lab.light_assignment import OK, UNRESOLVED, assign_minima, place_noise_probability
from shadowcam.lab.minima import find_minima

SHAPE, FRAMES, LEVEL = (16, 24), 48, 1.0


def _sweep(dips, *, sigma, seed):
    """(T, H, W, 1) frames: LEVEL minus box dips under Gaussian noise `sigma`.

    `dips`: (start (H, W) int frames, width frames, depth) per light; the exact time of a
    box over frames ``start .. start + width - 1`` is ``start + (width - 1) / 2``.
    """
    t = np.arange(FRAMES)[:, None, None]
    signal = np.full((FRAMES, *SHAPE), LEVEL)
    for start, width, depth in dips:
        signal -= depth * ((t >= start[None]) & (t < start[None] + width))
    noise = np.random.default_rng(seed).normal(0.0, sigma, signal.shape)
    return (signal + noise)[..., None]


def _start(offset):
    """A smooth integer map of dip starts: one frame later every four columns."""
    y, x = np.indices(SHAPE)
    return offset + x // 4 + y // 8


def _assigned(dips, sigma, seed=1):
    frames = _sweep(dips, sigma=sigma, seed=seed)
    minima = find_minima(frames, SHAPE, count=len(dips), half_window=4)
    return minima, assign_minima(minima, len(dips))


def _within_noise(a, k, truth, depth):
    """Light k's times within their derived tolerance of the 2-frame box's exact time.

    The centroid's noise (``time_std``: the method's propagation of the sample noise over
    the window) at 4.5 deviations for 384 pixels (P(any beyond) ~ 1e-3), plus the pull of
    the window's 16 lit samples, whose noise is clipped at zero coverage (mean 0.4 sigma
    each): at most half a frame (the window's asymmetry about the box) times their share
    of the coverage.
    """
    ok = a["reason"][k] == OK
    err = np.abs(a["time"][k] - truth)[ok]
    lit_share = 16 * SIGMA * 0.4 / (16 * SIGMA * 0.4 + 2 * depth)
    assert np.all(err <= 4.5 * a["time_std"][k][ok] + 0.5 * lit_share)


SIGMA = 0.01
SHARP = (_start(6), 2, 0.3)  # a point light's dip: 30 noise deviations deep


def test_a_shadow_below_the_noise_gives_no_times_and_says_so():
    # light 1: a 14-frame shadow 2.5 noise deviations deep (a tube lying along the wire)
    minima, a = _assigned([SHARP, (_start(22), 14, 2.5 * SIGMA)], SIGMA)
    # the minima given to it are its noise minima; some pass the detection (deepest of 14
    # floor samples)...
    given = a["minimum"][1] >= 0
    found = given & (np.take_along_axis(minima.reason, np.maximum(a["minimum"][1:], 0), 0)[0] == OK)
    assert found.sum() >= 5
    # ...but none is timed: no time, exactly those pixels say the dip is unresolved, the
    # light is not shown
    assert np.all(np.isnan(a["time"][1])) and np.all(a["reason"][1] != OK)
    assert np.array_equal(a["reason"][1] == UNRESOLVED, found)
    assert list(a["shown"]) == [True, False]
    # the sharp light keeps its exact times
    assert np.mean(a["reason"][0] == OK) > 0.99
    _within_noise(a, 0, SHARP[0] + 0.5, SHARP[2])


def test_a_dip_just_above_the_noise_is_timed_within_its_noise():
    # light 1: a sharp 2-frame dip 8 noise deviations deep. Resolved where the observed
    # difference to every far sample beats z = Q^-1(1e-3 / 14) sqrt(2) = 5.8 deviations; the
    # observed difference is 8 deviations, plus the noise of the deeper of the box's two
    # samples (about +0.6), less the lowest of the 14 far samples' noise (about -1.7): about
    # 1.1 above, one deviation of the difference, so nearly every pixel is timed (at 6.5
    # deviations 15 % are not: a lit sample 3.5 deviations low could have been the minimum)
    depth = 8 * SIGMA
    minima, a = _assigned([SHARP, (_start(26), 2, depth)], SIGMA, seed=3)
    assert list(a["shown"]) == [True, True]
    ok = a["reason"][1] == OK
    assert ok.mean() > 0.97
    _within_noise(a, 1, _start(26) + 0.5, depth)
    # confidence: no far sample reaches the minimum's depth: ~1 times the neighbours' 25 / 26
    assert np.median(a["confidence"][1][ok]) == pytest.approx(25 / 26, abs=0.01)


def test_the_place_probability_is_exact_on_a_small_window():
    sigma = 0.1
    window = np.array([1.0, 0.9, 0.55, 0.5, 0.6, 0.62, 1.0])  # minimum at slot 3
    p = place_noise_probability(window, sigma, tolerance=1)
    # bottom 0.5 (slots 2-4); far slots 0, 1, 5, 6 are 0.5, 0.4, 0.12, 0.5 above it
    q = ndtr(-np.array([0.5, 0.4, 0.12, 0.5]) / (np.sqrt(2) * sigma))
    assert p == pytest.approx(1 - np.prod(1 - q), rel=1e-12)
    # noise-free: a far sample as deep is a tie (1/2), deeper is certain, shallower never
    assert place_noise_probability(window, 0.0, tolerance=1) == 0.0
    tie = window.copy()
    tie[0] = 0.5
    assert place_noise_probability(tie, 0.0, tolerance=1) == pytest.approx(0.5)
    assert place_noise_probability(window, sigma, tolerance=3) == 0.0  # no far sample
    cut = window.copy()
    cut[[0, 1, 5, 6]] = np.nan  # samples of other dips take no part
    assert place_noise_probability(cut, sigma, tolerance=1) == 0.0
    with pytest.raises(ValueError, match="window"):
        place_noise_probability(window[:6], sigma, tolerance=1)
    with pytest.raises(ValueError, match="tolerance"):
        place_noise_probability(window, sigma, tolerance=0)


@settings(max_examples=12, deadline=None)
@given(n_lights=st.integers(1, 3), sigma=st.floats(0.002, 0.05), gain=st.floats(0.0, 1e-3),
       seed=st.integers(0, 2**16))
def test_pure_noise_gives_times_at_no_more_than_the_false_alarm_rate(n_lights, sigma, gain, seed):
    """No shadow at all, Poisson-Gaussian noise: timed pixels (any light) are no more than
    false_alarm (1e-3) of the pixel-lights, beyond chance at 1e-6 for the number drawn."""
    rng = np.random.default_rng(seed)
    level = rng.uniform(0.3, 1.0, SHAPE)
    std = np.sqrt(gain * level + sigma ** 2)
    frames = (level[None] + std[None] * rng.standard_normal((FRAMES, *SHAPE)))[..., None]
    a = assign_minima(find_minima(frames, SHAPE, count=n_lights, half_window=4), n_lights)
    n = n_lights * SHAPE[0] * SHAPE[1]
    assert np.sum(a["reason"] == OK) <= binom.isf(1e-6, n, 1e-3)
