"""Shadow times of demosaiced 12-bit RAW from each pixel's own mosaic site.

A textured plane under the sweep (``wire_sweep``: the shadow's centre line crosses image
point (y, x) at ``t0 + x + tilt * y`` frames, 8 x 8 sub-samples per pixel), sampled by an
RGGB mosaic, quantised to 12 bit (optionally with Poisson and read noise) and demosaiced
bilinearly as the decode step does. The channel sum of a pixel mixes its neighbours'
sites, shadowed at their own times and weighted by their levels (the texture), so its
dip's centroid is off by the level-weighted mean of the neighbours' time offsets; the own
site sees only its footprint, whose removed-light centroid is the truth when the pixel's
radiance is uniform (a box footprint crossed at a constant speed: a symmetric coverage).
"""

from dataclasses import replace

import numpy as np
import pytest

from shadowcam._shared.flux_centroid import flux_centroid_shift
from shadowcam.io.cfa import demosaic_bilinear
from shadowcam.io.decode import mosaic_image
from shadowcam.lab.mosaic_signal import mosaic_signal
from shadowcam.lab.dip_classification import OK
from shadowcam.lab.shadow_time import summary_shadow_times, sweep_shadow_times, track_sweep
from shadowcam.lab.shadow_time_methods import _site_times
from shadowcam.lab.site_signal import (
    blend_variance, cfa_site_colours, mosaic_own_site, own_site_samples, site_window_of_sums, site_window_sums,
    track_site_window,
)

SHAPE = (24, 32)
WHITE, BLACK = 4095, 256


def _raw_sweep(wire_sweep, *, electrons=None, read_noise=6.0, seed=0):
    """Demosaiced RAW frames ``(T, H, W, 3)`` of a textured plane, their truth and the texture."""
    h, w = SHAPE
    unit, truth = wire_sweep(shape=SHAPE, level=1.0, n_frames=48, px_per_frame=1.0, t0=4.0, tilt=0.3)
    rng = np.random.default_rng(seed)
    scene = 0.3 + 0.6 * rng.random((h, w, 3))
    site = cfa_site_colours(SHAPE, "RGGB").astype(np.intp)
    own = np.take_along_axis(scene, site[..., None], axis=2)[..., 0]
    frames = np.empty(unit.shape + (3,), np.float32)
    for k, wire in enumerate(unit):
        signal = own * wire
        dn = signal * (WHITE - BLACK)
        if electrons is not None:  # electrons per unit signal, 1 DN per electron
            dn = rng.poisson(signal * electrons) + rng.normal(0.0, read_noise, signal.shape)
        raw = np.clip(np.round(BLACK + dn), 0, WHITE).astype(np.uint16)
        frames[k] = (demosaic_bilinear(raw, pattern="RGGB", max_value=WHITE) - BLACK) / (WHITE - BLACK)
    return frames, truth, own


def _blocks(frames, size=8):
    return [frames[i:i + size] for i in range(0, len(frames), size)]


def _errors(result, truth):
    timed = result["reason"] == OK
    inner = np.zeros(SHAPE, bool)
    inner[1:-1, 1:-1] = True  # the mirrored border taps are not the scene's
    return np.abs(result["shadow_time"] - truth)[timed & inner & np.isfinite(truth)]


def _summed(frames):
    """The channel sum's times (the tracker's signal), as before the own-site timing."""
    summary, _, _ = track_sweep(_blocks(frames), SHAPE)
    return summary_shadow_times(summary, cfa_pattern="RGGB")


def _blend_bias(truth, own):
    """The channel-sum centroid's offset: its taps' level-weighted mean of the sites' time offsets."""
    site = cfa_site_colours(SHAPE, "RGGB")
    bias = np.zeros(SHAPE)
    weight = np.zeros(SHAPE)
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            green = site == 1
            tap = np.where(green, np.where(dr * dc == 0, 1.0 if dr == dc == 0 else 0.5, 0.0),
                           1.0 if dr == dc == 0 else 0.25)
            level = np.roll(own, (-dr, -dc), axis=(0, 1))
            offset = np.roll(truth, (-dr, -dc), axis=(0, 1)) - truth
            bias += tap * level * offset
            weight += tap * level
    return bias / weight


