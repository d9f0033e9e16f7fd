"""Several minima per pixel: K dips at known times, close dips, dips at the sweep's ends, NaN."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from shadowcam.lab.minima import (
    AT_END, INVALID, LOW_CONTRAST, MISSING, OK, OVERLAPPING, WIDE, find_minima, select_minima,
)


def box_dips(n_frames, centres, widths, depths, *, level=1.0, shape=(2, 3)):
    """Frames integrating, over each frame's exposure [k - 1/2, k + 1/2], a shadow of the
    given width (frames) and depth: the exact sampled profile of a wire passing a point."""
    k = np.arange(n_frames, dtype=np.float64)
    signal = np.full(n_frames, level)
    for c, w, d in zip(centres, widths, depths):
        overlap = np.clip(np.minimum(k + 0.5, c + w / 2) - np.maximum(k - 0.5, c - w / 2), 0, None)
        signal -= level * d * np.minimum(overlap, 1.0)
    return np.broadcast_to(signal[:, None, None], (n_frames, *shape)).astype(np.float32).copy()


separated = st.lists(st.floats(8.0, 72.0), min_size=1, max_size=3).filter(
    lambda c: all(abs(a - b) > 12 for i, a in enumerate(c) for b in c[i + 1:]))


@settings(max_examples=25, deadline=None)
@given(centres=separated, width=st.floats(0.6, 3.0), depth=st.floats(0.2, 0.9))
def test_separated_dips_are_timed_exactly_in_sweep_order(centres, width, depth):
    frames = box_dips(80, centres, [width] * len(centres), [depth] * len(centres))
    m = find_minima(frames, frames.shape[1:], count=len(centres), half_window=4)
    assert np.all(m.reason == OK)
    assert np.all(m.count == len(centres))
    # the centroid of exposure-integrated box coverage misses the centre by the two partly
    # covered frames only: a(1 - a)/2 <= 1/8 frame-moment each, over the dip's area
    np.testing.assert_allclose(m.time[:, 0, 0], sorted(centres), atol=1 / (8 * width) + 2e-3)
    # contrast: the deepest sample's lost fraction
    lowest = [1 - frames[int(round(c)) - 2:int(round(c)) + 3, 0, 0].min() for c in sorted(centres)]
    np.testing.assert_allclose(m.contrast[:, 0, 0], lowest, atol=1e-5)
    # half-depth width of a sampled box of `width` frames: within a frame of max(width, 1)
    assert np.all(np.abs(m.width[:, 0, 0] - max(width, 1.0)) <= 1.0 + 1e-6)


@settings(max_examples=20, deadline=None)
@given(first=st.floats(20.0, 40.0), fraction=st.floats(0.3, 1.0), width=st.floats(2.5, 4.0))
def test_dips_closer_than_their_widths_are_never_timed_confidently(first, fraction, width):
    centres = [first, first + fraction * width]
    frames = box_dips(64, centres, [width, width], [0.6, 0.6])
    m = find_minima(frames, frames.shape[1:], count=2, half_window=3)
    t = m.time[:, 0, 0]
    ok = m.reason[:, 0, 0] == OK
    # a minimum is either flagged or within its dip's half width of a true centre; two
    # confident times never both point at the same dip
    for value in t[ok]:
        assert np.min(np.abs(value - np.array(centres))) <= width / 2
    assert set(m.reason[:, 0, 0]) <= {OK, OVERLAPPING, MISSING, LOW_CONTRAST}
    if ok.all():
        assert abs(t[1] - t[0]) > 1.0


@settings(max_examples=20, deadline=None)
@given(edge=st.sampled_from(["start", "end"]), inset=st.floats(-1.0, 1.5))
def test_dips_at_the_sweep_ends_are_flagged_or_exact(edge, inset):
    n = 48
    centre = inset if edge == "start" else n - 1 - inset
    frames = box_dips(n, [centre, 24.0], [2.0, 2.0], [0.7, 0.7])
    m = find_minima(frames, frames.shape[1:], count=2, half_window=4)
    at_edge = 0 if edge == "start" else 1
    reason = m.reason[at_edge, 0, 0]
    assert reason in (OK, AT_END, MISSING)
    if reason == OK:
        assert abs(m.time[at_edge, 0, 0] - centre) < 1 / 16 + 2e-3
    middle = 1 - at_edge if m.count[0, 0] == 2 else 0
    assert abs(m.time[middle, 0, 0] - 24.0) < 1 / 16 + 2e-3


@settings(max_examples=20, deadline=None)
@given(offset=st.integers(-4, 4), where=st.integers(0, 1))
def test_non_finite_samples_never_give_a_confident_time(offset, where):
    frames = box_dips(60, [15.0, 40.0], [1.5, 1.5], [0.5, 0.5])
    centre = (15, 40)[where]
    frames[centre + offset, 0, 0] = np.nan
    m = find_minima(frames, frames.shape[1:], count=2, half_window=4)
    flagged = m.reason[:, 0, 0] != OK
    assert np.all(np.isnan(m.time[:, 0, 0][flagged]))
    inside = np.abs(np.array([15, 40]) - (centre + offset)) <= 4
    for k in range(2):
        if inside[k] and m.count[0, 0] == 2:
            assert m.reason[k, 0, 0] == INVALID
        elif m.reason[k, 0, 0] == OK:
            assert abs(m.time[k, 0, 0] - (15.0, 40.0)[k]) < 1 / 12 + 2e-3
    # the other pixels are untouched
    np.testing.assert_allclose(m.time[:, 1, 1], [15.0, 40.0], atol=1 / 12 + 2e-3)


def test_noise_level_and_low_contrast():
    rng = np.random.default_rng(3)
    frames = box_dips(200, [50.0, 120.0], [1.5, 1.5], [0.5, 0.01], shape=(20, 20))
    sigma = 0.01
    frames += rng.normal(0, sigma, frames.shape).astype(np.float32)
    m = find_minima(frames, frames.shape[1:], count=2, half_window=4)
    # noise from first differences of the lit frames: within 10 % of the truth
    assert abs(np.median(m.noise) / sigma - 1) < 0.1
    deep = m.frame == np.clip(m.frame, 45, 55)
    assert np.mean(m.reason[deep] == OK) > 0.99
    err = np.abs(m.time[deep] - 50.0)
    assert np.nanpercentile(err, 95) < 4 * np.median(m.time_std[deep])
    # the 1 % dip (one noise sigma) is below the detection level: (nearly) always flagged
    assert np.mean(m.reason[~deep] == LOW_CONTRAST) > 0.95


def test_extra_dip_is_reported():
    frames = box_dips(90, [20.0, 45.0, 70.0], [1.5] * 3, [0.6, 0.5, 0.4])
    m = find_minima(frames, frames.shape[1:], count=2, half_window=4)
    np.testing.assert_allclose(m.time[:, 0, 0], [20.0, 45.0], atol=1 / 12 + 2e-3)
    assert m.extra_contrast[0, 0] == pytest.approx(0.4, abs=2e-3)


def test_select_minima_is_greedy_and_separated():
    values = np.array([[0.1, 0.2, 0.15, np.inf, 0.3]])
    frames = np.array([[10, 30, 12, -1, 50]])
    frame, value = select_minima(values, frames, 3, separation=4)
    np.testing.assert_array_equal(frame, [[10, 30, 50]])
    np.testing.assert_allclose(value, [[0.1, 0.2, 0.3]])
    with pytest.raises(ValueError, match="count"):
        select_minima(values, frames, 0, separation=4)


@pytest.mark.parametrize("width", [12.0, 20.0])
def test_a_dip_wider_than_the_window_is_flagged_not_timed(width):
    """Under a steady lit level a window whose ends stay in the dip (half_window 3: 6
    frames each side of the minimum) cannot time it: wide_dip, no time."""
    frames = box_dips(90, [45.0], [width], [0.3])
    m = find_minima(frames, frames.shape[1:], count=1, half_window=3)
    assert np.all(m.reason == WIDE) and np.all(np.isnan(m.time))
    # a window that holds it times it
    m = find_minima(frames, frames.shape[1:], count=1, half_window=int(width // 2) + 2)
    np.testing.assert_allclose(m.time, 45.0, atol=1 / (8 * width) + 2e-3)



@settings(max_examples=30, deadline=None)
@given(centre=st.floats(28.0, 36.0), width=st.floats(1.5, 3.0), gap=st.floats(2.5, 5.0),
       trough=st.floats(6.0, 14.0), trough_depth=st.floats(0.1, 0.3), after=st.booleans())
def test_another_shadow_inside_the_window_does_not_move_a_dip(centre, width, gap, trough,
                                                              trough_depth, after):
    """A steady light's dip keeps its exact time and is timed (not flagged) when another
    light's wide, shallow shadow (a tube's) begins `gap` frames or so from it, inside its
    timing window: the frames between them are back at the lit level, so the other
    shadow's samples are no part of this dip. The other shadow's near edge is put on a
    frame boundary, so that each of its samples is either lit or deeper than noise-free
    detection (a partly shadowed sample shallower than the detectable depth stays in the
    window's level, see docs/benchmarks.md)."""
    side = 1.0 if after else -1.0
    edge = np.floor(centre + side * (width / 2 + gap)) + 0.5
    alone = box_dips(72, [centre], [width], [0.5])
    both = box_dips(72, [centre, edge + side * trough / 2], [width, trough], [0.5, trough_depth])
    m_alone = find_minima(alone, alone.shape[1:], count=2, half_window=4)
    m_both = find_minima(both, both.shape[1:], count=2, half_window=4)
    k_alone = int(np.nanargmin(np.abs(m_alone.estimate[:, 0, 0] - centre)))
    k_both = int(np.nanargmin(np.abs(m_both.estimate[:, 0, 0] - centre)))
    assert m_alone.reason[k_alone, 0, 0] == OK
    assert np.all(m_both.reason[k_both] == OK)
    np.testing.assert_allclose(m_both.time[k_both], m_alone.time[k_alone], atol=1e-6)
    np.testing.assert_allclose(m_both.contrast[k_both], m_alone.contrast[k_alone], atol=1e-6)


def test_poisson_gaussian_noise_makes_no_minimum_and_hides_no_dip():
    """One one-third-deep dip per pixel under shot and read noise (sigma 1 % - 4 % of the
    level, the dip 8 - 33 sigma): the second minimum asked for is pure noise."""
    rng = np.random.default_rng(5)
    gain, floor = 4e-5, 3e-7
    shape = (40, 50)
    level = rng.uniform(0.03, 0.2, shape).astype(np.float32)
    clean = box_dips(48, [24.0], [1.5], [1 / 3], shape=shape) * level[None]
    frames = clean + np.sqrt(gain * clean + floor) * rng.standard_normal(clean.shape).astype(np.float32)
    m = find_minima(frames, shape, count=2, half_window=4)
    assert m.noise_model[0] == pytest.approx(gain, rel=0.1)
    real = np.abs(m.frame - 24) <= 1
    assert np.mean(real.any(axis=0)) == 1.0
    # the dip: found and timed in every pixel
    assert np.mean(m.reason[real] == OK) > 0.995
    # noise minima: at most a few in 2000 pixels at false_alarm 1e-3 (expected about 2)
    noise_minima = ~real & (m.reason != LOW_CONTRAST) & (m.reason != MISSING)
    assert noise_minima.sum() <= 8
    assert np.all(m.count <= 1 + noise_minima.any(axis=0))


@settings(max_examples=15, deadline=None)
@given(first=st.floats(20.0, 40.0), fraction=st.floats(0.3, 1.0), width=st.floats(2.5, 4.0),
       snr=st.floats(8.0, 30.0), seed=st.integers(0, 2**16))
def test_close_dips_under_poisson_gaussian_noise_are_flagged_or_near_a_dip(first, fraction, width, snr,
                                                                         seed):
    """Two one-third-deep dips closer than their widths, shot and read noise with the dip
    `snr` noise sigma deep (per sample, at the lit level): a confident time always lies
    within its dip's half width (plus a frame of noise) of a true centre."""
    rng = np.random.default_rng(seed)
    centres = [first, first + fraction * width]
    clean = box_dips(64, centres, [width, width], [1 / 3, 1 / 3], shape=(6, 6))
    sigma_lit = (1 / 3) / snr
    gain, floor = 0.8 * sigma_lit ** 2, 0.2 * sigma_lit ** 2  # variance at level 1: sigma_lit ** 2
    frames = clean + np.sqrt(gain * clean + floor) * rng.standard_normal(clean.shape).astype(np.float32)
    m = find_minima(frames, frames.shape[1:], count=2, half_window=3)
    ok = m.reason == OK
    distance = np.min(np.abs(m.time[..., None] - np.array(centres)), axis=-1)
    assert np.all(distance[ok] <= width / 2 + 1.0)


def _assert_same_record(a, b, where="minima"):
    """Every field of two records (and of their nested summaries) equal bit for bit."""
    from dataclasses import fields, is_dataclass

    for f in fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if is_dataclass(x):
            _assert_same_record(x, y, f"{where}.{f.name}")
        elif isinstance(x, np.ndarray):
            assert x.shape == y.shape and x.dtype == y.dtype, f"{where}.{f.name}"
            np.testing.assert_array_equal(x, y, err_msg=f"{where}.{f.name}")
        else:
            assert x == y or (x != x and y != y), f"{where}.{f.name}"


@pytest.mark.parametrize("band_rows", [1, 3, 7])
def test_row_bands_give_the_whole_frames_minima_bit_for_bit(band_rows):
    """Demosaiced-RAW-like frames (three channels, own sites), two dips per pixel whose times
    drift across the image, shot and read noise: the per-pixel work done in row bands (one
    noise model fitted over every pixel) gives the whole frame's record, every field."""
    from shadowcam.lab.site_signal import cfa_site_colours

    rng = np.random.default_rng(11)
    shape = (10, 9)
    rows, cols = np.indices(shape)
    frames = np.empty((56, *shape, 3), np.float32)
    for r, c in zip(rows.ravel(), cols.ravel()):
        centres = [14.0 + 0.7 * r + 0.3 * c, 34.0 + 0.5 * r - 0.2 * c]
        frames[:, r, c, :] = box_dips(56, centres, [1.5, 2.5], [0.5, 0.3], shape=(1, 3))[:, 0, :]
    frames *= rng.uniform(0.1, 0.3, (1, *shape, 3)).astype(np.float32)
    frames += np.sqrt(4e-5 * frames + 3e-7) * rng.standard_normal(frames.shape).astype(np.float32)
    colour = cfa_site_colours(shape, "RGGB")
    whole = find_minima(frames, shape, count=3, site_colour=colour, band_rows=shape[0])
    banded = find_minima(lambda: (frames[t:t + 5] for t in range(0, 56, 5)), shape, count=3,
                         site_colour=colour, band_rows=band_rows)
    assert np.isfinite(whole.time).sum() > 0.9 * 2 * frames[0, ..., 0].size  # both dips timed nearly everywhere
    _assert_same_record(banded, whole)
