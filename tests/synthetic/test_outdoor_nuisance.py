"""Tests of shadowcam.synthetic.outdoor.nuisance: timing, auto-exposure, shake, cloud shadow."""

import numpy as np
import pytest

from shadowcam.synthetic.outdoor.nuisance import (apply_shake, auto_exposure, capture_times,
                                        cloud_transmittance, shake_offsets)


def test_regular_and_irregular_capture_times():
    t, nominal, dropped = capture_times(600.0, 21, seed=0, irregular=False)
    np.testing.assert_allclose(t, np.linspace(0, 600, 21))
    np.testing.assert_array_equal(nominal, np.arange(21))
    assert dropped.size == 0
    t, nominal, dropped = capture_times(6400.0, 120, seed=3, irregular=True, dropped=2)
    assert len(t) == 120 and t[0] == 0 and t[-1] == pytest.approx(6400.0, abs=1e-3)
    assert np.all(np.diff(t) > 0) and np.all(t == np.round(t, 3))
    assert len(dropped) == 2 and not set(dropped) & set(nominal)
    assert sorted(set(nominal) | set(dropped)) == list(range(122))
    dt = np.diff(t)
    assert dt.max() / dt.min() > 1.5  # regimes, jitter, slow writes and the dropped slots
    with pytest.raises(ValueError, match="dropped"):
        capture_times(100.0, 10, seed=0, dropped=5)


def test_auto_exposure_keeps_the_metered_level_within_half_an_ev():
    levels = 0.5 ** np.linspace(0, 3, 80)  # the scene dims by 3 EV
    gain, ev = auto_exposure(levels, seed=1)
    assert np.all(np.abs(np.diff(ev)[np.diff(ev) != 0]) >= 1 / 3 - 1e-12)
    np.testing.assert_allclose(ev * 3, np.round(ev * 3), atol=1e-12)  # 1/3-EV steps
    residual = np.log2(levels * 2.0**ev / levels[0])
    assert np.all(np.abs(residual) <= 0.5 + 1e-12)
    flicker = np.log(gain / 2.0**ev)
    assert 0.002 < flicker.std() < 0.012
    off_gain, off_ev = auto_exposure(levels, seed=1, enabled=False)
    assert np.all(off_gain == 1) and np.all(off_ev == 0)


def test_shake_is_bounded_and_moves_content_by_plus_dx_dy():
    dx, dy = shake_offsets(500, seed=2, max_px=2.0)
    assert np.hypot(dx, dy).max() <= 2.0 + 1e-9 and np.hypot(dx, dy).max() > 1.2
    none = shake_offsets(10, seed=2, max_px=0.0)
    assert np.all(none[0] == 0) and np.all(none[1] == 0)
    rows, cols = np.mgrid[0:40, 0:50].astype(float)
    image = np.stack([np.sin(cols / 5.0) + np.cos(rows / 7.0) + 2.0] * 3, axis=2)
    out = apply_shake(image, 1.25, -0.5)
    # out(u, v) = image(u - dx, v - dy), away from the replicated edges
    expected = np.sin((cols - 1.25) / 5.0) + np.cos((rows + 0.5) / 7.0) + 2.0
    np.testing.assert_allclose(out[5:-5, 5:-5, 1], expected[5:-5, 5:-5], atol=2e-3)


def test_cloud_shadow_is_a_soft_moving_blob():
    pts = np.array([[0.0, 0.0], [250.0, 0.0], [5000.0, 0.0]])
    c = cloud_transmittance(pts, 0.0, start_xy=(0, 0), velocity_xy=(1.0, 0.0), depth=0.5)
    np.testing.assert_allclose(c, [0.5, 1 - 0.5 * np.exp(-0.5), 1.0], atol=1e-12)
    later = cloud_transmittance(pts, 250.0, start_xy=(0, 0), velocity_xy=(1.0, 0.0), depth=0.5)
    assert later[1] == pytest.approx(0.5)


def test_a_cloud_with_a_rim_is_a_disk_with_a_hard_or_soft_border():
    pts = np.array([[0.0, 0.0], [100.0, 0.0], [104.0, 0.0], [300.0, 0.0]])
    hard = cloud_transmittance(pts, 0.0, start_xy=(0, 0), velocity_xy=(1.0, 0.0), sigma_m=100.0, depth=0.8, rim_m=2.0)
    np.testing.assert_allclose(hard, [0.2, 0.6, 1 - 0.8 / (1 + np.exp(2.0)), 1.0], atol=1e-9)
    soft = cloud_transmittance(pts, 0.0, start_xy=(0, 0), velocity_xy=(1.0, 0.0), sigma_m=100.0, depth=0.8, rim_m=40.0)
    assert soft[2] < hard[2] and soft[0] > hard[0]  # the soft rim reaches further out and in
    with pytest.raises(ValueError, match="rim_m"):
        cloud_transmittance(pts, 0.0, start_xy=(0, 0), velocity_xy=(1.0, 0.0), rim_m=0.0)
