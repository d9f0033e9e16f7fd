"""Cubic-convolution translation: exact integer moves, cut-independent bits, OpenCV's kernel."""

import numpy as np
import pytest

from shadowcam.outdoor.registration import block_mean
from shadowcam.outdoor.translation import cubic_weights, translate, translate_with_block_means
from shadowcam.outdoor.frame_kernels import normalise_smooth_minimum


@pytest.mark.parametrize("fraction", [0.0, 0.25, 0.5, 0.9])
def test_weights_preserve_constants_and_are_symmetric(fraction):
    weights = cubic_weights(fraction).astype(np.float64)
    assert weights.sum() == pytest.approx(1.0, abs=1e-7)
    if fraction:
        np.testing.assert_allclose(weights[::-1], cubic_weights(1 - fraction), atol=1e-7)
    else:
        assert list(weights) == [0, 1, 0, 0]  # interpolating: samples are kept


def test_integer_shifts_move_pixels_exactly_and_constants_stay():
    image = np.random.default_rng(1).random((30, 40), dtype=np.float32)
    moved = translate(image, (2.0, -3.0), method="cubic_Keys1981")
    assert np.array_equal(moved[:-2, 3:], image[2:, :-3])  # content at (r + 2, c - 3)
    flat = translate(np.full((20, 20), 0.375, np.float32), (0.4, -1.7), method="cubic_Keys1981")
    np.testing.assert_allclose(flat, 0.375, rtol=1e-6)
    assert moved.dtype == np.float32


def test_column_windows_give_the_same_bits_and_match_opencv():
    image = np.random.default_rng(0).random((48, 120), dtype=np.float32)
    shift = (-0.7, 2.35)
    whole = translate(image, shift, method="cubic_Keys1981")
    need = int(np.ceil(abs(shift[1]))) + 2
    for start, stop in ((0, 60), (7, 77), (33, 120)):
        window = translate(image[:, start:stop], shift, method="cubic_Keys1981")
        lo = 0 if start == 0 else need
        hi = stop - start if stop == 120 else stop - start - need
        assert np.array_equal(window[:, lo:hi], whole[:, start + lo:start + hi])
    np.testing.assert_allclose(whole, translate(image, shift, method="opencv_cubic"), atol=2e-5)  # same kernel, other rounding


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="image"):
        translate(np.zeros((4, 4, 3)), (0.5, 0.5), method="cubic_Keys1981")
    with pytest.raises(ValueError, match="shift"):
        translate(np.zeros((4, 4)), (np.nan, 0.5), method="cubic_Keys1981")


def test_every_method_moves_content_back_by_the_shift():
    from shadowcam.outdoor.translation import TRANSLATION_METHODS

    rows, cols = np.indices((24, 24), dtype=np.float64)
    image = np.sin(rows / 3.0) + np.cos(cols / 4.0)
    for method in TRANSLATION_METHODS:
        moved = translate(image.astype(np.float32), (1.0, -2.0), method=method)
        np.testing.assert_allclose(moved[4:18, 4:18], image[5:19, 2:16], atol=1e-5, err_msg=method)
    with pytest.raises(ValueError, match="method"):
        translate(image, (0.5, 0.5), method="lanczos")
    with pytest.raises(ValueError, match="shift"):
        translate(image, (0.5,), method="spline")


def _separable_cubic(image, shift):
    """Independent reference: each axis's four taps from an edge-padded copy, in float64."""
    out = image.astype(np.float64)
    for axis, offset in enumerate(shift):
        whole = int(np.floor(offset))
        weights = cubic_weights(offset - whole).astype(np.float64)
        index = np.clip(np.arange(out.shape[axis])[:, None] + whole - 1 + np.arange(4)[None, :], 0, out.shape[axis] - 1)
        taken = np.take(out, index, axis=axis)  # (..., n, 4, ...) along `axis`
        out = np.tensordot(taken, weights, axes=([axis + 1], [0]))
    return out


@pytest.mark.parametrize("shift", [(0.3, -1.7), (0.0, 2.25), (-3.4, 0.0), (5.5, -0.1)])
def test_translation_with_block_means_is_the_cubic_kernel_and_its_block_means(shift):
    image = np.random.default_rng(2).random((45, 62), dtype=np.float32)
    buffer = np.full(image.shape, np.nan, np.float32)
    moved, means = translate_with_block_means(image, shift, factor=4, out=buffer)
    assert moved is buffer and means.shape == (11, 15)
    np.testing.assert_allclose(moved, _separable_cubic(image, shift), rtol=0, atol=1e-6)
    np.testing.assert_allclose(means, block_mean(moved, 4), rtol=0, atol=1e-6)  # float64 sums, float32 mean
    assert np.array_equal(moved, translate(image, shift, method="cubic_Keys1981"))
    assert translate_with_block_means(image, shift, factor=None)[1] is None
    with pytest.raises(ValueError, match="out"):
        translate_with_block_means(image, shift, factor=4, out=image)


def test_the_running_minimum_of_the_smoothing_is_the_float32_formula():
    rng = np.random.default_rng(3)
    earlier, previous, current = (rng.random((9, 13), dtype=np.float32) for _ in range(3))
    minimum = rng.random((9, 13), dtype=np.float32)
    minimum[0, 0] = np.inf
    gain = np.float32(1.37)
    now = current / gain
    expected = np.minimum(minimum, earlier * np.float32(0.25) + previous * np.float32(0.5) + now * np.float32(0.25))
    normalise_smooth_minimum(current, gain, earlier, previous, minimum)
    assert np.array_equal(current, now) and np.array_equal(minimum, expected)
    before = minimum.copy()
    normalise_smooth_minimum(current, gain, None, None, minimum)  # no window yet: only the division
    assert np.array_equal(current, now / gain) and np.array_equal(minimum, before)
