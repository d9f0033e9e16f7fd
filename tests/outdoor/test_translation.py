"""Cubic-convolution translation: exact integer moves, cut-independent bits, OpenCV's kernel."""

import numpy as np
import pytest

from shadowcam.outdoor.translation import cubic_weights, translate


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
