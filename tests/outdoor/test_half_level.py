"""The half-level crossing: the levels of a final descent, and the time half the sun's disc is hidden."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from shadowcam.outdoor.half_level import end_level, half_level_crossings, half_levels
from shadowcam.outdoor.penumbra import visible_fraction
from shadowcam.outdoor.photometric import luminance
from shadowcam.synthetic.outdoor.render import (frame_radiance, make_outdoor_scene, sample_grid, sun_lit_fraction,
                                                trace_samples)

INTERVAL = 5.0
TIMES = np.arange(128) * INTERVAL
LIT, SHADOW = 0.45, 0.04


def _descent(centre_s, first_s, second_s=None, *, times=TIMES):
    """A disc ramp whose edge moves at one speed until half the disc is hidden and at another after.

    ``first_s`` and ``second_s``: the durations of its halves (s); the constant-speed law has them equal.
    """
    second_s = first_s if second_s is None else second_s
    dt = times - centre_s
    u = np.where(dt < 0, dt / first_s, dt / np.asarray(second_s))
    return SHADOW + (LIT - SHADOW) * visible_fraction(u)


def test_end_level_tells_a_plateau_from_a_ramp_under_way():
    rng = np.random.default_rng(0)
    flat = 0.4 + rng.normal(0.0, 0.005, (200, 60))
    level, plateau, _ = end_level(flat, TIMES[:60], side="start")
    assert np.abs(level - 0.4).max() < 4 * 0.005 / np.sqrt(10)  # mean of the first 10 samples
    assert 0.90 <= plateau.mean() <= 0.99  # a 2-standard-error test on a true plateau
    # a ramp under way: the first 10 samples descend by 0.75 % of the level per interval (5 standard errors)
    ramp = flat - 0.003 * np.arange(60)[None, :]
    _, plateau, slope = end_level(ramp, TIMES[:60], side="start")
    assert plateau.mean() < 0.05 and (slope < 0).all()
    level, plateau, _ = end_level(ramp, TIMES[:60], side="end")
    np.testing.assert_allclose(level, 0.4 - 0.003 * np.arange(50, 60).mean(), atol=4 * 0.005 / np.sqrt(10))


@pytest.mark.parametrize(("first", "second"), [(19, 19), (38, 19), (10, 30), (4, 4)])
def test_the_half_level_crossing_needs_no_law_of_the_ramp(first, second):
    # the edge's speed changes between the halves of the ramp (the sun along a curved skyline);
    # half the disc is hidden at the centre all the same
    centre = np.array([52.3, 60.0, 67.8]) * INTERVAL
    series = _descent(centre[:, None], first * INTERVAL, second * INTERVAL)
    levels = half_levels(series, TIMES, shadow_ratio=0.5)  # both plateaus seen: the ratio is not used
    assert levels["lit_seen"].all() and levels["own_shadow"].all()
    np.testing.assert_allclose(levels["half"], 0.5 * (LIT + SHADOW), rtol=1e-12)
    duration = first + second
    k = max(1, round(duration / 8))
    crossing, sigma, _, _ = half_level_crossings(series, TIMES, half_level=levels["half"], half_window=k)
    # a line over +-k samples across a change of rate a -> b is off by (b - a) / (a + b) times
    # the mean distance k / 2 of its samples from the centre: 0 for one speed
    bound = 1.1 * abs(second - first) / duration * k / 2 + 0.02  # with 10 % for the law's curvature
    assert np.abs(crossing - centre).max() / INTERVAL <= bound
    # with k = 1 the crossing is between the two samples, with no standard error
    assert np.isfinite(sigma).all() if k > 1 else np.isinf(sigma).all()


def test_a_ramp_cut_by_the_end_takes_its_shadow_level_from_the_ratio():
    centre = np.array([110.0, 114.5]) * INTERVAL  # 40-frame ramps: the record ends at 2/3 and 1/2 of them
    series = _descent(centre[:, None], 20 * INTERVAL)
    levels = half_levels(series, TIMES, shadow_ratio=SHADOW / LIT)
    assert levels["lit_seen"].all() and not levels["own_shadow"].any()
    np.testing.assert_allclose(levels["half"], 0.5 * (LIT + SHADOW), rtol=1e-12)
    crossing, _, _, _ = half_level_crossings(series, TIMES, half_level=levels["half"], half_window=5)
    np.testing.assert_allclose(crossing, centre, atol=0.02 * INTERVAL)
    # a record ending before half the disc was hidden: no crossing, no time
    early = _descent(130.0 * INTERVAL, 20 * INTERVAL)[None, :]
    half = half_levels(early, TIMES, shadow_ratio=SHADOW / LIT)["half"]
    crossing, _, _, _ = half_level_crossings(early, TIMES, half_level=half, half_window=5)
    assert np.isnan(crossing).all()


def test_a_ramp_under_way_at_the_start_has_no_half_level():
    series = _descent(np.array([[8.0 * INTERVAL]]), 20 * INTERVAL)  # begun 12 frames before the record
    levels = half_levels(series, TIMES, shadow_ratio=SHADOW / LIT)
    assert not levels["lit_seen"][0] and levels["under_way"][0] and np.isnan(levels["half"][0])


@settings(max_examples=25, deadline=None)
@given(duration=st.integers(24, 60), phase=st.floats(0.0, 1.0), seed=st.integers(0, 2**16))
def test_noisy_crossings_are_within_their_standard_errors(duration, phase, seed):
    rng = np.random.default_rng(seed)
    centre = (50.0 + phase) * INTERVAL
    clean = _descent(centre, 0.5 * duration * INTERVAL)
    series = clean[None, :] + rng.normal(0.0, 0.004, (400, TIMES.size))
    levels = half_levels(series, TIMES, shadow_ratio=SHADOW / LIT)
    k = max(1, round(duration / 8))
    crossing, sigma, _, _ = half_level_crossings(series, TIMES, half_level=levels["half"], half_window=k)
    ok = np.isfinite(crossing)
    assert ok.mean() > 0.85  # a plateau test of 2 standard errors at each end misses ~5 % each
    z = np.abs(crossing[ok] - centre) / sigma[ok]
    # the line's standard error (k >= 3: 4 or more degrees of freedom; the levels' error is not in it)
    assert np.mean(z <= 3.0) > 0.85


def test_levels_against_the_renderers_exact_levels():
    # a sunset at a photographer's cadence: penumbrae of tens of frames
    rows, cols = 64, 96
    scene = make_outdoor_scene(seed=3, height=rows, width=cols, start_elevation_deg=8.0, end_elevation_deg=7.2)
    samples = trace_samples(scene, *sample_grid(rows, cols, 1))
    times = np.linspace(0.0, scene.duration_s, 96)
    ones = np.ones(len(samples.sky))
    shown, lit, sky = [], [], []
    for t in times:
        frac = sun_lit_fraction(samples, scene.sun, t)
        shown.append(luminance(frame_radiance(samples, scene, t, shape=(rows, cols), supersample=1, lit=frac)[0]))
        lit.append(luminance(frame_radiance(samples, scene, t, shape=(rows, cols), supersample=1, lit=ones)[0]))
        sky.append(luminance(frame_radiance(samples, scene, t, shape=(rows, cols), supersample=1, lit=0 * ones)[0]))
    shown, lit, sky = (np.stack(a).reshape(times.size, -1).T for a in (shown, lit, sky))
    # the photometry holds the lit level steady: the series over the pixel's own lit-level drift
    drift = lit / lit[:, :1]
    noise = np.random.default_rng(3).normal(0.0, 0.003, shown.shape) * lit[:, :1]  # a 14-bit capture's, about
    y, exact_lit, exact_shadow = shown / drift + noise, lit[:, 0], sky / drift
    with np.errstate(invalid="ignore", divide="ignore"):  # sky pixels: no sun term
        fraction = (shown - sky) / (lit - sky)
    # pixels whose whole penumbra is in the record, with the levels' samples (10) before and after it
    descends = (fraction[:, :12] > 0.999).all(1) & (fraction[:, -12:] < 0.001).all(1) & (lit[:, 0] > 0)
    assert descends.sum() >= 10
    assert np.median(np.sum((fraction > 0.001) & (fraction < 0.999), axis=1)[descends]) > 10  # frames of penumbra
    levels = half_levels(y[descends], times, shadow_ratio=0.1)
    exact_half = 0.5 * (exact_lit[descends] + exact_shadow[descends, -1])
    contrast = exact_lit[descends] - exact_shadow[descends, -1]
    seen = levels["lit_seen"] & levels["own_shadow"]
    assert seen.mean() > 0.8
    assert np.abs(levels["half"] - exact_half)[seen].max() < 0.005 * contrast[seen].min()
    # the crossing against the exact levels' crossing of half the disc hidden, per frame
    interval = times[1] - times[0]
    crossing, _, _, _ = half_level_crossings(y[descends], times, half_level=levels["half"], half_window=3)
    truth, _, _, _ = half_level_crossings(fraction[descends], times, half_level=np.full(descends.sum(), 0.5), half_window=1)
    assert np.abs(crossing - truth)[seen].max() / interval < 0.3


def _reference_crossings(values, time_s, half_level, half_window):
    """The half-level crossing written per pixel in numpy: the formulation the compiled kernel follows.

    Returns (crossing, sigma, step, slope) and, where the line descends, the line's residual
    RMS and the factor that turns it into ``sigma``, as (6, N) rows.
    """
    y = np.asarray(values, dtype=np.float64)
    t = np.broadcast_to(np.asarray(time_s, dtype=np.float64), y.shape)
    y = np.where(np.isfinite(t), y, np.nan)
    n = y.shape[0]
    k = np.broadcast_to(np.asarray(half_window), (n,)).astype(np.int64)
    out = np.full((6, n), np.nan)
    for i in np.nonzero(np.isfinite(half_level))[0]:
        finite = np.isfinite(y[i])
        yi, ti = y[i, finite] - half_level[i], t[i, finite]
        down = np.nonzero((yi[:-1] >= 0) & (yi[1:] < 0))[0]
        if down.size == 0:
            continue
        j = down[-1]
        out[2, i] = yi[j] - yi[j + 1]
        a, b = max(j - k[i] + 1, 0), min(j + k[i] + 1, yi.size)
        tw, yw = ti[a:b], yi[a:b]
        tm = tw.mean()
        sxx = ((tw - tm) ** 2).sum()
        with np.errstate(invalid="ignore", divide="ignore"):
            slope = ((tw - tm) * (yw - yw.mean())).sum() / sxx
        if slope < 0 and yw.size > 2:
            out[0, i] = tm - yw.mean() / slope
            s2 = ((yw - yw.mean() - slope * (tw - tm)) ** 2).sum() / (yw.size - 2)
            out[1, i] = np.sqrt(s2 * (1.0 / yw.size + (out[0, i] - tm) ** 2 / sxx)) / -slope
            out[3, i] = slope
            out[4, i], out[5, i] = np.sqrt(s2), np.sqrt(1.0 / yw.size + (out[0, i] - tm) ** 2 / sxx) / -slope
        else:
            out[0, i] = ti[j] + yi[j] / (yi[j] - yi[j + 1]) * (ti[j + 1] - ti[j])
            out[1, i] = np.inf
            out[3, i] = -out[2, i] / (ti[j + 1] - ti[j])
    return out


#: a sample: missing, on one of a few levels (plateaus, exact ties with the half level), or anywhere
_SAMPLE = st.one_of(st.just(np.nan), st.sampled_from([0.0, 0.25, 0.5, 0.75, 1.0]), st.floats(-1.0, 2.0))


@settings(max_examples=300, deadline=None)
@given(series=st.lists(st.lists(_SAMPLE, min_size=1, max_size=24), min_size=1, max_size=6),
       half=st.lists(st.one_of(st.just(np.nan), st.sampled_from([0.25, 0.5]), st.floats(-0.5, 1.5)), min_size=6,
                     max_size=6),
       window=st.lists(st.integers(1, 30), min_size=6, max_size=6),
       gaps=st.lists(st.floats(0.5, 10.0), min_size=24, max_size=24),
       missing_time=st.integers(-1, 23))
def test_the_compiled_crossing_is_the_numpy_formulation(series, half, window, gaps, missing_time):
    # random series: missing samples, plateaus, several crossings or none, crossings at the ends,
    # windows from 1 sample to wider than the series, irregular times (one of them unknown)
    length = max(len(s) for s in series)
    values = np.array([s + [np.nan] * (length - len(s)) for s in series])
    n = len(values)
    time_s = np.cumsum(gaps[:length])
    if 0 <= missing_time < length:
        time_s[missing_time] = np.nan
    level, k = np.array(half[:n]), np.array(window[:n])
    got = np.array(half_level_crossings(values, time_s, half_level=level, half_window=k))
    want, (rms, factor) = np.split(_reference_crossings(values, time_s, level, k), [4])
    np.testing.assert_array_equal(np.isnan(got), np.isnan(want))
    np.testing.assert_array_equal(np.isinf(got), np.isinf(want))
    # samples on a line to within rounding (1e-16 of the values): the residual, and the
    # standard error from it, are rounding in either summation order; they stay below 1e-6
    scale = np.abs(np.nan_to_num(values, nan=0.0)).max() + np.abs(np.nan_to_num(level, nan=0.0)).max() + 1.0
    rounding = rms <= 1e-6 * scale
    assert (got[1][rounding] <= 1e-6 * scale * factor[rounding]).all()
    rows = np.isfinite(want)
    rows[1] &= ~rounding
    np.testing.assert_allclose(got[rows], want[rows], rtol=1e-9)


def _noisy_ramps(rng, n, *, centres, durations):
    """`n` noisy disc-sun ramps over TIMES (2 % of samples missing), centres and durations
    uniform in the given ranges of intervals; returns (series (n, K), durations (n,) s)."""
    centre, duration = rng.uniform(*centres, n) * INTERVAL, rng.uniform(*durations, n) * INTERVAL
    series = SHADOW + (LIT - SHADOW) * visible_fraction(2 * (TIMES[None, :] - centre[:, None]) / duration[:, None])
    series += rng.normal(0.0, 0.004, series.shape)
    series[rng.random(series.shape) < 0.02] = np.nan
    return series, duration


def test_the_compiled_crossing_on_noisy_ramps():
    # realistic inputs: noisy disc ramps with missing samples, windows an eighth of the duration
    rng = np.random.default_rng(1)
    n = 2000
    series, duration = _noisy_ramps(rng, n, centres=(30, 100), durations=(20, 60))
    level = half_levels(series, TIMES, shadow_ratio=SHADOW / LIT)["half"]
    k = np.maximum(1, np.rint(duration / INTERVAL / 8)).astype(np.int64)
    got = np.array(half_level_crossings(series, TIMES, half_level=level, half_window=k))
    want = _reference_crossings(series, TIMES, level, k)[:4]
    assert np.isfinite(got[0]).mean() > 0.8 and np.isfinite(got[1]).mean() > 0.8
    np.testing.assert_array_equal(np.isnan(got), np.isnan(want))
    np.testing.assert_allclose(got[np.isfinite(want)], want[np.isfinite(want)], rtol=1e-9)


def _reference_levels(values, time_s, shadow_ratio, samples=10, z=2.0):
    """The end levels and half levels written vectorised in numpy: the formulation the compiled kernel follows.

    Returns the :func:`half_levels` dict and the end levels' (level, plateau, slope) of both sides.
    """
    y = np.asarray(values, dtype=np.float64)
    t = np.broadcast_to(np.asarray(time_s, dtype=np.float64), y.shape)
    y = np.where(np.isfinite(t), y, np.nan)

    def ends(side):
        key = np.where(np.isfinite(y), np.arange(y.shape[1])[None, :], y.shape[1] if side == "start" else -1)
        pick = (np.sort(key, axis=1) if side == "start" else -np.sort(-key, axis=1))[:, :samples]
        valid = (pick >= 0) & (pick < y.shape[1])
        index = np.clip(pick, 0, y.shape[1] - 1)
        return (np.where(valid, np.take_along_axis(y, index, axis=1), np.nan),
                np.where(valid, np.take_along_axis(t, index, axis=1), np.nan))

    def level(side):
        ys, ts = ends(side)
        full = np.isfinite(ys).all(1)
        with np.errstate(invalid="ignore", divide="ignore"):
            mean_y, mean_t = ys.mean(1), ts.mean(1)
            dt = ts - mean_t[:, None]
            sxx = (dt**2).sum(1)
            slope = (dt * (ys - mean_y[:, None])).sum(1) / sxx
            residual = ys - mean_y[:, None] - slope[:, None] * dt
            s2 = (residual**2).sum(1) / (samples - 2)
            plateau = full & (sxx > 0) & (slope**2 <= z**2 * s2 / sxx)
        return np.where(full, mean_y, np.nan), plateau, np.where(full, slope, np.nan), ys

    lit, lit_seen, lit_slope, start = level("start")
    shadow, shadow_seen, shadow_slope, _ = level("end")
    with np.errstate(invalid="ignore"):
        own = shadow_seen & lit_seen & (shadow < lit)
    low = np.where(own | (~lit_seen & shadow_seen), shadow, shadow_ratio * lit)
    half = 0.5 * (lit + low)
    with np.errstate(invalid="ignore"):
        under_way = ~lit_seen & (lit_slope < 0) & (np.min(start, axis=1) > half)
    out = {"half": np.where(lit_seen, half, np.nan), "lit": lit, "contrast": lit - low, "lit_seen": lit_seen,
           "under_way": under_way, "own_shadow": own, "shadow": shadow, "shadow_seen": shadow_seen}
    return out, (lit, lit_seen, lit_slope), (shadow, shadow_seen, shadow_slope)


def _assert_same(got, want):
    got, want = np.asarray(got), np.asarray(want)
    if want.dtype == bool:
        np.testing.assert_array_equal(got, want)
    else:
        np.testing.assert_array_equal(np.isnan(got), np.isnan(want))
        np.testing.assert_allclose(got[np.isfinite(want)], want[np.isfinite(want)], rtol=1e-9, atol=0)


@settings(max_examples=300, deadline=None)
@given(series=st.lists(st.one_of(st.lists(_SAMPLE, min_size=1, max_size=30),
                                 st.lists(st.sampled_from([0.1, 0.3]), min_size=1, max_size=30).map(
                                     lambda s: s[:1] * len(s))),  # constant series
                       min_size=1, max_size=6),
       gaps=st.lists(st.floats(0.5, 10.0), min_size=30, max_size=30),
       missing_time=st.integers(-1, 29), samples=st.sampled_from([3, 5, 10]), ratio=st.floats(0.0, 0.9))
def test_the_compiled_levels_are_the_numpy_formulation(series, gaps, missing_time, samples, ratio):
    # random series: missing samples, fewer finite samples than the levels take, constant
    # series, exact ties with the levels, irregular times (one of them unknown); records of at
    # least `samples` frames (the numpy formulation took a shorter record's samples as full)
    length = max(max(len(s) for s in series), samples)
    values = np.array([s + [np.nan] * (length - len(s)) for s in series])
    time_s = np.cumsum(gaps[:length])
    if 0 <= missing_time < length:
        time_s[missing_time] = np.nan
    want, want_start, want_end = _reference_levels(values, time_s, ratio, samples=samples)
    got = half_levels(values, time_s, shadow_ratio=ratio, samples=samples)
    assert set(got) == set(want)
    for key in want:
        _assert_same(got[key], want[key])
    for side, expected in (("start", want_start), ("end", want_end)):
        for g, w in zip(end_level(values, time_s, side=side, samples=samples), expected):
            _assert_same(g, w)


def test_the_compiled_levels_on_noisy_ramps():
    # realistic inputs: noisy disc ramps with missing samples, some records missing their start
    rng = np.random.default_rng(2)
    n = 3000
    series, _ = _noisy_ramps(rng, n, centres=(5, 120), durations=(4, 60))
    series[rng.random(n) < 0.2, :10] = np.nan
    want, _, _ = _reference_levels(series, TIMES, SHADOW / LIT)
    got = half_levels(series, TIMES, shadow_ratio=SHADOW / LIT)
    assert 0.3 < got["lit_seen"].mean() < 0.95 and got["under_way"].any() and got["own_shadow"].any()
    for key in want:  # the same sums in the same order: equal bit for bit
        np.testing.assert_array_equal(got[key], want[key])
