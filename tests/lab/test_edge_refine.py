"""Edge-aware plane fit: exact on planes, sharp at discontinuities, averages noise."""

import numpy as np
import pytest

from shadowcam.lab.edge_refine import refine_times


def test_plane_is_reproduced_exactly_including_borders():
    rows, cols = np.mgrid[0:20, 0:30]
    plane = 3.0 + 0.4 * cols - 0.25 * rows
    refined, std = refine_times(plane, np.full(plane.shape, 0.2))
    np.testing.assert_allclose(refined, plane, atol=1e-9)
    assert np.all(std < 0.2)


def test_depth_discontinuity_stays_sharp():
    rows, cols = np.mgrid[0:20, 0:30]
    times = np.where(cols < 15, 0.5 * cols, 40.0 + 0.5 * cols)
    refined, _ = refine_times(times, np.full(times.shape, 0.1))
    np.testing.assert_allclose(refined, times, atol=1e-6)


def test_staircase_quantisation_is_averaged_out():
    # a pixel's own estimate rounds to the frame centre: floor(t) + 0.5
    rows, cols = np.mgrid[0:40, 0:40]
    truth = 0.5 * cols + 0.13 * rows
    staircase = np.floor(truth) + 0.5
    refined, _ = refine_times(staircase, np.full(truth.shape, 0.15))
    inner = (slice(4, -4), slice(4, -4))
    assert np.percentile(np.abs(staircase - truth)[inner], 95) > 0.4
    assert np.percentile(np.abs(refined - truth)[inner], 95) < 0.1


def test_noise_is_reduced_and_missing_pixels_stay_missing():
    rng = np.random.default_rng(0)
    rows, cols = np.mgrid[0:40, 0:40]
    truth = 0.3 * cols
    noisy = truth + rng.normal(0, 0.4, truth.shape)
    noisy[10, 10] = np.nan
    refined, _ = refine_times(noisy.astype(np.float32), np.full(truth.shape, 0.4))
    assert refined.dtype == np.float32
    assert np.isnan(refined[10, 10])
    inner = (slice(4, -4), slice(4, -4))
    assert np.nanstd((refined - truth)[inner]) < 0.4 / 3


def test_rejects_bad_parameters():
    with pytest.raises(ValueError, match="radius"):
        refine_times(np.zeros((4, 4)), 1.0, radius=0)
    with pytest.raises(ValueError, match="range_sigma"):
        refine_times(np.zeros((4, 4)), 1.0, range_sigma=0)
    with pytest.raises(ValueError, match="time"):
        refine_times(np.zeros(4), 1.0)


def _sphere_cap_times(radius=60.0, size=48):
    """Shadow times over a sphere seen head-on: curved, smooth, not a quadric in (row, col)."""
    rows, cols = np.mgrid[0:size, 0:size].astype(float)
    centre = size / 2
    height = np.sqrt(radius**2 - (rows - centre) ** 2 - (cols - centre) ** 2)
    return 10.0 + 0.8 * cols + 0.6 * height


def test_clean_centroid_on_a_curved_surface_is_kept():
    # noise-free own times (an open-shutter centroid) stated with the workflow's prior std:
    # the dispersion about the local quadratic is ~0, so the own time carries the weight
    times = _sphere_cap_times()
    refined, _ = refine_times(times, np.full(times.shape, 0.15))
    np.testing.assert_allclose(refined, times, atol=0.01)


def test_curved_surface_with_noise_is_still_smoothed():
    # noise well above the plane's misfit: the plane keeps most of the weight
    rng = np.random.default_rng(3)
    truth = _sphere_cap_times()
    noisy = truth + rng.normal(0, 0.3, truth.shape)
    refined, _ = refine_times(noisy, np.full(truth.shape, 0.3))
    inner = (slice(4, -4), slice(4, -4))
    assert np.sqrt(np.mean((refined - truth)[inner] ** 2)) < 0.3 / 3


