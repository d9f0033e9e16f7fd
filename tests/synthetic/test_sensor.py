"""Tests of shadowcam.synthetic.sensor: the Poisson-Gaussian model, mosaic, levels and seeding."""

import numpy as np
import pytest

from shadowcam.synthetic.sensor import (
    SensorModel,
    electrons_per_unit_radiance,
    mosaic_rggb,
    raw_to_linear,
    simulate_raw,
)


def test_rggb_layout():
    img = np.zeros((4, 6, 3))
    img[..., 0], img[..., 1], img[..., 2] = 1, 2, 3
    m = mosaic_rggb(img)
    np.testing.assert_array_equal(m[0::2, 0::2], 1)
    np.testing.assert_array_equal(m[0::2, 1::2], 2)
    np.testing.assert_array_equal(m[1::2, 0::2], 2)
    np.testing.assert_array_equal(m[1::2, 1::2], 3)


@pytest.mark.parametrize("electrons", [20.0, 400.0])
def test_noise_mean_and_variance_follow_poisson_gaussian(electrons):
    """var(DN) = gain^2 * mean_electrons + read^2 (+ 1/12 quantisation), mean = black + gain e."""
    sensor = SensorModel(bit_depth=14, black_level=512, gain=1.5, read_noise=4.0)
    radiance = np.full((200, 200, 3), electrons / 1000.0)
    dn = simulate_raw(radiance, sensor=sensor, scale=1000.0, seed=[1, 0, 0]).astype(float)
    expected_var = sensor.gain**2 * electrons + sensor.read_noise**2 + 1 / 12
    assert dn.mean() == pytest.approx(sensor.black_level + sensor.gain * electrons, rel=2e-3)
    # 40,000 samples: relative standard error of a variance is sqrt(2/n) ~ 0.7%
    assert dn.var() == pytest.approx(expected_var, rel=0.03)


def test_noise_is_seeded_and_switchable():
    sensor = SensorModel()
    img = np.random.default_rng(0).uniform(0, 1, (8, 8, 3))
    a = simulate_raw(img, sensor=sensor, scale=1000.0, seed=[7, 1, 3])
    b = simulate_raw(img, sensor=sensor, scale=1000.0, seed=[7, 1, 3])
    c = simulate_raw(img, sensor=sensor, scale=1000.0, seed=[7, 1, 4])
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    clean = simulate_raw(img, sensor=sensor, scale=1000.0, noise=False)
    np.testing.assert_array_equal(clean, np.rint(256 + 1000.0 * mosaic_rggb(img)))
    with pytest.raises(ValueError, match="seed"):
        simulate_raw(img, sensor=sensor, scale=1000.0)


def test_levels_clip_and_normalise():
    sensor = SensorModel(bit_depth=12, black_level=256)
    assert sensor.white_level == 4095
    img = np.zeros((2, 2, 3))
    img[0, 1, 1] = 10.0  # the G photosite at (even row, odd col) saturates
    dn = simulate_raw(img, sensor=sensor, scale=1e4, noise=False)
    assert dn.dtype == np.uint16 and dn.max() == 4095 and dn.min() == 256
    lin = raw_to_linear(dn, sensor=sensor)
    assert lin.dtype == np.float32
    assert lin.max() == 1.0 and lin.min() == 0.0
    with pytest.raises(ValueError, match="bit_depth"):
        SensorModel(bit_depth=20)
    with pytest.raises(ValueError, match="black_level"):
        SensorModel(bit_depth=8, black_level=300)


def test_exposure_scale_places_percentile_at_target():
    sensor = SensorModel(bit_depth=12, black_level=256)
    ref = np.random.default_rng(1).uniform(0, 0.01, (64, 64, 3))
    scale = electrons_per_unit_radiance(ref, sensor=sensor, target_fraction=0.5, percentile=99.5)
    level = np.percentile(mosaic_rggb(ref), 99.5)
    assert scale * level == pytest.approx(0.5 * (4095 - 256))
