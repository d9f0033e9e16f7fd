"""Each pixel's final descent: kept while streaming, fitted, with states and arrival reasons."""

import numpy as np
import pytest

from shadowcam.outdoor.arrival import REASON_CODE, apply_ramps
from shadowcam.outdoor.descent import STATE_CODE, DescentBuffer, fit_descents
from shadowcam.outdoor.penumbra import ramp_model
from shadowcam.outdoor.strips import edge_width, strip_halo

INTERVAL = 5.0


def _stream(series, *, frames=64, luminance=None):
    """Feed (T, H, W) coverage (and, given, the (T, H, W) luminance) through a buffer, dark below 0.5
    from the first crossing on; return the buffer and the crossing times (linear between frames)."""
    series = np.asarray(series, dtype=np.float64)
    times = np.arange(series.shape[0]) * INTERVAL
    buffer = DescentBuffer(series.shape[1:], frames=frames, luminance=luminance is not None)
    crossing = np.full(series.shape[1:], np.nan)
    dark = np.zeros(series.shape[1:], bool)
    for k, cover in enumerate(series):
        now = cover < 0.5
        start = now & ~dark
        if k and start.any():
            prev = series[k - 1]
            frac = (prev - 0.5) / np.where(prev != cover, prev - cover, 1.0)
            crossing[start] = times[k - 1] + np.clip(frac, 0, 1)[start] * INTERVAL
        crossing[~now] = np.nan
        dark = now
        buffer.update(cover, dark=dark, luminance=None if luminance is None else luminance[k])
    return buffer, crossing, times


def test_the_buffer_freezes_on_the_final_descent_and_restarts_after_a_passing_shadow():
    t = np.arange(200)
    cover = np.ones((200, 1, 2))
    cover[20:25, 0, 1] = 0.2  # a passing cloud, then the final shadow at frame 150
    cover[150:, 0, :] = 0.1
    buffer = DescentBuffer((1, 2), frames=16)
    for k in range(200):
        buffer.update(cover[k], dark=cover[k] < 0.5)
    values, frame = buffer.series(np.array([0, 0]), np.array([0, 1]))
    # both hold the 8 frames before the crossing and the 8 from it on (frozen after)
    for j in range(2):
        np.testing.assert_array_equal(frame[j], t[142:158])
        np.testing.assert_allclose(values[j], cover[142:158, 0, j], atol=1e-3)  # float16


@pytest.mark.parametrize("duration", [10, 60])
def test_fitted_descents_give_the_ramp_centre_and_short_ones_keep_the_crossing(duration):
    rng = np.random.default_rng(2)
    centre = rng.uniform(60, 70, (3, 8)) * INTERVAL
    times = np.arange(160) * INTERVAL
    series = ramp_model(times[:, None, None], centre_s=centre, duration_s=duration * INTERVAL, lit=1.0, shadow=0.05)
    series = series + rng.normal(0, 0.02, series.shape)
    buffer, crossing, times = _stream(series, frames=128)
    out = fit_descents(buffer, crossing, times, max_sigma=1.0)
    fitted = (out["ramp_state"] == STATE_CODE["fitted"]) | (out["ramp_state"] == STATE_CODE["neighbours_duration"])
    assert fitted.all()
    error = np.abs(out["ramp_centre_s"] - centre) / INTERVAL
    assert np.median(error) <= (0.1 if duration == 10 else 0.3)
    assert error.max() <= 1.5


def test_a_one_frame_ramp_is_short_and_keeps_the_level_crossing():
    rng = np.random.default_rng(3)
    centre = rng.uniform(30, 40, (2, 6)) * INTERVAL
    times = np.arange(80) * INTERVAL
    series = ramp_model(times[:, None, None], centre_s=centre, duration_s=INTERVAL, lit=1.0, shadow=0.05)
    buffer, crossing, times = _stream(series + rng.normal(0, 0.01, series.shape))
    out = fit_descents(buffer, crossing, times)
    assert (out["ramp_state"] == STATE_CODE["short"]).mean() >= 0.9
    assert np.isnan(out["ramp_centre_s"][out["ramp_state"] == STATE_CODE["short"]]).all()
    # the arrival keeps the crossing (the midpoint crossing of the old estimators) with its reason
    reason = np.full(crossing.shape, REASON_CODE["coverage_crossing"], np.uint8)
    arrival, new_reason = apply_ramps(crossing, reason, out["ramp_centre_s"], out["ramp_state"])
    short = out["ramp_state"] == STATE_CODE["short"]
    np.testing.assert_array_equal(arrival[short], crossing[short])
    assert (new_reason[short] == REASON_CODE["coverage_crossing"]).all()
    # the crossing of a one-frame ramp is the centre within a small part of an interval
    assert np.median(np.abs(crossing - centre)) / INTERVAL < 0.15