def test_bright_raw_is_timed_from_the_own_site_to_the_quantisation(wire_sweep):
    frames, truth, own = _raw_sweep(wire_sweep)
    result = sweep_shadow_times(_blocks(frames), SHAPE, cfa_pattern="RGGB", own_site=True)
    err = _errors(result, truth)
    assert err.size > 0.9 * (SHAPE[0] - 2) * (SHAPE[1] - 2)
    # 12-bit quantisation: 1 DN in >= 1150 (the darkest site, 0.3 of 3839 DN) on each of the
    # ~3 covered samples moves the centroid by < 3 * (4 frames) / 1150 / 2 = 0.005 frame
    assert np.percentile(err, 95) < 0.01
    # the channel sum is off by the blend of its neighbours (the old timing fails above)
    summed = _errors(_summed(frames), truth)
    bias = np.abs(_blend_bias(truth, own))[1:-1, 1:-1]
    assert np.percentile(summed, 95) > 0.05
    assert np.percentile(summed, 95) == pytest.approx(np.percentile(bias, 95), rel=0.5)


def test_dim_raw_falls_back_to_the_channel_sum_without_losing_coverage(wire_sweep):
    # 30 electrons at full scale: many own-site dips are not significant on their own
    frames, truth, _ = _raw_sweep(wire_sweep, electrons=30.0, read_noise=6.0, seed=3)
    summary, _, _ = track_sweep(_blocks(frames), SHAPE)
    site = track_site_window(_blocks(frames), summary, site_colour=cfa_site_colours(SHAPE, "RGGB"))
    new = summary_shadow_times(summary, cfa_pattern="RGGB", own_site=True, read=lambda: _blocks(frames))
    old = summary_shadow_times(summary, cfa_pattern="RGGB")
    np.testing.assert_array_equal(new["reason"], old["reason"])  # the same pixels are timed
    assert (new["reason"] == OK).mean() > 0.9
    masked = replace(summary, window=np.where((old["reason"] == OK)[None], summary.window, np.nan))
    own_time, _, _ = _site_times(masked, site)
    fallen_back = (old["reason"] == OK) & ~np.isfinite(own_time)
    assert fallen_back.mean() > 0.3  # the fallback is exercised (64 % of the pixels here)
    err_new, err_old = _errors(new, truth), _errors(old, truth)
    # the noise dominates here: no worse than the channel sum's beyond the p95's sampling
    # error (half-normal errors, n ~ 650: sqrt(0.05 * 0.95 / n) / (2 phi(1.96)) / 1.96 ~ 4 %
    # of it; 1.1 allows 2.5 of those)
    assert np.percentile(err_new, 95) <= 1.1 * np.percentile(err_old, 95)
    assert np.median(err_new) <= 1.1 * np.median(err_old)


def test_without_a_mosaic_the_times_are_the_channel_sum_bit_for_bit(wire_sweep):
    frames, _ = wire_sweep(shape=SHAPE, n_frames=48, px_per_frame=1.0, t0=4.0, noise=0.0)
    listed = sweep_shadow_times(_blocks(frames), SHAPE)
    streamed = sweep_shadow_times(iter(_blocks(frames)), SHAPE)
    for key in ("shadow_time", "time_std", "reason"):
        np.testing.assert_array_equal(listed[key], streamed[key])
    # the same footprint as a number or per pixel: the same shift bit for bit
    level = 0.3 + frames[0].sum(axis=2)
    for a, b in zip(flux_centroid_shift(level, footprint_variance=15 / 192),
                    flux_centroid_shift(level, footprint_variance=np.full(SHAPE, 15 / 192))):
        np.testing.assert_array_equal(a, b)


def test_site_window_holds_each_sites_own_samples_and_lit_statistics(wire_sweep):
    frames, _, _ = _raw_sweep(wire_sweep, electrons=400.0, seed=1)
    summary, _, _ = track_sweep(_blocks(frames), SHAPE)
    colour = cfa_site_colours(SHAPE, "RGGB")
    site = track_site_window(_blocks(frames, 5), summary, site_colour=colour)
    rows, cols = np.indices(SHAPE)
    own = frames[:, rows, cols, colour]  # (T, H, W)
    k = summary.window.shape[0]
    frame = summary.window_start[None] + np.arange(k)[:, None, None]
    inside = (frame >= 0) & (frame < len(frames))
    expected = np.where(inside, own[np.clip(frame, 0, len(frames) - 1), rows, cols], np.nan)
    np.testing.assert_array_equal(site.window, expected.astype(np.float32))
    lit = np.ones(own.shape, bool)
    for t in range(k):
        f = summary.window_start + t
        lit[np.clip(f, 0, len(frames) - 1), rows, cols] &= ~((f >= 0) & (f < len(frames)))
    np.testing.assert_allclose(site.level, np.where(lit, own, 0).sum(0) / lit.sum(0), rtol=1e-6)
    rest = frames.sum(axis=3) - own
    mean = np.where(lit, rest, 0).sum(0) / lit.sum(0)
    np.testing.assert_allclose(site.neighbour_level, mean, rtol=1e-5)
    std = np.sqrt(np.where(lit, (rest - mean) ** 2, 0).sum(0) / (lit.sum(0) - 1))
    np.testing.assert_allclose(site.neighbour_noise, std, rtol=1e-3)
    with pytest.raises(ValueError, match="site_colour"):
        track_site_window(_blocks(frames), summary, site_colour=colour[:-1])


