"""Registration: sub-pixel translations recovered, the moving shadow edge masked out, large
shifts recovered coarse to fine."""

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from shadowcam.outdoor.translation import translate
from shadowcam.outdoor.registration import (bandpass_log, pyramid_levels, shift_coarse_to_fine,
                                    shift_lucas_kanade_LucasKanade1981, static_weight)


def _texture(seed=0, shape=(64, 80)):
    rng = np.random.default_rng(seed)
    noise = rng.random(shape).astype(np.float32)
    return 0.2 + cv2.GaussianBlur(noise, (0, 0), 1.5) * 2


@pytest.mark.parametrize("shift", [(0.3, -0.45), (-0.8, 0.6), (0.05, 0.0)])
def test_recovers_known_subpixel_shift(shift):
    ref = _texture()
    frame = translate(ref, (-shift[0], -shift[1]), method="opencv_cubic")  # content moves by +shift
    estimate, residual = shift_lucas_kanade_LucasKanade1981(frame, ref)
    np.testing.assert_allclose(estimate, shift, atol=0.02)
    assert residual < 0.05


def test_apply_shift_keeps_dtype_and_zero_shift_is_identity():
    ref = _texture()
    assert translate(ref, (0.3, 0.2), method="opencv_cubic").dtype == np.float32
    np.testing.assert_array_equal(translate(ref, (0, 0), method="opencv_cubic"), ref)
    with pytest.raises(ValueError, match="image"):
        translate(np.ones(5), (0, 0), method="opencv_cubic")


def test_moving_shadow_is_masked_and_does_not_bias_the_shift():
    ref = _texture(1)
    lit = np.ones_like(ref, bool)
    ref_lit = ref.copy()
    ref_lit[40:] *= 0.1  # shadow in the reference below row 40
    frame = ref.copy()
    frame[25:] *= 0.1  # the shadow climbed 15 rows
    true = (0.4, -0.3)
    frame = translate(frame * 1.3, (-true[0], -true[1]), method="opencv_cubic")
    lit_ref = np.zeros_like(lit)
    lit_ref[:40] = True
    weight = static_weight(frame, ref_lit, lit_reference=lit_ref, gain=1.3)
    assert weight[30:40].sum() == 0  # newly shadowed rows excluded
    assert weight[10:15, 10:70].all()
    estimate, _ = shift_lucas_kanade_LucasKanade1981(frame, ref_lit, weight=weight)
    np.testing.assert_allclose(estimate, true, atol=0.08)  # residual: band-pass tail of the old edge
    unmasked, _ = shift_lucas_kanade_LucasKanade1981(frame, ref_lit)
    assert np.abs(unmasked - true).max() > 3 * np.abs(estimate - true).max()


def test_bandpass_removes_gain():
    ref = _texture(2)
    np.testing.assert_allclose(bandpass_log(ref * 3.0), bandpass_log(ref), atol=0.02)


@settings(max_examples=25, deadline=None)
@given(shift=st.tuples(st.floats(-2.5, 2.5), st.floats(-2.5, 2.5)), seed=st.integers(0, 3))
def test_bandpass_commutes_with_the_resampling(shift, seed):
    # the search resamples the band-passed frame: both are convolutions, so away from the borders
    # (the outer Gaussian's 12-pixel reach, the shift and the cubic's 2 pixels) the band-pass of
    # the resampled log luminance is the resampled band-pass
    luma = _texture(seed, shape=(72, 88))
    moved_log = translate(np.log(luma), shift, method="opencv_cubic")
    direct = bandpass_log(np.exp(moved_log))
    resampled = translate(bandpass_log(luma), shift, method="opencv_cubic")
    inner = np.s_[18:-18, 18:-18]
    np.testing.assert_allclose(resampled[inner], direct[inner], atol=1e-5)  # signal std ~0.03


def _multiscale_texture(shape=(256, 320), seed=3):
    """Texture with power at every scale (like terrain), so that every pyramid level has detail."""
    rng = np.random.default_rng(seed)
    tex = np.zeros(shape, np.float32)
    for sigma in (1, 2, 4, 8, 16):
        tex += cv2.GaussianBlur(rng.random(shape).astype(np.float32), (0, 0), sigma) * np.float32(sigma ** 0.5)
    return 0.3 + tex / tex.max()


@pytest.mark.parametrize("shift", [(9.3, -11.6), (-7.25, 6.8)])
def test_coarse_to_fine_recovers_a_shift_beyond_one_level(shift):
    ref = _multiscale_texture()
    frame = translate(ref, (-shift[0], -shift[1]), method="opencv_cubic")  # content moves by +shift
    single, single_residual = shift_lucas_kanade_LucasKanade1981(frame, ref)
    assert not np.isfinite(single_residual) or np.abs(single - shift).max() > 1  # one level: out of range
    estimate, residual = shift_coarse_to_fine(frame, ref, levels=2)
    np.testing.assert_allclose(estimate, shift, atol=0.02)  # pixels, exact shift known
    assert residual < 0.05


def test_coarse_to_fine_keeps_the_single_level_solution_for_small_shifts():
    ref = _multiscale_texture(seed=4)
    shift = (0.4, -0.7)
    frame = translate(ref, (-shift[0], -shift[1]), method="opencv_cubic")
    weight = np.zeros(ref.shape, np.float32)
    weight[8:-8, 8:-8] = 1
    single = shift_lucas_kanade_LucasKanade1981(frame, ref, weight=weight)
    pyramid = shift_coarse_to_fine(frame, ref, weight=weight, levels=2)
    np.testing.assert_array_equal(pyramid[0], single[0])  # same search from the same start
    np.testing.assert_allclose(pyramid[0], shift, atol=0.02)