def test_a_ramp_cut_by_the_sequence_end_gets_a_reason_and_no_time():
    rng = np.random.default_rng(5)
    times = np.arange(100) * INTERVAL
    centre = np.full((2, 7), 90.0 * INTERVAL)  # a 60-frame ramp centred 10 frames before the end
    series = ramp_model(times[:, None, None], centre_s=centre, duration_s=60 * INTERVAL, lit=1.0, shadow=0.05)
    buffer, crossing, times = _stream(series + rng.normal(0, 0.02, series.shape), frames=128)
    out = fit_descents(buffer, crossing, times)
    assert (out["ramp_state"] == STATE_CODE["cut"]).all()
    assert np.isnan(out["ramp_centre_s"]).all()
    reason = np.full(centre.shape, REASON_CODE["coverage_crossing"], np.uint8)
    arrival, reason = apply_ramps(crossing, reason, out["ramp_centre_s"], out["ramp_state"])
    assert np.isnan(arrival).all() and (reason == REASON_CODE["ramp_cut"]).all()


def test_a_noisy_pixel_takes_its_neighbours_duration():
    rng = np.random.default_rng(7)
    times = np.arange(160) * INTERVAL
    centre = rng.uniform(60, 70, (7, 7)) * INTERVAL
    series = ramp_model(times[:, None, None], centre_s=centre, duration_s=40 * INTERVAL, lit=1.0, shadow=0.05)
    noise = np.full((7, 7), 0.01)
    noise[3, 3] = 0.25  # one very noisy pixel
    series = series + rng.normal(0, 1, series.shape) * noise
    buffer, crossing, times = _stream(series, frames=128)
    out = fit_descents(buffer, crossing, times, max_sigma=1.0)
    # refitted with the neighbours' duration, or left to the crossing / no time when still uncertain
    assert out["ramp_state"][3, 3] in (STATE_CODE["neighbours_duration"], STATE_CODE["ambiguous"], STATE_CODE["short"])
    if out["ramp_state"][3, 3] == STATE_CODE["neighbours_duration"]:
        assert out["ramp_duration_s"][3, 3] / INTERVAL == pytest.approx(40, rel=0.1)
    others = np.ones((7, 7), bool)
    others[3, 3] = False
    assert (out["ramp_state"][others] == STATE_CODE["fitted"]).all()


def test_apply_ramps_labels_fitted_and_ambiguous_pixels():
    arrival = np.array([[10.0, 20.0, 30.0, 40.0]])
    reason = np.array([[REASON_CODE["edge_crossing"], REASON_CODE["coverage_crossing"],
                        REASON_CODE["relit_after_arrival"], REASON_CODE["coverage_crossing"]]], np.uint8)
    centre = np.array([[12.0, 22.0, 32.0, np.nan]])
    state = np.array([[STATE_CODE["fitted"], STATE_CODE["neighbours_duration"], STATE_CODE["fitted"],
                       STATE_CODE["ambiguous"]]], np.uint8)
    out, codes = apply_ramps(arrival, reason, centre, state)
    np.testing.assert_array_equal(out[0, :3], [12.0, 22.0, 30.0])  # a relit pixel's arrival is not the final descent
    assert np.isnan(out[0, 3])
    assert codes[0].tolist() == [REASON_CODE["penumbra_fit"], REASON_CODE["penumbra_fit"],
                                 REASON_CODE["relit_after_arrival"], REASON_CODE["ambiguous_ramp"]]


