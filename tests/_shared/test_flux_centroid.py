"""Flux centroid of a pixel's footprint: exact on linear images, never outside the footprint."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from shadowcam._shared.flux_centroid import flux_centroid_shift


def test_linear_irradiance_gives_the_exact_centroid_of_any_symmetric_footprint():
    # E = a + b col + c row: a footprint of second moment var has its flux centroid at
    # var * (c, b) / E(centre) exactly (the first moment of a linear weight)
    rows, cols = np.mgrid[0:6, 0:9].astype(float)
    irradiance = 2.0 + 0.1 * cols - 0.05 * rows
    shift, clipped = flux_centroid_shift(irradiance, footprint_variance=1.0 / 12.0)
    np.testing.assert_allclose(shift[..., 1], (0.1 / 12.0) / irradiance, rtol=1e-12)
    np.testing.assert_allclose(shift[..., 0], (-0.05 / 12.0) / irradiance, rtol=1e-12)
    assert not np.any(clipped)


def test_box_samples_centroid_matches_the_rendered_sub_samples():
    # s x s point samples of an exponential irradiance: the samples' flux centroid against
    # the first order from the pixel values (error of second order in the footprint, < 2 %)
    s, k = 4, 0.3
    offsets = (np.arange(s) + 0.5) / s - 0.5
    cols = np.arange(12.0)
    pixel = np.array([np.mean(np.exp(k * (c + offsets))) for c in cols])
    centroid = np.array([np.sum(offsets * np.exp(k * (c + offsets))) / np.sum(np.exp(k * (c + offsets)))
                         for c in cols])
    shift, _ = flux_centroid_shift(np.tile(pixel, (3, 1)), footprint_variance=(s * s - 1) / (12.0 * s * s))
    np.testing.assert_allclose(shift[1, 1:-1, 1], centroid[1:-1], rtol=0.02)
    assert np.all(shift[..., 0] == 0)


@settings(max_examples=60, deadline=None)
@given(gradient=st.floats(-50, 50), level=st.floats(0.01, 10), variance=st.floats(0, 0.5))
def test_shift_never_leaves_the_footprint_and_splits_the_first_order(gradient, level, variance):
    irradiance = np.maximum(level + gradient * np.arange(5.0)[None, :] * np.ones((3, 1)), 0.0)
    shift, clipped = flux_centroid_shift(irradiance, footprint_variance=variance)
    half_width = np.sqrt(3 * variance)
    assert np.all(np.abs(shift) <= half_width + 1e-12)
    usable = irradiance > 0
    first = variance * np.gradient(irradiance, axis=1) / np.where(usable, irradiance, 1.0)
    np.testing.assert_allclose((shift + clipped)[..., 1][usable], first[usable], rtol=1e-9, atol=1e-12)
    assert np.all(shift[~usable] == 0) and np.all(clipped[~usable] == 0)


@pytest.mark.parametrize("variance", [-0.1, np.nan, np.inf])
def test_bad_footprint_variance_names_the_parameter(variance):
    with pytest.raises(ValueError, match="footprint_variance"):
        flux_centroid_shift(np.ones((3, 3)), footprint_variance=variance)
