"""Photometric normalisation: exposure gains, lit/shadow split, robust gain, coverage."""

import numpy as np
import pytest

from shadowcam.outdoor.photometric import coverage, estimate_gain, exposure_gains, lit_at_start, luminance


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