def test_the_edge_width_is_measured_and_widens_the_strip_halo():
    rows, cols = 100, 4
    r = np.arange(rows)[:, None] + 0.5
    lit_frac = np.clip((60.0 - r) / 20.0 + 0.5, 0, 1) * np.ones((1, cols))  # a 20-row penumbra centred at row 60
    shadow, lit = 0.1, 1.0
    ref = shadow + (lit - shadow) * lit_frac
    lit_at_start = lit_frac >= 0.5
    width = edge_width(ref, lit_level=np.full(ref.shape, lit), shadow_level=np.full(ref.shape, shadow),
                       lit_at_start=lit_at_start, sky=np.zeros(ref.shape, bool))
    # the shadow-side half: rows with lit fraction in (0.1, 0.9) below the Otsu split, doubled
    assert width == pytest.approx(16.0, abs=2.0)
    shift = np.zeros((3, 2))
    assert strip_halo(shift, edge_width_rows=width) == strip_halo(shift) + int(np.ceil(width))
    with pytest.raises(ValueError, match="edge_width_rows"):
        strip_halo(shift, edge_width_rows=-1.0)


def test_ramps_cut_after_their_centre_take_their_neighbours_duration_and_shadow_level():
    rng = np.random.default_rng(13)
    times = np.arange(100) * INTERVAL
    rows = np.arange(40)[:, None] * np.ones((1, 5))
    centre = (40.0 + 1.5 * rows) * INTERVAL  # the edge moves down; 40-frame ramps: rows >= 27 end after the last frame
    series = ramp_model(times[:, None, None], centre_s=centre, duration_s=40 * INTERVAL, lit=1.0, shadow=0.05)
    buffer, crossing, times = _stream(series + rng.normal(0, 0.01, series.shape), frames=128)
    ended = centre + 20 * INTERVAL <= times[-1] + 0.5 * INTERVAL
    cut = ~ended & np.isfinite(crossing)  # the last row has not crossed the coverage's half level
    near = fit_descents(buffer, crossing, times)  # neighbours within 3 rows only
    wide = fit_descents(buffer, crossing, times, cut_rows=16)
    for out in (near, wide):
        assert (out["ramp_state"][ended] == STATE_CODE["fitted"]).all()
    # within 16 rows every cut ramp has ended neighbours (at the border its own fit may end in time);
    # within 3 only the first rows do
    assert np.isin(wide["ramp_state"][cut], [STATE_CODE["cut_centred"], STATE_CODE["fitted"]]).all()
    assert (wide["ramp_state"][cut] == STATE_CODE["cut_centred"]).mean() >= 0.9
    assert (near["ramp_state"][cut] == STATE_CODE["cut"]).sum() >= 5 * 8
    error = np.abs(wide["ramp_centre_s"] - centre)[cut] / INTERVAL
    assert np.median(error) <= 0.3 and error.max() <= 1.5
    np.testing.assert_allclose(wide["ramp_duration_s"][cut] / INTERVAL, 40, rtol=0.1)
    reason = np.full(centre.shape, REASON_CODE["coverage_crossing"], np.uint8)
    arrival, reason = apply_ramps(crossing, reason, wide["ramp_centre_s"], wide["ramp_state"])
    assert (reason[cut] == REASON_CODE["penumbra_fit"]).all()
    np.testing.assert_array_equal(arrival[cut], wide["ramp_centre_s"][cut])


# a planar cliff: lit a (E cos i + sky), shadowed a sky; the ratio lit / shadow is 1 + E cos i / sky
CLIFF_SKY, CLIFF_SUN, CLIFF_NOISE, CLIFF_DURATION = 0.15, 0.85, 0.002, 40


def _cliff(*, sun=None, seed=17):
    """A textured cliff whose 40-interval penumbra moves down one row per interval (64 x 6 px,
    100 frames): rows 0-2 are past their half level at frame 0, rows up to 19 are under way then.

    Returns the buffer (coverage against frame 0's level, as the first pass sees it, and the
    luminance), the level crossings, the times, the true centres, the albedo and the shadow level."""
    rng = np.random.default_rng(seed)
    rows, cols = 64, 6
    centre = np.broadcast_to((np.arange(rows, dtype=float)[:, None] - 3.0) * INTERVAL, (rows, cols))
    albedo = rng.uniform(0.3, 0.9, (rows, cols))  # the texture
    sun = CLIFF_SUN if sun is None else sun
    lit, shadow = albedo * (sun + CLIFF_SKY), albedo * CLIFF_SKY
    times = np.arange(100) * INTERVAL
    luminance = ramp_model(times[:, None, None], centre_s=centre, duration_s=CLIFF_DURATION * INTERVAL, lit=lit,
                           shadow=shadow) + rng.normal(0, CLIFF_NOISE, (times.size, rows, cols))
    cover = (luminance - shadow) / (luminance[0] - shadow)  # frame 0 is the first pass's lit level
    buffer, crossing, times = _stream(cover, frames=128, luminance=luminance)
    return buffer, crossing, times, centre, albedo, shadow


