"""The cloud's shade as a field over the frame: block levels, transmittance, interpolation."""

import numpy as np

from shadowcam.outdoor.shade_field import block_grid, interpolate_field, shade_field


def test_shade_field_is_the_transmittance_of_the_blocks_levels():
    # a block's level is gain (rho + T (1 - rho)); T >= 0.9 (FULLY_LIT) reads as no cloud
    rho, gain = 0.15, np.array([1.0, 1.3, 2.0])
    transmittance = np.array([[[1.0, 0.95], [0.6, 0.3]],
                              [[0.5, 0.5], [0.5, 0.5]],
                              [[1.0, 1.0], [1.0, 1.0]]])
    levels = gain[:, None, None] * (rho + transmittance * (1 - rho))
    field = shade_field(levels, gain, shadow_ratio=rho)
    expected = np.where(transmittance < 0.9, transmittance, 1.0)
    np.testing.assert_allclose(field, expected, rtol=1e-6)
    assert np.all(field[2] == 1.0)  # no cloud: exactly 1
    # blocks without a level take the nearest block's; a frame without any reads 1
    levels[0, 0, 0] = levels[1] = np.nan
    field = shade_field(levels, gain, shadow_ratio=rho)
    assert field[0, 0, 0] == 1.0 and np.all(field[1] == 1.0)
    levels[0, 0, :] = np.nan
    np.testing.assert_allclose(shade_field(levels, gain, shadow_ratio=rho)[0, 0], [0.6, 0.3], rtol=1e-6)


def test_interpolated_field_is_bilinear_in_the_block_centres_and_the_same_in_column_strips():
    rows, cols, row_centres, col_centres = block_grid((40, 30), block=16, factor=2)
    np.testing.assert_array_equal(rows, [0, 16, 32, 40])
    np.testing.assert_array_equal(row_centres, [16.0, 48.0, 72.0])
    np.testing.assert_array_equal(col_centres, [16.0, 46.0])
    field = 0.3 + 0.004 * row_centres[:, None] + 0.002 * col_centres[None, :]  # a plane
    value = interpolate_field(field, row_centres=row_centres, col_centres=col_centres, shape=(80, 60))
    r, c = np.arange(80)[:, None] + 0.5, np.arange(60)[None, :] + 0.5
    plane = 0.3 + 0.004 * np.clip(r, 16, 72) + 0.002 * np.clip(c, 16, 46)  # held beyond the outer centres
    np.testing.assert_allclose(value, plane, atol=1e-6)
    strip = interpolate_field(field, row_centres=row_centres, col_centres=col_centres - 20, shape=(80, 25))
    np.testing.assert_array_equal(strip, value[:, 20:45])
