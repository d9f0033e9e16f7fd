"""The cloud's shade as a field over the frame: block levels, transmittance, interpolation."""

import numpy as np

import pytest

from shadowcam.outdoor.shade_field import block_grid, block_levels, interpolate_field, shade_field


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


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_block_levels_are_each_blocks_upper_quartile_of_its_lit_ratios(dtype):
    rng = np.random.default_rng(5)
    ref = (rng.random((120, 150)) * 0.8 + 0.1).astype(dtype)
    ref[:3, :3] = 0  # no ratio where the reference is 0
    state = rng.choice([0.2, 0.9, 1.1], p=[0.05, 0.5, 0.45], size=ref.shape)
    state[48:72, 0:24] = 0.2  # a block the ridge reached: no level
    luma = (ref * state * (1 + 0.05 * rng.standard_normal(ref.shape))).astype(dtype)
    pixels = rng.random(ref.shape) > 0.1
    pixels[96:, 120:] = False  # blocks without lit pixels (the last one 6 columns wide): no level
    rows, cols, _, _ = block_grid(ref.shape, block=24, factor=1)
    levels = block_levels(luma, ref, pixels=pixels, row_edges=rows, col_edges=cols, reached_below=0.3)
    expected = np.full(levels.shape, np.nan)
    for i in range(rows.size - 1):
        for j in range(cols.size - 1):
            block = np.s_[rows[i]:rows[i + 1], cols[j]:cols[j + 1]]
            used = pixels[block] & (ref[block] > 0)
            ratio = luma[block][used] / ref[block][used]
            lit = ratio[ratio >= 0.3]
            if lit.size >= 10 and 4 * (ratio.size - lit.size) < ratio.size and 4 * ratio.size >= used.size:
                expected[i, j] = np.percentile(lit, 75)
    assert np.isnan(levels[[2, 4, 4], [0, 5, 6]]).all() and np.isfinite(levels).sum() == levels.size - 3
    assert np.array_equal(levels, expected, equal_nan=True)  # numpy's percentile, bit for bit