def test_time_chunks_of_site_sums_give_the_single_passs_window(wire_sweep):
    frames, _, _ = _raw_sweep(wire_sweep, electrons=400.0, seed=2)
    summary, _, _ = track_sweep(_blocks(frames), SHAPE)
    colour = cfa_site_colours(SHAPE, "RGGB")
    whole = track_site_window(_blocks(frames), summary, site_colour=colour)
    own = own_site_samples(frames, colour.astype(np.intp))
    signal = frames.sum(axis=3, dtype=np.float32)
    k = summary.window.shape[0]
    parts = [site_window_sums([(own[a:b], signal[a:b])], summary.window_start, k, first=a)
             for a, b in ((0, 13), (13, 30), (30, len(frames)))]
    chunked = site_window_of_sums(parts, summary, site_colour=colour)
    np.testing.assert_array_equal(chunked.window, whole.window)
    np.testing.assert_array_equal(chunked.count, whole.count)
    for name in ("level", "noise", "neighbour_level", "neighbour_noise"):
        # float64 sums added in another order
        np.testing.assert_allclose(getattr(chunked, name), getattr(whole, name), rtol=1e-12, err_msg=name)
    with pytest.raises(ValueError, match="frames"):
        site_window_of_sums(parts[:2], summary, site_colour=colour)


@pytest.mark.parametrize("black, white", [(256, 4095), (512, 16383), (64, 1023)])
def test_own_sites_from_the_mosaic_are_the_demosaics_bit_for_bit(black, white):
    rng = np.random.default_rng(4)
    mosaic = rng.integers(0, white + 1, size=(10, 12)).astype(np.uint16)
    levels = dict(black_sites=np.full((2, 2), black), white_sites=np.full((2, 2), white))
    for pattern in ("RGGB", "GBRG"):
        image = mosaic_image(mosaic, cfa_pattern=pattern, **levels)
        colour = cfa_site_colours(mosaic.shape, pattern).astype(np.intp)
        expected = own_site_samples(image[None], colour)[0]
        got = mosaic_own_site(mosaic, pattern=pattern, black=levels["black_sites"], white=levels["white_sites"])
        assert got.dtype == np.float32
        np.testing.assert_array_equal(got, expected)


@pytest.mark.parametrize("row, col", [(4, 6), (4, 7), (5, 6), (5, 7)])  # R, G, G, B sites of RGGB
def test_blend_variance_is_the_second_moment_of_the_channel_sums_taps(row, col):
    mosaic = np.zeros((12, 14), np.uint16)
    white = np.full((2, 2), 4095.0)
    taps = np.zeros((12, 14))
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):  # the weight of site (row + dr, col + dc) in pixel (row, col)'s sum
            delta = mosaic.copy()
            delta[row + dr, col + dc] = 4095
            signal, _ = mosaic_signal(delta, pattern="RGGB", black=np.zeros((2, 2)), white=white)
            taps[row + dr, col + dc] = signal[row, col]
    r = np.arange(12)[:, None] - row
    colour = cfa_site_colours((12, 14), "RGGB")
    for own, weights in ((True, taps), (False, np.where((r == 0) & (np.arange(14) == col), 0.0, taps))):
        moment = (weights * r**2).sum() / weights.sum()
        assert blend_variance(colour, own=own)[row, col] == pytest.approx(moment, abs=1e-6)


def test_own_site_timing_asked_for_where_it_cannot_be_done_is_an_error(wire_sweep):
    frames, _, _ = _raw_sweep(wire_sweep)
    with pytest.raises(ValueError, match="one-shot iterator"):
        sweep_shadow_times(iter(_blocks(frames)), SHAPE, cfa_pattern="RGGB", own_site=True)
    with pytest.raises(ValueError, match="cfa_pattern"):
        sweep_shadow_times(_blocks(frames), SHAPE, own_site=True)
    with pytest.raises(ValueError, match="edge_fit"):
        sweep_shadow_times(_blocks(frames), SHAPE, cfa_pattern="RGGB", method="dip_centroid", own_site=True)
    summary, _, _ = track_sweep(_blocks(frames), SHAPE)
    with pytest.raises(ValueError, match="read"):
        summary_shadow_times(summary, cfa_pattern="RGGB", own_site=True)
    # without own_site the same frames are timed from the channel sum, read once
    once = sweep_shadow_times(iter(_blocks(frames)), SHAPE, cfa_pattern="RGGB")
    np.testing.assert_array_equal(once["shadow_time"], _summed(frames)["shadow_time"])
