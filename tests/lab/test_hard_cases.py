"""Hard cases and numerical stability of the shadow-time and dual-coordinate stages.

Only public behaviour is exercised: ``DipTracker.update/result``, ``sweep_shadow_times``,
``SHADOW_TIME_METHODS``, ``REASONS``, and the public functions of ``dual_coords``.
Properties (hypothesis): detectors never crash, never return a time outside the sweep,
flag rather than guess, and every flagged pixel carries a reason.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from shadowcam.lab.dip_tracker import DipTracker
from shadowcam.cameras.dual_coords import (dual_coords_calibration, dual_coords_uniform,
                                   fit_time_to_plane)
from shadowcam.synthetic.sensor import SensorModel, raw_to_linear, simulate_raw
from shadowcam.lab.dip_classification import OK, REASONS, SATURATED, SEVERAL_MINIMA
from shadowcam.lab.shadow_time import sweep_shadow_times
from shadowcam.lab.shadow_time_methods import SHADOW_TIME_METHODS

METHODS = sorted(SHADOW_TIME_METHODS)
LEVEL = 0.6  # lit level of the synthetic pixels (white = 1)


@pytest.fixture(scope="module")
def dips(wire_sweep):
    """``dips(n_frames, centres, ...)``: (T, rows, cols) signal, a dip of `width` frames (plus
    linear ramps of `ramp` frames, an area source's penumbra) at `centres` (a time, a (rows,
    cols) array of times, or a list of them for several dips, with a list of `depth`);
    exact, noise-free, float64."""
    def make(n_frames, centres, *, width=2.0, depth=0.9, shape=(6, 6), level=LEVEL, ramp=0.0):
        frames, _ = wire_sweep(n_frames=n_frames, centres=centres, width=width, depth=depth, shape=shape,
                               level=level, ramp=ramp, dtype=np.float64)
        return frames
    return make


def run(stack, **kwargs):
    """Shadow times of a (T, rows, cols) scalar sweep (one channel), in blocks of 7 frames."""
    stack = np.asarray(stack, np.float32)[..., None]
    blocks = [stack[i:i + 7] for i in range(0, len(stack), 7)]
    return sweep_shadow_times(blocks, stack.shape[1:3], **kwargs)


def check_invariants(result, n_frames):
    """Times inside the sweep; a time exactly where the reason is ok; known reasons."""
    t = result["shadow_time"]
    finite = np.isfinite(t)
    assert np.all((t[finite] >= 0) & (t[finite] <= n_frames - 1))
    assert np.array_equal(result["reason"] == OK, finite)
    assert set(np.unique(result["reason"])) <= set(REASONS)
    conf = result["confidence"]
    assert np.all(np.isfinite(conf) & (conf >= 0) & (conf <= 1))
    assert np.all(conf[~finite] == 0)


# ------------------------------------------------------------------ low light, 12 bit


@settings(max_examples=12, deadline=None)
@given(electrons=st.sampled_from([15, 40, 100, 400, 3000]), seed=st.integers(0, 1000),
       method=st.sampled_from(METHODS))
def test_low_light_12bit_times_are_right_or_flagged(electrons, seed, method, dips):
    """Poisson + read noise (6 e-), 12-bit quantisation, 15 to 3000 electrons when lit:
    pixels given a time are within 3 frames of the truth except for the detector's designed
    false alarms (SNR ~ 2 at 15 e-); in good light every pixel is within a frame."""
    rows, cols = np.mgrid[0:8, 0:8]
    centres = 9.0 + 2.6 * cols + 0.4 * rows + np.random.default_rng(seed).uniform()  # an edge
    clean = dips(40, centres, shape=(8, 8)) / LEVEL  # 1 = lit
    sensor = SensorModel(bit_depth=12)
    scale = electrons / sensor.gain
    frames = np.stack([raw_to_linear(simulate_raw(np.repeat(f[..., None], 3, -1), sensor=sensor,
                                                  scale=scale, seed=[seed, k], mosaic=False),
                                     sensor=sensor)[..., 1] for k, f in enumerate(clean)])
    result = run(frames, method=method)
    check_invariants(result, 40)
    err = np.abs(result["shadow_time"] - centres)[np.isfinite(result["shadow_time"])]
    # a gross error (a noise dip taken for the shadow) only at about the designed
    # false-alarm rate (1e-2 per pixel): 0.64 expected of 64 pixels (measured 0.5-1.0 per
    # method over 100 seeds at 15 e-); a Poisson count of mean 1 reaches 7 with p < 1e-4
    assert (err > 3.0).sum() <= 6
    if electrons >= 400:
        assert np.all(err < 1.0)
        assert (result["reason"] == OK).mean() > 0.9


# ------------------------------------------------------------------ saturation


@settings(max_examples=10, deadline=None)
@given(level=st.floats(0.9995, 3.0), method=st.sampled_from(METHODS))
def test_saturated_pixels_are_timed_from_the_dip_below_the_clip(level, method, dips):
    # the clipped pixels' lit level is `level` (white = 1); their dip's floor (0.1 of it)
    # is below the clip, so the censored dip keeps the unclipped pixels' time
    frames = dips(30, 14.3, shape=(4, 4))
    frames[:, :, :2] = np.minimum(frames[:, :, :2] * level / LEVEL, 1.0)  # clipped at white
    result = run(frames, method=method)
    check_invariants(result, 30)
    assert (result["reason"] == OK).all()
    t = result["shadow_time"]
    assert np.abs(t[:, :2] - t[:, 2:].mean()).max() < 0.02


def test_a_pixel_flat_at_the_clip_is_saturated(dips):
    frames = dips(30, 14.3, shape=(4, 4))
    frames[:, :, :2] = 1.0  # white in every frame: a dip, if any, is above the clip
    result = run(frames)
    check_invariants(result, 30)
    assert (result["reason"][:, :2] == SATURATED).all()
    assert (result["reason"][:, 2:] == OK).all()


# ------------------------------------------------------------------ flat, wide minima


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("width", [7.0, 9.0, 12.0, 16.0])
def test_dip_wider_than_the_window_is_flagged_not_biased(width, method, dips):
    """Thick wire: a flat minimum wider than the 9-frame window. Its time is either the
    centre of the dip (within a quarter frame) or the pixel is flagged."""
    result = run(dips(60, 30.3, width=width), method=method, half_window=4)
    check_invariants(result, 60)
    t = result["shadow_time"]
    centre = (np.ceil(30.3 - width / 2) + np.floor(30.3 + width / 2)) / 2  # of dark frames
    assert np.all(np.abs(t[np.isfinite(t)] - centre) < 0.25)


@pytest.mark.parametrize("method", ["dip_centroid", "edge_fit"])
def test_area_source_penumbra_that_fits_the_window_is_timed_at_its_centre(method, dips):
    """Area source: umbra 2 frames, linear penumbra ramps of 3 frames each side."""
    result = run(dips(60, 30.3, width=2.0, ramp=3.0), method=method, half_window=6)
    assert (result["reason"] == OK).all()
    np.testing.assert_allclose(result["shadow_time"], 30.3, atol=0.1)


def test_flat_minimum_narrower_than_the_window_is_timed(dips):
    result = run(dips(60, 30.0, width=7.0), method="dip_centroid", half_window=4)
    assert (result["reason"] == OK).all()
    np.testing.assert_allclose(result["shadow_time"], 30.0, atol=0.25)


# ------------------------------------------------------------------ two minima


@pytest.mark.parametrize("ratio", [0.6, 1.0])
def test_two_comparable_minima_far_apart_are_flagged(ratio, dips):
    """Two sources: two dips 20 frames apart, the second `ratio` as deep."""
    result = run(dips(60, [20.0, 40.0], depth=[0.9, 0.9 * ratio]))
    check_invariants(result, 60)
    assert (result["reason"] == SEVERAL_MINIMA).all()


def test_a_much_weaker_second_minimum_keeps_the_deeper_time(dips):
    result = run(dips(60, [20.5, 40.0], depth=[0.9, 0.25]), method="dip_centroid")
    assert (result["reason"] == OK).all()
    np.testing.assert_allclose(result["shadow_time"], 20.5, atol=0.05)


@pytest.mark.parametrize("gap", [6.0, 8.0])
def test_two_equal_minima_closer_than_a_window_are_flagged(gap, dips):
    result = run(dips(60, [25.0, 25.0 + gap]), half_window=4)
    assert (result["reason"] == SEVERAL_MINIMA).all()


# ------------------------------------------------------------------ zero contrast, NaN, inf


@settings(max_examples=15, deadline=None)
@given(level=st.sampled_from([0.0, 1e-30, 1e-6, 0.5]), method=st.sampled_from(METHODS))
def test_pixels_that_never_change_are_flagged_without_division_by_zero(level, method):
    frames = np.full((25, 5, 5), level, np.float32)
    with np.errstate(divide="raise", invalid="raise"):
        result = run(frames, method=method)
    check_invariants(result, 25)
    assert (result["reason"] != OK).all()
    assert np.all(np.isfinite(result["contrast"]))


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_a_corrupt_sample_far_from_the_dip_is_ignored(bad, dips):
    frames = dips(40, 25.5)
    frames[3] = bad
    result = run(frames, method="dip_centroid")
    assert (result["reason"] == OK).all()
    np.testing.assert_allclose(result["shadow_time"], 25.5, atol=0.05)
    np.testing.assert_allclose(result["lit_level"], LEVEL, rtol=1e-6)


def test_a_minus_inf_sample_far_from_the_dip_is_ignored(dips):
    frames = dips(40, 25.5)
    frames[3] = -np.inf
    result = run(frames, method="dip_centroid")
    np.testing.assert_allclose(result["shadow_time"], 25.5, atol=0.05)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_corrupt_sample_inside_the_dip_is_flagged(bad, dips):
    frames = dips(40, 25.5)
    frames[25] = bad
    result = run(frames)
    check_invariants(result, 40)
    assert (result["reason"] != OK).all()


@settings(max_examples=30, deadline=None)
@given(n_frames=st.integers(4, 40), centre=st.floats(-3.0, 45.0), width=st.floats(0.5, 14.0),
       depth=st.floats(0.0, 1.0), noise=st.sampled_from([0.0, 1e-3, 0.05]),
       corrupt=st.lists(st.tuples(st.integers(0, 39), st.sampled_from([np.nan, np.inf, -np.inf,
                                                                       2.0, -1.0])),
                        max_size=4),
       half_window=st.integers(1, 6), method=st.sampled_from(METHODS), seed=st.integers(0, 99))
def test_detectors_never_crash_never_leave_the_sweep_and_say_why(
        n_frames, centre, width, depth, noise, corrupt, half_window, method, seed, dips):
    frames = dips(n_frames, centre, width=width, depth=depth, shape=(5, 5))
    frames += np.random.default_rng(seed).normal(0, noise, frames.shape)
    for frame, value in corrupt:
        if frame < n_frames:
            frames[frame, seed % 5] = value
    with np.errstate(all="ignore"):
        result = run(frames, method=method, half_window=half_window)
    check_invariants(result, n_frames)


# ------------------------------------------------------------------ very long sequences


def test_ten_thousand_frames_keep_running_statistics_exact():
    """10,000 frames at a high DC level (raw DN scale) with small noise: the lit level and
    the noise come out as accurately as the samples allow (float64 running sums)."""
    rng = np.random.default_rng(4)
    n, level, sigma = 10_000, 3000.0, 0.5
    frames = (level + rng.normal(0, sigma, (n, 3, 3))).astype(np.float32)
    frames[7001:7004] -= 2000.0  # dip centred on frame 7002
    tracker = DipTracker((3, 3), half_window=4)
    for start in range(0, n, 997):
        tracker.update(frames[start:start + 997])
    summary = tracker.result()
    assert summary.n_frames == n
    assert np.all(summary.minimum_frame == 7002)
    lit = np.delete(frames.astype(np.float64), np.s_[6998:7007], axis=0)
    np.testing.assert_allclose(summary.lit_level, lit.mean(axis=0), rtol=0, atol=1e-6)
    np.testing.assert_allclose(summary.noise, lit.std(axis=0, ddof=1), rtol=1e-3)
    result = run(frames / 4095.0, method="dip_centroid")
    np.testing.assert_allclose(result["shadow_time"], 7002.0, atol=0.01)


# ------------------------------------------------------------------ dual coordinates


def _plane_sweeps(angle_deg, n=20, step=0.05):
    """Plane points on a grid and the times of two sweeps crossing at `angle_deg`."""
    y, x = np.mgrid[0:n, 0:n] * step
    xy = np.column_stack([x.ravel(), y.ravel()])
    a = np.radians(angle_deg)
    t_u = xy @ np.array([1.0, 0.0]) / step * 0.8
    t_v = xy @ np.array([np.cos(a), np.sin(a)]) / step * 0.8
    return np.column_stack([t_u, t_v]), xy


@settings(max_examples=25, deadline=None)
@given(angle=st.floats(0.5, 90.0))
def test_nearly_parallel_sweeps_raise_and_crossing_sweeps_are_exact(angle):
    times, xy = _plane_sweeps(angle)
    if angle < 15.0:  # min_sweep_angle_deg: ill-conditioned, never silently wrong
        with pytest.raises(ValueError, match="parallel|collinear"):
            fit_time_to_plane(times, xy, models=("affine", "homography"))
    else:
        fit = fit_time_to_plane(times, xy, models=("affine", "homography"))
        np.testing.assert_allclose(fit.model(times), xy, atol=1e-6)


def test_uniform_model_refuses_parallel_time_maps():
    times, _ = _plane_sweeps(2.0)
    t_u, t_v = (times[:, i].reshape(20, 20) for i in (0, 1))
    with pytest.raises(ValueError, match="collinear|parallel"):
        dual_coords_uniform(t_u, t_v, n_frames=(32, 32))


@settings(max_examples=15, deadline=None)
@given(n=st.integers(0, 7))
def test_too_few_calibration_points_raise(n):
    times, xy = _plane_sweeps(90.0)
    with pytest.raises(ValueError, match="too few"):
        fit_time_to_plane(times[:n], xy[:n])


@settings(max_examples=15, deadline=None)
@given(n=st.integers(8, 60), jitter=st.floats(0.0, 1e-4), seed=st.integers(0, 99))
def test_collinear_calibration_points_raise(n, jitter, seed):
    rng = np.random.default_rng(seed)
    s = rng.uniform(0, 1, n)
    xy = np.column_stack([s, 2 * s + 0.1]) + rng.normal(0, jitter, (n, 2))
    times = np.column_stack([s * 30, rng.uniform(0, 30, n)])
    with pytest.raises(ValueError, match="collinear"):
        fit_time_to_plane(times, xy)


def test_calibration_from_a_single_row_of_plane_pixels_raises():
    rows, cols = 12, 16
    r, c = np.mgrid[0:rows, 0:cols].astype(np.float64)
    cal_t_u, cal_t_v = c * 1.5, r * 1.5
    mask = np.zeros((rows, cols), bool)
    mask[5] = True  # the plane is seen in one image row only: collinear plane points
    with pytest.raises(ValueError, match="collinear"):
        dual_coords_calibration(cal_t_u, cal_t_v, cal_t_u=cal_t_u, cal_t_v=cal_t_v,
                                homography=np.eye(3), dual_shape=(16, 16), plane_mask=mask)