def _cliff_sigma(albedo, shadow):
    """Standard error (intervals) of the crossing of the half level ``S (1 + R) / 2`` from the noise: the
    shadow plateau's mean of 10 samples (its error times ``(1 + R) / 2``) and the neighbours' ratio
    (one pixel's ratio error, an upper bound of their median's), over the disc law's rate at the
    centre ``4 / (pi D)`` of the contrast, with the line's own error over +-5 samples."""
    ratio = 1 + CLIFF_SUN / CLIFF_SKY
    noise_s = CLIFF_NOISE / np.sqrt(10)
    ratio_error = ratio * np.hypot(noise_s / (ratio * shadow), noise_s / shadow)
    half_error = np.hypot(0.5 * (1 + ratio) * noise_s, 0.5 * shadow * ratio_error)
    rate = 4 / (np.pi * CLIFF_DURATION) * albedo * CLIFF_SUN  # per interval
    return np.hypot(half_error, CLIFF_NOISE / np.sqrt(11)) / rate


def test_a_penumbra_under_way_at_the_first_frame_is_timed_from_its_neighbours_lit_to_shadow_ratio():
    buffer, crossing, times, centre, albedo, shadow = _cliff()
    # the neighbours within the penumbra's width in rows (40): those with both plateaus (rows >= 33)
    out = fit_descents(buffer, crossing, times, cut_rows=CLIFF_DURATION, shadow_ratio=0.2)
    state = out["ramp_state"]
    true_centre = centre / INTERVAL
    under_way = (true_centre >= 1) & (true_centre <= 12)  # begun 8-19 intervals before frame 0
    # timed, or (the plateau test at 2 standard errors turns down ~5 % of flat shadow levels) no time
    assert np.isin(state[under_way], [STATE_CODE["neighbours_lit"], STATE_CODE["no_lit_level"]]).all()
    assert (state[under_way] == STATE_CODE["neighbours_lit"]).mean() >= 0.85
    under_way &= state == STATE_CODE["neighbours_lit"]
    error = (out["ramp_centre_s"] - centre) / INTERVAL
    sigma = _cliff_sigma(albedo, shadow)
    assert np.all(np.abs(error[under_way]) <= 4 * sigma[under_way])
    assert np.median(np.abs(error[under_way])) <= np.median(sigma[under_way])
    # every time given to a ramp begun before frame 0 is as good: no confident wrong time
    begun = true_centre < CLIFF_DURATION / 2
    timed = begun & np.isfinite(out["ramp_centre_s"])
    assert np.all(np.abs(error[timed]) <= 4 * sigma[timed] + 0.25)  # + the start-on-plateau half level's bias
    # its stated standard error covers the error
    assert np.all(np.abs(error[under_way]) <= 4 * out["ramp_sigma_s"][under_way] / INTERVAL + 0.05)
    # past its half level at frame 0: the arrival came before the record
    assert (state[true_centre <= -1] == STATE_CODE["before_record"]).all()
    reason = np.full(centre.shape, REASON_CODE["coverage_crossing"], np.uint8)
    arrival, reason = apply_ramps(crossing, reason, out["ramp_centre_s"], state)
    assert (reason[under_way] == REASON_CODE["penumbra_fit"]).all()
    assert np.isnan(arrival[true_centre <= -1]).all()
    assert (reason[true_centre <= -1] == REASON_CODE["arrival_before_record"]).all()


def test_a_penumbra_under_way_without_neighbours_of_both_levels_gets_a_reason_and_no_time():
    buffer, crossing, times, centre, _, _ = _cliff()
    # within 3 rows no neighbour of the under-way rows has its lit plateau
    out = fit_descents(buffer, crossing, times, cut_rows=3, shadow_ratio=0.2)
    under_way = (centre / INTERVAL >= 1) & (centre / INTERVAL <= 12)
    assert (out["ramp_state"][under_way] == STATE_CODE["no_lit_level"]).all()
    reason = np.full(centre.shape, REASON_CODE["coverage_crossing"], np.uint8)
    arrival, reason = apply_ramps(crossing, reason, out["ramp_centre_s"], out["ramp_state"])
    assert np.isnan(arrival[under_way]).all() and (reason[under_way] == REASON_CODE["no_lit_level"]).all()