def test_noisy_plane_is_averaged():
    # std 0.4 frame -> 0.06 measured (the 48 neighbours' plane carries nearly all the weight)
    rng = np.random.default_rng(1)
    rows, cols = np.mgrid[0:48, 0:48]
    truth = 3 + 0.4 * cols - 0.25 * rows
    noisy = truth + rng.normal(0, 0.4, truth.shape)
    refined, refined_std = refine_times(noisy, np.full(truth.shape, 0.4))
    inner = (slice(4, -4), slice(4, -4))
    assert np.std((refined - truth)[inner]) < 0.4 / 5
    # the stated std follows the achieved error within a factor 1.5
    ratio = np.std((refined - truth)[inner]) / np.median(refined_std[inner])
    assert 1 / 1.5 < ratio < 1.5


def test_silhouette_step_does_not_mix_the_sides():
    # the same noisy plane with and without a 3-frame step at column 24: any weight taken
    # across the step would shift the pixels next to it by 3 frames times that weight
    rng = np.random.default_rng(2)
    rows, cols = np.mgrid[0:40, 0:48]
    plane = 0.5 * cols + 0.1 * rows + rng.normal(0, 0.1, cols.shape)
    step = np.where(cols < 24, 0.0, 3.0)
    flat, _ = refine_times(plane, np.full(plane.shape, 0.1))
    stepped, _ = refine_times(plane + step, np.full(plane.shape, 0.1))
    for side in (slice(21, 24), slice(24, 27)):  # the three columns next to the step, each side
        shift = (stepped - step - flat)[4:-4, side]
        assert abs(np.mean(shift)) < 0.02
        assert np.max(np.abs(shift)) < 0.15


def test_dispersion_is_the_median_of_the_finite_fits():
    from shadowcam.lab.edge_refine import dispersion

    assert dispersion(np.array([[0.5, np.nan], [2.0, 1.0]])) == 1.0
    assert dispersion(np.array([[0.25, np.inf], [0.5, np.nan]])) == 0.375
    assert dispersion(np.full((2, 2), np.nan)) == 1.0
    assert dispersion(np.array([[np.inf, np.inf], [np.nan, np.nan]])) == 1.0


def _reference_fit(times, inv_var, row, col, *, radius=3, range_sigma=0.5, iterations=3):
    """One pixel's IRLS plane and quadratic by numpy least squares (the kernel's stated model)."""
    h, w = times.shape
    own = times[row, col]
    design, offsets, weights = [], [], []
    for dr in range(-radius, radius + 1):
        for dc in range(-radius, radius + 1):
            rr, cc = row + dr, col + dc
            inside = (dr or dc) and 0 <= rr < h and 0 <= cc < w
            if inside and np.isfinite(times[rr, cc]) and inv_var[rr, cc] > 0:
                design.append([1.0, dr, dc, dr * dr, dr * dc, dc * dc])
                offsets.append(times[rr, cc] - own)
                weights.append(inv_var[rr, cc])
    x, t, iv = np.array(design), np.array(offsets), np.array(weights)
    coef = np.zeros(3)
    for _ in range(iterations + 1):
        kernel = np.exp(-0.5 * ((t - x[:, :3] @ coef) / range_sigma) ** 2)
        wgt = iv * kernel
        plane = np.linalg.solve(x[:, :3].T @ (wgt[:, None] * x[:, :3]), x[:, :3].T @ (wgt * t))
        coef = plane
    normal3 = x[:, :3].T @ (wgt[:, None] * x[:, :3])
    normal6 = x.T @ (wgt[:, None] * x)
    inverse3 = np.linalg.inv(normal3)
    plane_fit = (own + plane[0], inverse3[0, 0], plane[1], plane[2], inverse3[1, 1], inverse3[2, 2])
    if kernel.sum() - 6.0 <= 1.0:  # too little weight left for the quadratic's dispersion
        return plane_fit + (np.nan, np.nan, np.nan)
    quad = np.linalg.solve(normal6, x.T @ (wgt * t))
    chi2 = np.sum(wgt * (t - x @ quad) ** 2)
    ratio = kernel.sum() / wgt.sum()
    shrunk = chi2 / (kernel.sum() - 6.0) * ratio
    phi = shrunk * range_sigma**2 / (range_sigma**2 - shrunk) / ratio if shrunk < range_sigma**2 else np.inf
    return plane_fit + (phi, own + quad[0], np.linalg.inv(normal6)[0, 0])


