"""Photometric normalisation: exposure gains, lit/shadow split, robust gain, coverage."""

import numpy as np
import pytest

from shadowcam.outdoor.photometric import (coverage, estimate_gain, estimate_lit_gain, exposure_gains, lit_at_start,
                                          luminance)


def test_exposure_gains_relative_to_first_known():
    gains = exposure_gains([np.nan, 0.01, 0.02, np.nan, 0.005])
    np.testing.assert_allclose(gains, [np.nan, 1.0, 2.0, np.nan, 0.5])
    assert np.isnan(exposure_gains([np.nan, np.nan])).all()


def test_luminance_keeps_float32_and_needs_channels():
    image = np.ones((4, 5, 3), np.float32) * np.float32([1, 2, 3])
    out = luminance(image)
    assert out.dtype == np.float32 and np.allclose(out, 2.0)
    with pytest.raises(ValueError, match="channel"):
        luminance(np.ones(4))


def test_lit_at_start_splits_sun_and_sky_lit():
    rng = np.random.default_rng(1)
    albedo = 0.5 + 0.3 * rng.random((30, 30))
    lit = np.zeros((30, 30), bool)
    lit[:12] = True
    luma = albedo * np.where(lit, 1.0, 0.1)
    valid = np.ones_like(lit)
    valid[0] = False
    found, threshold = lit_at_start(luma, valid=valid)
    assert np.array_equal(found, lit & valid)
    assert 0.08 < threshold < 0.5


def test_estimate_gain_ignores_newly_shadowed_pixels():
    rng = np.random.default_rng(2)
    ref = 0.2 + rng.random((50, 50))
    frame = 1.7 * ref
    frame[:20] *= 0.1  # 40% of the pixels went into shadow
    gain, kept = estimate_gain(frame, ref, pixels=np.ones_like(ref, bool), prior=1.5)
    assert gain == pytest.approx(1.7, rel=1e-9)
    assert kept == 30 * 50
    with pytest.raises(ValueError, match="prior"):
        estimate_gain(frame, ref, pixels=np.ones_like(ref, bool), prior=0)


def test_coverage_is_the_lit_fraction():
    lit, shadow = np.full((2, 2), 0.8), np.full((2, 2), 0.1)
    fraction = np.array([[0.0, 0.25], [0.5, 1.0]])
    luma = shadow + fraction * (lit - shadow)
    out = coverage(luma, lit_level=lit, shadow_level=shadow)
    assert out.dtype == np.float32
    np.testing.assert_allclose(out, fraction, atol=1e-6)
    assert np.isnan(coverage(luma, lit_level=shadow, shadow_level=shadow)).all()


def _cloudy_frame(rng, *, share, rim, sun=0.9, sky=0.95, exposure=1.37, depth=0.6, noise=0.01):
    """A frame of lit (rows 0-39) and sky-lit (rows 40-63) pixels under a cloud shadow.

    Lit: ``exposure (T sun s + sky a)``, sky-lit: ``exposure sky a``, reference ``s + a`` and
    ``a``; the cloud (a disc whose transmittance of the sun term falls from 1 to ``1 - depth``
    over a rim of `rim` pixels, centred on the lit pixels) covers `share` of the lit pixels
    (transmittance < 1). Returns the reference, the frame, the lit mask, the true lit and sky
    gains (the noise-free cloud-free frame's median ratio over the lit pixels, and
    ``exposure sky``) and the share the cloud covers.
    """
    s = rng.uniform(0.6, 1.2, (64, 64))
    a = rng.uniform(0.1, 0.2, (64, 64))
    lit = np.zeros((64, 64), bool)
    lit[:40] = True
    reference = np.where(lit, s + a, a)
    rows, cols = np.mgrid[:64, :64]
    distance = np.hypot(rows - 20.0, cols - 32.0)
    radius = np.sort(distance[lit])[int(round(share * lit.sum())) - 1] + 1e-9 if share > 0 else -1.0
    inside = np.clip((radius - distance) / max(rim, 1e-9), 0.0, 1.0)  # 0 outside, 1 beyond the rim
    transmittance = 1.0 - depth * inside
    clear = exposure * np.where(lit, sun * s + sky * a, sky * a)
    frame = exposure * np.where(lit, transmittance * sun * s + sky * a, sky * a)
    frame = frame * (1.0 + noise * rng.standard_normal(frame.shape))
    true_lit = float(np.median(clear[lit] / reference[lit]))
    covered = float((transmittance[lit] < 1).mean())
    return reference, frame, lit, true_lit, exposure * sky, covered


