"""The disc-sun ramp: the circular-segment law, its per-pixel fit and the neighbours' duration."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from shadowcam.outdoor.penumbra import coherent_durations, fit_ramps, neighbour_median, ramp_model, visible_fraction

INTERVAL = 5.0
TIMES = np.arange(128) * INTERVAL


def test_visible_fraction_is_the_area_of_the_disc_beyond_a_straight_edge():
    assert visible_fraction(-1.0) == 1.0 and visible_fraction(1.0) == 0.0
    assert visible_fraction(0.0) == pytest.approx(0.5, abs=1e-15)
    u = np.linspace(-1.5, 1.5, 31)
    np.testing.assert_allclose(visible_fraction(u) + visible_fraction(-u), 1.0, atol=1e-12)
    # area of the unit disc with x < -u (the edge at x = u occludes x > u ... mirrored), on a fine grid
    grid = (np.arange(2000) + 0.5) / 1000 - 1.0
    x, y = np.meshgrid(grid, grid)
    inside = x * x + y * y <= 1.0
    for edge in (-0.7, -0.2, 0.3, 0.8):
        assert visible_fraction(edge) == pytest.approx((inside & (x < -edge)).sum() / inside.sum(), abs=2e-3)


def _ramps(duration_intervals, n, *, noise, seed=0):
    rng = np.random.default_rng(seed)
    centre = rng.uniform(40.0, 80.0, n) * INTERVAL
    clean = ramp_model(TIMES[None, :], centre_s=centre[:, None], duration_s=duration_intervals * INTERVAL,
                       lit=1.0, shadow=0.1)
    return centre, clean + rng.normal(0.0, noise, clean.shape)


@pytest.mark.parametrize(("duration", "median_tol"), [(10, 0.1), (60, 0.3)])
def test_noisy_ramps_of_10_and_60_frames_are_centred_within_tolerance(duration, median_tol):
    centre, series = _ramps(duration, 300, noise=0.02)
    # the start guess is a level crossing several intervals off (as on a penumbra of the real sun)
    guess = centre + np.random.default_rng(1).normal(0.0, 5.0, centre.size) * INTERVAL
    fit = fit_ramps(series, TIMES, centre_s=guess, interval_s=INTERVAL)
    assert fit["resolved"].all()
    error = np.abs(fit["centre_s"] - centre) / INTERVAL
    assert np.median(error) <= median_tol  # intervals, noise 0.02 of a lit-shadow contrast of 0.9
    assert np.percentile(error, 95) <= 3 * median_tol
    # the standard error is honest: within 3 sigma for ~all pixels
    assert np.mean(np.abs(fit["centre_s"] - centre) <= 3 * fit["sigma_s"]) >= 0.97
    np.testing.assert_allclose(np.median(fit["duration_s"]) / INTERVAL, duration, rtol=0.05)


def test_a_ramp_of_one_frame_is_not_resolved_by_the_law():
    centre, series = _ramps(1, 300, noise=0.02)
    fit = fit_ramps(series, TIMES, centre_s=centre, interval_s=INTERVAL)
    # at most one or two samples inside the ramp: the caller keeps the level crossing
    assert fit["resolved"].mean() < 0.05
    assert (fit["n_inside"] <= 2).mean() > 0.95


@settings(max_examples=40, deadline=None)
@given(duration=st.floats(4.0, 80.0), phase=st.floats(0.0, 1.0), lit=st.floats(0.3, 2.0),
       contrast=st.floats(0.2, 0.9))
def test_noise_free_ramps_are_recovered_exactly_whatever_their_length_and_phase(duration, phase, lit, contrast):
    centre = (64.0 + phase) * INTERVAL
    shadow = lit * (1.0 - contrast)
    series = ramp_model(TIMES, centre_s=centre, duration_s=duration * INTERVAL, lit=lit, shadow=shadow)[None]
    fit = fit_ramps(series, TIMES, centre_s=np.array([centre + 4 * INTERVAL]), interval_s=INTERVAL)
    assert fit["resolved"][0]
    assert abs(fit["centre_s"][0] - centre) / INTERVAL <= 1e-3
    assert fit["duration_s"][0] / INTERVAL == pytest.approx(duration, rel=1e-3)
    assert fit["lit"][0] == pytest.approx(lit, rel=1e-3) and fit["shadow"][0] == pytest.approx(shadow, rel=1e-3)


def test_a_known_duration_fits_only_the_centre_and_the_levels():
    centre, series = _ramps(40, 50, noise=0.02, seed=4)
    fit = fit_ramps(series, TIMES, centre_s=centre, interval_s=INTERVAL, duration_s=np.full(50, 40 * INTERVAL))
    np.testing.assert_allclose(fit["duration_s"], 40 * INTERVAL, rtol=1e-12)
    assert np.median(np.abs(fit["centre_s"] - centre)) / INTERVAL <= 0.25


def test_fit_inputs_are_validated():
    with pytest.raises(ValueError, match="series"):
        fit_ramps(np.zeros(5), TIMES[:5], centre_s=np.zeros(1), interval_s=1.0)
    with pytest.raises(ValueError, match="centre_s"):
        fit_ramps(np.zeros((2, 5)), TIMES[:5], centre_s=np.zeros(3), interval_s=1.0)
    with pytest.raises(ValueError, match="interval_s"):
        fit_ramps(np.zeros((2, 5)), TIMES[:5], centre_s=np.zeros(2), interval_s=0.0)
    with pytest.raises(ValueError, match="duration_s"):
        ramp_model(TIMES, centre_s=0.0, duration_s=0.0, lit=1.0, shadow=0.0)


def test_neighbours_duration_is_the_median_of_the_confident_ones():
    duration = np.full((5, 6), 10.0)
    duration[2, 3] = 1000.0  # an outlier
    confident = np.ones((5, 6), bool)
    confident[:, 0] = False
    duration[:, 0] = np.nan
    out = coherent_durations(duration, confident, radius=1)
    assert out[2, 3] == pytest.approx(10.0)  # the median ignores one outlier in nine
    assert out[0, 0] == pytest.approx(10.0)  # from the confident neighbours
    assert np.isnan(coherent_durations(duration, np.zeros_like(confident), radius=1)).all()
    with pytest.raises(ValueError, match="radius"):
        coherent_durations(duration, confident, radius=-1)


def test_each_pixel_is_fitted_alone_whatever_its_batch_and_its_gaps():
    centre, series = _ramps(30, 6, noise=0.02, seed=11)
    series[2, 50:53] = np.nan  # a gap inside the ramp
    series[4, :20] = np.nan  # a short record
    together = fit_ramps(series, TIMES, centre_s=centre, interval_s=INTERVAL)
    for i in range(series.shape[0]):
        alone = fit_ramps(series[i:i + 1], TIMES, centre_s=centre[i:i + 1], interval_s=INTERVAL)
        for key in ("centre_s", "duration_s", "sigma_s", "n_inside"):
            assert alone[key][0] == together[key][i]
    # the gap's samples take no part: the same series without them (times kept) gives the same fit
    kept = np.isfinite(series[2])
    short = fit_ramps(series[2:3, kept], TIMES[kept], centre_s=centre[2:3], interval_s=INTERVAL)
    assert short["n_inside"][0] == together["n_inside"][2]
    assert abs(short["centre_s"][0] - centre[2]) / INTERVAL <= 0.5


@pytest.mark.parametrize("seen_after", [0.05, 0.25])
def test_a_ramp_cut_after_its_centre_is_centred_with_the_duration_and_shadow_known(seen_after):
    # the series ends `seen_after` durations after the centre: the second half of the ramp is not seen
    duration = 50 * INTERVAL
    rng = np.random.default_rng(12)
    centre = rng.uniform(60.0, 70.0, 200) * INTERVAL
    end = centre + seen_after * duration
    clean = ramp_model(TIMES[None, :], centre_s=centre[:, None], duration_s=duration, lit=1.0, shadow=0.1)
    series = np.where(TIMES[None, :] <= end[:, None], clean, np.nan)
    known = {"duration_s": np.full(200, duration), "shadow": np.full(200, 0.1)}
    exact = fit_ramps(series, TIMES, centre_s=centre + 3 * INTERVAL, interval_s=INTERVAL, **known)
    assert exact["resolved"].all()
    np.testing.assert_allclose(exact["centre_s"], centre, atol=1e-3 * INTERVAL)
    np.testing.assert_allclose(exact["lit"], 1.0, atol=1e-6)
    np.testing.assert_allclose(exact["shadow"], 0.1, atol=0.0)  # fixed
    noisy = fit_ramps(series + rng.normal(0.0, 0.02, series.shape), TIMES, centre_s=centre + 3 * INTERVAL,
                      interval_s=INTERVAL, **known)
    error = np.abs(noisy["centre_s"] - centre)
    assert np.median(error) / INTERVAL <= 0.5
    assert np.mean(error <= 3 * noisy["sigma_s"]) >= 0.95  # the standard error is honest
    with pytest.raises(ValueError, match="shadow"):
        fit_ramps(series, TIMES, centre_s=centre, interval_s=INTERVAL, shadow=np.zeros(3))


def test_neighbour_median_reads_a_rectangle_of_confident_values():
    values = np.arange(60, dtype=float).reshape(10, 6)
    confident = np.zeros((10, 6), bool)
    confident[0, 2] = confident[9, 2] = True
    out = neighbour_median(values, confident, radius=(9, 1), at=(np.array([5, 5]), np.array([2, 5])))
    assert out[0] == pytest.approx((values[0, 2] + values[9, 2]) / 2) and np.isnan(out[1])
    full = neighbour_median(values, confident, radius=(4, 0))
    assert full[4, 2] == values[0, 2] and full[5, 2] == values[9, 2] and np.isnan(full[4, 3])


def _changing_edge(tau, beta):
    """Edge distance (disc radii) when its speed changes linearly: 2 tau (1 + beta tau), monotonic (held beyond the disc)."""
    turned = 1.0 + 2.0 * beta * tau <= 0.0
    return np.where(turned, -2.0 * np.sign(beta), 2.0 * tau * (1.0 + beta * tau))


@settings(max_examples=20, deadline=None)
@given(beta=st.floats(-0.4, 0.4), duration=st.floats(20.0, 60.0), phase=st.floats(0.0, 1.0))
def test_a_ramp_whose_edge_speed_changes_is_centred_exactly_with_the_speed_change_fitted(beta, duration, phase):
    centre = (60.0 + phase) * INTERVAL
    series = (0.1 + 0.9 * visible_fraction(_changing_edge((TIMES - centre) / (duration * INTERVAL), beta)))[None]
    fit = fit_ramps(series, TIMES, centre_s=np.array([centre + 3 * INTERVAL]), interval_s=INTERVAL, speed_change=True)
    assert fit["resolved"][0]
    assert abs(fit["centre_s"][0] - centre) / INTERVAL <= 1e-3
    assert fit["speed_change"][0] == pytest.approx(beta, abs=1e-3)
    assert fit["duration_s"][0] / INTERVAL == pytest.approx(duration, rel=1e-3)


def test_the_constant_speed_law_is_off_centre_on_a_ramp_whose_speed_doubles():
    # u = 2 tau (1 + 0.4 tau): the edge's speed is 0.6 / 1.4 of its mean at the ramp's start / end
    centre, duration = 60.0 * INTERVAL, 50.0 * INTERVAL
    series = (0.1 + 0.9 * visible_fraction(_changing_edge((TIMES - centre) / duration, 0.4)))[None]
    constant = fit_ramps(series, TIMES, centre_s=np.array([centre]), interval_s=INTERVAL)
    changing = fit_ramps(series, TIMES, centre_s=np.array([centre]), interval_s=INTERVAL, speed_change=True)
    assert abs(constant["centre_s"][0] - centre) / INTERVAL > 0.5  # 0.79 intervals early
    assert abs(changing["centre_s"][0] - centre) / INTERVAL <= 1e-3
    np.testing.assert_array_equal(constant["speed_change"], 0.0)
