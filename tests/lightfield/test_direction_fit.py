import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from shadowcam.lightfield import direction_fit, rays


def _field(shape=(64, 64)):
    r, c = np.mgrid[:shape[0], :shape[1]].astype(float)
    return np.stack([0.001 * (c - 32) + 2e-6 * (c - 32) ** 2, 0.0008 * (r - 32) - 1e-6 * (r - 32) * (c - 32)], -1)


@settings(max_examples=5, deadline=None)
@given(seed=st.integers(0, 2**16), bandwidth=st.sampled_from([1.0, 2.0, 3.0]))
def test_local_linear_error_matches_the_noise_model(seed, bandwidth):
    rng = np.random.default_rng(seed)
    n = 160  # the fit's errors are correlated over ~4 pi h^2 px: 136^2 inner px leave >= 300 independent
    true = _field((n, n))
    std = np.where(np.arange(n)[None, :] < n // 2, 1e-3, 2e-3) * np.ones((n, 1))
    est, est_std = direction_fit.local_linear_fit(true + rng.normal(size=true.shape) * std[..., None], std,
                                                  bandwidth=bandwidth)
    inner = (slice(12, -12), slice(12, -12))
    z = (est - true)[inner] / est_std[inner][..., None]
    # the std of a std from >= 300 independent values is <= 0.04: +-0.15 is about 4 of them
    assert 0.85 < np.std(z) < 1.15                       # the fit's error is its predicted std
    # inverse-variance weights: interior std ~ 1 / sqrt(sum of weights), well below the raw noise
    assert np.median(est_std[inner]) < 0.5 * np.median(std[inner])


def test_fit_directions_reduces_independent_noise_and_keeps_a_linear_field_exact():
    rng = np.random.default_rng(3)
    true = _field()
    std = np.full((64, 64), 1.5e-3)
    fit = direction_fit.fit_directions(true + rng.normal(size=true.shape) * std[..., None], std)
    inner = (slice(8, -8), slice(8, -8))
    rms = np.sqrt(np.mean((fit["direction"] - true)[inner] ** 2))
    assert rms < 0.3 * 1.5e-3
    assert np.sqrt(np.mean(fit["direction_std"][inner] ** 2)) == pytest.approx(rms, rel=0.3)
    linear = np.stack(np.mgrid[:32, :32].astype(float), -1) * 1e-3
    exact = direction_fit.fit_directions(linear, np.full((32, 32), 1e-3))["direction"]
    assert np.allclose(exact, linear, atol=1e-12)        # no bias on a linear field


def test_direction_noise_propagates_mask_std():
    got = direction_fit.direction_noise(np.full((2, 2), 0.03), np.full((2, 2), 0.04), np.full((2, 2), 9.0),
                                        separation_mm=200.0)
    assert np.allclose(got, 9.0 * 0.05 / np.sqrt(2) / 200.0)
    with pytest.raises(ValueError, match="separation_mm"):
        direction_fit.direction_noise(got, got, got, separation_mm=0.0)


def _screen(z, shape=(24, 24), pitch=1.0, hole=None):
    r, c = np.mgrid[:shape[0], :shape[1]].astype(float)
    xy = np.stack([(c - 11.5) * pitch, (r - 11.5) * pitch], -1) * z / 100.0
    mask = xy * 50.0 / z                                  # rays from the origin, mask at 50 mm
    ok = np.ones(shape, bool)
    if hole is not None:
        ok[hole] = False
    return {"mask": np.where(ok[..., None], mask, np.nan), "mask_std": np.where(ok, 0.01, np.nan), "xy": xy,
            "area": np.full(shape, (pitch * z / 100.0) ** 2), "irradiance": np.ones(shape), "ok": ok,
            "position_mm": float(z)}


def test_edge_rays_get_the_local_fit_direction_and_are_flagged():
    hole = (slice(0, 24), slice(0, 3))                    # beam edge: no correspondence on the left
    ray_set = rays.rays_dataset(_screen(100.0, hole=hole), _screen(200.0), edge_rays="fit", anchor="near")
    xy = _screen(100.0)["xy"]
    expected = xy / 100.0                                 # a point source at the origin: d = x / z
    assert np.all(ray_set["flag"].values[hole] == rays.NO_SHADOW_NEAR)
    assert np.allclose(ray_set["direction"].values[..., :2], expected, atol=1e-9)  # linear field: exact
    assert np.all(np.isfinite(ray_set["direction_std"].values[hole]))
    nearest = rays.rays_dataset(_screen(100.0, hole=hole), _screen(200.0), edge_rays="nearest", anchor="near")
    assert not np.allclose(nearest["direction"].values[hole][..., :2], expected[hole], atol=1e-3)
    dropped = rays.rays_dataset(_screen(100.0, hole=hole), _screen(200.0), edge_rays="drop", anchor="near")
    assert np.all(dropped["flux"].values[hole] == 0) and np.all(dropped["flux"].values[:, 3:] > 0)
    with pytest.raises(ValueError, match="edge_rays"):
        rays.rays_dataset(_screen(100.0), _screen(200.0), edge_rays="borrow")


def test_far_anchored_rays_err_by_the_near_screens_smaller_magnification():
    # rays from a point source at the origin, mask at 50 mm, screens at 100 and 200 mm: screen mm
    # per mask mm 2 (near) and 4 (far); independent mask noise of the same std on both screens.
    # A ray's direction error is the other screen's magnification times the anchor's mask error
    # over the separation: 4 sigma / 100 anchored near, 2 sigma / 100 anchored far.
    rng = np.random.default_rng(3)
    sigma = 0.02
    errors = {}
    for anchor in rays.ANCHORS:
        near, far = _screen(100.0, shape=(48, 48), pitch=0.5), _screen(200.0, shape=(48, 48), pitch=0.5)
        for screen in (near, far):
            screen["mask"] = screen["mask"] + rng.normal(0.0, sigma, screen["mask"].shape)
            screen["mask_std"] = np.full(screen["ok"].shape, sigma * np.sqrt(2))
        ray_set = rays.rays_dataset(near, far, anchor=anchor)
        origin = ray_set["origin"].values
        assert np.all(origin[..., 2] == (100.0 if anchor == "near" else 200.0))
        truth = origin[..., :2] / origin[..., 2:]                  # d = x / z through the anchor pixel
        inner = (slice(4, -4), slice(4, -4))
        d = ray_set["direction"].values[..., :2]
        errors[anchor] = np.sqrt(np.mean((d - truth)[inner] ** 2))  # per-axis rms
    # per axis: g_other * (anchor's mask error - the other map's, interpolated) / 100, at most
    # g_other sqrt(2) sigma / 100; the two anchors' ratio is the magnifications' 2 / 4 (15 % for
    # 1600 rays' rms)
    assert errors["far"] / errors["near"] == pytest.approx(0.5, rel=0.15)
    assert errors["near"] == pytest.approx(4 * sigma * np.sqrt(2) / 100.0, rel=0.2)


def test_rays_through_the_mask_point_err_by_the_mask_error_over_the_mask_distance():
    # the same point source: the ray through the anchor pixel and its mask point (mask plane at
    # 50 mm) tilts by the anchor's mask error over (z_anchor - 50 mm), whatever the other
    # screen's magnification: per-axis rms sigma / 150 anchored far (against 2 sigma / 100
    # through the near screen's point), and the noise model reports that std
    rng = np.random.default_rng(5)
    sigma = 0.02
    near, far = _screen(100.0, shape=(48, 48), pitch=0.5), _screen(200.0, shape=(48, 48), pitch=0.5)
    for screen in (near, far):
        screen["mask"] = screen["mask"] + rng.normal(0.0, sigma, screen["mask"].shape)
        screen["mask_std"] = np.full(screen["ok"].shape, sigma * np.sqrt(2))
    errors = {}
    for anchor in rays.ANCHORS:
        ray_set = rays.rays_dataset(near, far, anchor=anchor, mask_position_mm=50.0)
        assert ray_set.attrs["through"] == "mask"
        origin = ray_set["origin"].values
        truth = origin[..., :2] / origin[..., 2:]
        error = (ray_set["direction"].values[..., :2] - truth)[4:-4, 4:-4]
        errors[anchor] = np.sqrt(np.mean(error ** 2))
        lever = origin[0, 0, 2] - 50.0
        # 1600 rays x 2 axes: the rms is within 5 % of its std (4 of the rms's own std)
        assert errors[anchor] == pytest.approx(sigma / lever, rel=0.1)
        good = ray_set["flag"].values == rays.OK
        assert good[4:-4, 4:-4].all()
        assert np.allclose(ray_set["direction_std"].values[good], sigma / lever)
    screen_far = rays.rays_dataset(near, far, anchor="far")
    assert screen_far.attrs["through"] == "screen"
    with pytest.raises(ValueError, match="mask_position_mm"):
        rays.rays_dataset(near, far, mask_position_mm=150.0)


def test_rays_through_the_mask_point_start_from_the_flux_centroid():
    # noise-free point source, irradiance rising along x: a pixel's flux is centred
    # footprint_variance * grad(E) / E px off its centre; the ray through the mask point
    # recorded for that centroid is exact only from the centroid
    near, far = _screen(100.0), _screen(200.0)
    var, k = 1.0 / 6.0, 0.05                              # px^2; E = 1 + k * col (linear: first order exact)
    col = np.arange(24.0)[None, :] * np.ones((24, 1))
    for screen in (near, far):
        screen["irradiance"] = 1.0 + k * col
        pitch = screen["xy"][0, 1, 0] - screen["xy"][0, 0, 0]
        centroid_x = screen["xy"][..., 0] + var * k / screen["irradiance"] * pitch
        screen["mask"] = np.stack([centroid_x, screen["xy"][..., 1]], -1) * 50.0 / screen["position_mm"]
    centred = rays.rays_dataset(near, far, mask_position_mm=50.0, footprint_variance=var)
    truth = (far["xy"] / 200.0)
    truth[..., 0] += var * k / far["irradiance"] * (far["xy"][0, 1, 0] - far["xy"][0, 0, 0]) / 200.0
    assert np.allclose(centred["direction"].values[..., :2], truth, atol=1e-12)
    at_centre = rays.rays_dataset(near, far, mask_position_mm=50.0)
    assert np.max(np.abs(at_centre["direction"].values[..., :2] - truth)) > 1e-5