def test_a_lit_to_shadow_ratio_that_varies_over_the_neighbours_gives_no_time():
    # every pixel its own orientation (cos i from 0.2 to 1): the ratio 1 + E cos i / sky spreads
    rng = np.random.default_rng(4)
    buffer, crossing, times, centre, _, _ = _cliff(sun=CLIFF_SUN * rng.uniform(0.2, 1.0, (64, 6)))
    out = fit_descents(buffer, crossing, times, cut_rows=CLIFF_DURATION, shadow_ratio=0.2)
    under_way = (centre / INTERVAL >= 1) & (centre / INTERVAL <= 12)
    assert np.isin(out["ramp_state"][under_way], [STATE_CODE["lit_ratio_spread"], STATE_CODE["no_lit_level"]]).all()
    assert (out["ramp_state"][under_way] == STATE_CODE["lit_ratio_spread"]).mean() >= 0.85
    assert np.isnan(out["ramp_centre_s"][under_way]).all()


def test_a_penumbra_under_way_with_both_levels_but_an_uncertain_crossing_is_ambiguous():
    buffer, crossing, times, centre, _, _ = _cliff()
    wide = fit_descents(buffer, crossing, times, cut_rows=CLIFF_DURATION, shadow_ratio=0.2)
    # the neighbours' lit level crossings' standard errors are 0.13-0.23 interval: a bound inside that range
    tight = fit_descents(buffer, crossing, times, cut_rows=CLIFF_DURATION, shadow_ratio=0.2, max_sigma=0.15)
    # whether a pixel has a lit level does not depend on the bound
    no_level = STATE_CODE["no_lit_level"]
    np.testing.assert_array_equal(wide["ramp_state"] == no_level, tight["ramp_state"] == no_level)
    lost = (wide["ramp_state"] == STATE_CODE["neighbours_lit"]) & (tight["ramp_state"] != STATE_CODE["neighbours_lit"])
    assert lost.sum() >= 10
    # its levels are known: the crossing is too uncertain (ambiguous), or the neighbours' spread alone is
    assert np.isin(tight["ramp_state"][lost], [STATE_CODE["ambiguous"], STATE_CODE["lit_ratio_spread"]]).all()
    ambiguous = lost & (tight["ramp_state"] == STATE_CODE["ambiguous"])
    assert ambiguous.sum() >= 10
    reason = np.full(centre.shape, REASON_CODE["coverage_crossing"], np.uint8)
    arrival, reason = apply_ramps(crossing, reason, tight["ramp_centre_s"], tight["ramp_state"])
    assert np.isnan(arrival[ambiguous]).all() and (reason[ambiguous] == REASON_CODE["ambiguous_ramp"]).all()


def test_a_penumbra_begun_in_the_first_frames_is_timed_within_the_noise():
    # begun 1-5 frames after frame 0: too few lit samples for the plateau test, so taken for under
    # way; its shadow plateau and its neighbours' ratio still give its lit level
    buffer, crossing, times, centre, albedo, shadow = _cliff()
    out = fit_descents(buffer, crossing, times, cut_rows=CLIFF_DURATION, shadow_ratio=0.2)
    true_centre = centre / INTERVAL
    band = (true_centre >= CLIFF_DURATION / 2 + 1) & (true_centre <= CLIFF_DURATION / 2 + 5)
    state = out["ramp_state"]
    # timed, or (the shadow plateau test at 2 standard errors turns some flat levels down) no time
    assert np.isin(state[band], [STATE_CODE["neighbours_lit"], STATE_CODE["no_lit_level"]]).all()
    timed = band & (state == STATE_CODE["neighbours_lit"])
    assert timed.sum() >= 0.8 * band.sum()
    error = (out["ramp_centre_s"] - centre) / INTERVAL
    assert np.all(np.abs(error[timed]) <= 4 * _cliff_sigma(albedo, shadow)[timed])
