"""Tests of shadowcam.evaluate.render_consistency (the naive detector of the consistency benchmark)."""

import numpy as np
import pytest

from shadowcam.evaluate.render_consistency import naive_detection


def test_naive_detection_finds_the_first_halving():
    k = np.arange(30)[:, None, None]
    stack = np.where(k < np.array([[5, 12, 40]]), 1.0, 0.2) * (1.0 - 0.001 * k)
    np.testing.assert_array_equal(naive_detection(stack), [[5, 12, -1]])
    with pytest.raises(ValueError, match="stack"):
        naive_detection(np.zeros((3, 4)))