@pytest.mark.parametrize("rim", [0.0, 6.0])  # hard and soft cloud borders
@pytest.mark.parametrize("share", [0.0, 0.5, 0.9])
def test_lit_gain_is_the_unclouded_population_whatever_the_cloud_covers(share, rim):
    rng = np.random.default_rng([5, int(10 * share), int(rim)])
    reference, frame, lit, true_lit, true_sky, covered = _cloudy_frame(rng, share=share, rim=rim)
    assert abs(covered - share) < 0.01
    # expected from the sky gain and a lit-to-sky ratio a frame old (the sun faded 1 % more since)
    expected = true_sky * (true_lit / true_sky) * 1.01
    gain, kept, found = estimate_lit_gain(frame, reference, pixels=lit, expected=expected)
    assert found and kept >= 0.5 * (1 - share) * lit.sum()
    # the median of ~2560 x (1 - share) ratios of 1 % noise and the pixels' own spread: 0.3 %
    assert abs(gain / true_lit - 1) < 0.003
    if share <= 0.5:  # without an expected level, from the 90th percentile (> 10 % unclouded)
        gain, _, found = estimate_lit_gain(frame, reference, pixels=lit)
        assert found and abs(gain / true_lit - 1) < 0.003
    else:  # the median of the lit pixels follows the cloud
        old, _ = estimate_gain(frame, reference, pixels=lit, prior=expected)
        assert old / true_lit - 1 < -0.3


def test_lit_gain_cloud_free_is_the_median_within_noise():
    for seed in range(5):
        reference, frame, lit, true_lit, _, _ = _cloudy_frame(np.random.default_rng([6, seed]), share=0.0, rim=0.0)
        ratios = frame[lit] / reference[lit]
        old, _ = estimate_gain(frame, reference, pixels=lit, prior=true_lit)
        new, _, _ = estimate_lit_gain(frame, reference, pixels=lit, expected=true_lit)
        # the standard error of a median: 1.25 sigma / sqrt(n)
        assert abs(new - old) < 3 * 1.25 * (np.std(ratios) / np.sqrt(ratios.size))


def test_lit_gain_under_a_cloud_over_every_lit_pixel_is_the_expected_level():
    reference, frame, lit, true_lit, true_sky, covered = _cloudy_frame(
        np.random.default_rng(7), share=1.0, rim=0.0, depth=0.5)
    assert covered == 1.0
    gain, kept, found = estimate_lit_gain(frame, reference, pixels=lit, expected=true_lit)
    assert not found and kept == 0 and gain == true_lit


def test_lit_gain_validates_its_options():
    reference, frame, lit, *_ = _cloudy_frame(np.random.default_rng(8), share=0.0, rim=0.0)
    with pytest.raises(ValueError, match="spread"):
        estimate_lit_gain(frame, reference, pixels=lit, spread=0.0)
    with pytest.raises(ValueError, match="expected"):
        estimate_lit_gain(frame, reference, pixels=lit, expected=-1.0)
    with pytest.raises(ValueError, match="min_ratio"):
        estimate_lit_gain(frame, reference, pixels=lit, min_ratio=1.0)
    with pytest.raises(ValueError, match="pixels"):
        estimate_lit_gain(frame, reference, pixels=lit[:10])