def test_pyramid_levels_stop_at_the_minimum_size():
    assert pyramid_levels((1000, 1500), levels=2) == 2
    assert pyramid_levels((128, 192), levels=2) == 1  # 64 rows is the smallest level
    assert pyramid_levels((100, 100), levels=3) == 0
    with pytest.raises(ValueError, match="levels"):
        pyramid_levels((100, 100), levels=-1)
    with pytest.raises(ValueError, match="weight"):
        shift_coarse_to_fine(np.ones((80, 80)), np.ones((80, 80)), weight=np.ones((8, 8)))


def _penumbra_frame(ref, *, top_row, width_px, shadow=0.15, noise=0.01, seed=5):
    """`ref` with a shadow below `top_row` whose soft edge is a disc sun's penumbra `width_px`
    rows wide (lit fraction of a uniform disc), times gain 1.3, with multiplicative noise."""
    from shadowcam.synthetic.outdoor.render import disc_fraction_above

    rows = np.arange(ref.shape[0])[:, None] + 0.5
    lit_fraction = disc_fraction_above((top_row - rows) / (0.5 * width_px))
    rng = np.random.default_rng(seed)
    frame = ref * (shadow + (1 - shadow) * lit_fraction) * 1.3
    return (frame * (1 + noise * rng.standard_normal(ref.shape))).astype(np.float32)


@pytest.mark.parametrize("width_px", [4.0, 10.0, 16.0])
def test_soft_shadow_measures_the_penumbra_width(width_px):
    from shadowcam.outdoor.registration import soft_shadow

    ref = _multiscale_texture()
    frame = _penumbra_frame(ref, top_row=120.0, width_px=width_px)
    lit = np.ones(ref.shape, bool)
    shadow, width = soft_shadow(frame, ref, lit_reference=lit, gain=1.3)
    # ratio from 0.15 (core below 0.5) to 1 within noise: the core starts where the disc
    # fraction is (0.5 - 0.15) / 0.85 = 0.41, the soft band ends within 3 sigma of 1
    assert width == pytest.approx(width_px * 0.5 * (1 - 0.14), abs=1.5)
    assert shadow[int(120 + width_px / 2) + 1:].all()
    assert not shadow[:int(120 - width_px / 2) - 2].any()


@pytest.mark.parametrize("width_px", [6.0, 14.0])
def test_soft_edge_does_not_bias_the_shift(width_px):
    ref = _multiscale_texture()
    true = (0.4, -0.3)
    frame = _penumbra_frame(ref, top_row=110.0, width_px=width_px, noise=0.002)
    frame = translate(frame, (-true[0], -true[1]), method="opencv_cubic")
    lit = np.ones(ref.shape, bool)
    weight = static_weight(frame, ref, lit_reference=lit, gain=1.3)
    assert weight[110 - int(width_px / 2) - 5:].sum() == 0  # penumbra + band-pass reach out
    estimate, _ = shift_lucas_kanade_LucasKanade1981(frame, ref, weight=weight)
    np.testing.assert_allclose(estimate, true, atol=0.03)


@pytest.mark.parametrize("moved", [(3, -5), (-7, 2), (11, 4), (-4, -13)])
def test_recovers_an_area_sampled_shift(moved):
    """Frames integrated over their pixels from one fine texture moved by whole fine pixels
    (1/8 of a frame pixel): the shift is exact, not made by the estimator's own interpolation."""
    fine, rows, cols = 8, 96, 128
    rng = np.random.default_rng(3)
    texture = cv2.resize(rng.random((rows * 2 + 8, cols * 2 + 8)).astype(np.float32),
                         ((cols + 4) * fine, (rows + 4) * fine), interpolation=cv2.INTER_CUBIC)
    texture = np.maximum(cv2.GaussianBlur(texture, (0, 0), fine * 0.5) + 0.2, 0.05)

    def frame(d_row, d_col):
        crop = texture[2 * fine - d_row:2 * fine - d_row + rows * fine, 2 * fine - d_col:2 * fine - d_col + cols * fine]
        return cv2.resize(crop, (cols, rows), interpolation=cv2.INTER_AREA)

    estimate, _ = shift_coarse_to_fine(frame(*moved) * 1.2, frame(0, 0), levels=1)
    np.testing.assert_allclose(estimate, np.divide(moved, fine), atol=0.02)


def test_a_prepared_reference_gives_the_same_shift_bit_for_bit():
    from shadowcam.outdoor.registration import reference_levels, shift_coarse_to_fine

    rng = np.random.default_rng(4)
    ref = (rng.random((300, 400)) * 0.5 + 0.3).astype(np.float32)
    ref = translate(ref, (0.3, 0.3), method="spline")  # some spatial correlation
    frame = translate(ref, (-1.4, 2.2), method="opencv_cubic")  # content moves by (1.4, -2.2)
    prepared = reference_levels(ref, levels=2)
    assert [level["luma"].shape for level in prepared] == [(300, 400), (150, 200), (75, 100)]
    alone = shift_coarse_to_fine(frame, ref, levels=2)
    shared = shift_coarse_to_fine(frame, ref, levels=2, prepared=prepared)
    assert np.array_equal(alone[0], shared[0]) and alone[1] == shared[1]
    np.testing.assert_allclose(shared[0], (1.4, -2.2), atol=0.05)
    with pytest.raises(ValueError, match="levels"):
        shift_coarse_to_fine(frame, ref, levels=2, prepared=prepared[:2])
