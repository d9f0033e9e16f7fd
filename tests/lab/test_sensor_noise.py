"""Poisson-Gaussian noise of a sweep: the model fitted to per-pixel estimates, pixels noisier than it."""

import numpy as np
import pytest

from shadowcam.lab.sensor_noise import fit_noise_model, pixel_noise

GAIN, FLOOR = 4e-5, 3e-7  # variance = GAIN * level + FLOOR, frame units


def _estimates(rng, n_pixels, n_diff):
    """Levels and their variance estimates from `n_diff` first differences of Gaussian samples."""
    level = rng.uniform(0.03, 0.2, n_pixels)
    sigma = np.sqrt(GAIN * level + FLOOR)
    samples = level[:, None] + sigma[:, None] * rng.standard_normal((n_pixels, n_diff + 1))
    variance = np.mean(np.diff(samples, axis=1) ** 2, axis=1) / 2.0
    return level, variance, np.full(n_pixels, n_diff)


def test_the_model_is_recovered_from_noisy_per_pixel_estimates():
    level, variance, count = _estimates(np.random.default_rng(0), 2000, 20)
    gain, floor = fit_noise_model(level, variance, count)
    # 2000 pixels x 20 differences: the slope within 5 %, the floor (1/25 of the variance
    # at the middle level) within 1e-6
    assert gain == pytest.approx(GAIN, rel=0.05)
    assert abs(floor - FLOOR) < 1e-6
    # the pixels' own estimates scatter by tens of percent; the model's noise is exact
    truth = np.sqrt(GAIN * level + FLOOR)
    noise = pixel_noise(level, variance, count, model=(GAIN, FLOOR))
    assert np.percentile(np.abs(np.sqrt(variance) / truth - 1), 90) > 0.2
    assert np.mean(noise == truth) > 0.99


def test_a_pixel_noisier_than_the_sensor_keeps_its_own_noise():
    level, variance, count = _estimates(np.random.default_rng(1), 500, 30)
    variance[:10] *= 9.0  # three times the sensor's noise (flicker)
    noise = pixel_noise(level, variance, count, model=fit_noise_model(level, variance, count))
    np.testing.assert_array_equal(noise[:10], np.sqrt(variance[:10]))


def test_noise_free_and_missing_estimates():
    level = np.linspace(0.1, 0.2, 6)
    assert fit_noise_model(level, np.zeros(6), np.full(6, 10)) == (0.0, 0.0)
    assert all(np.isnan(fit_noise_model(level[:1], np.zeros(1), np.ones(1))))
    noise = pixel_noise(level, np.zeros(6), np.array([10, 10, 10, 10, 10, 0]), model=(0.0, 0.0))
    np.testing.assert_array_equal(noise[:5], 0.0)
    # no estimate and no model: NaN, not a made-up noise
    assert np.isnan(pixel_noise(level, np.zeros(6), np.zeros(6), model=(np.nan, np.nan))).all()
    with pytest.raises(ValueError, match="false_alarm"):
        pixel_noise(level, np.zeros(6), np.ones(6), model=(0.0, 0.0), false_alarm=1.5)