@pytest.mark.parametrize("seed", [0, 1])
def test_kernel_solves_the_stated_normal_equations(seed):
    # curved noisy map with a 4-frame step, missing pixels and unequal variances: every
    # pixel's outputs against numpy least squares on its own neighbours (borders included)
    from shadowcam.lab.edge_refine import _exact_inverse, _robust_plane_fit

    rng = np.random.default_rng(seed)
    rows, cols = np.mgrid[0:14, 0:17].astype(float)
    times = 2.0 + 0.45 * cols - 0.2 * rows + 0.01 * (cols - 8) ** 2 + rng.normal(0, 0.15, cols.shape)
    times[:, 9:] += 4.0
    times[rng.random(times.shape) < 0.08] = np.nan
    inv_var = np.where(np.isfinite(times), 1.0 / rng.uniform(0.1, 0.3, times.shape) ** 2, 0.0)
    plane, plane_var, slope, slope_var, phi, quad, quad_var = _robust_plane_fit(times, inv_var, 3, 0.5, 3, _exact_inverse(0.5))
    got = (plane, plane_var, slope[..., 0], slope[..., 1], slope_var[..., 0], slope_var[..., 1], phi, quad,
           quad_var)
    names = ("plane", "plane_var", "slope_r", "slope_c", "slope_r_var", "slope_c_var", "phi", "quad", "quad_var")
    for row, col in zip(*np.nonzero(np.isfinite(times))):
        want = _reference_fit(times, inv_var, row, col)
        for name, value, expected in zip(names, [g[row, col] for g in got], want):
            # times to 1e-9 frame; variances and the dispersion relative to their size
            if not np.isfinite(expected):
                assert value == expected or np.isnan(value) and np.isnan(expected), (name, row, col, value)
                continue
            tol = 1e-9 if name in ("plane", "quad", "slope_r", "slope_c") else 1e-9 * abs(expected)
            assert abs(value - expected) <= tol, (name, row, col, value, expected)


@pytest.mark.parametrize("range_sigma", [0.5, 0.25, 2.0])
def test_power_of_two_range_scale_multiplies_without_changing_a_bit(range_sigma):
    # a power-of-two range_sigma is applied as a product with its exact inverse: every
    # output equal to the division's, NaN placement included
    from shadowcam.lab.edge_refine import _exact_inverse, _robust_plane_fit

    rng = np.random.default_rng(3)
    rows, cols = np.mgrid[0:20, 0:23].astype(float)
    times = 1.0 + 0.37 * cols + 0.11 * rows + 0.02 * rows * cols / 7 + rng.normal(0, 0.2, cols.shape)
    times[:, 12:] -= 3.0
    times[rng.random(times.shape) < 0.1] = np.nan
    inv_var = np.where(np.isfinite(times), 1.0 / rng.uniform(0.05, 0.4, times.shape) ** 2, 0.0)
    inverse = _exact_inverse(range_sigma)
    assert inverse == 1.0 / range_sigma
    by_product = _robust_plane_fit(times, inv_var, 3, range_sigma, 3, inverse)
    by_division = _robust_plane_fit(times, inv_var, 3, range_sigma, 3, 0.0)
    for got, want in zip(by_product, by_division):
        assert np.array_equal(got, want, equal_nan=True)


@pytest.mark.parametrize("value", [0.3, 0.75, 1e-320, np.inf])
def test_no_exact_inverse_for_other_scales(value):
    from shadowcam.lab.edge_refine import _exact_inverse

    assert _exact_inverse(value) == 0.0
