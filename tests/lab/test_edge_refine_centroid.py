"""Edge refinement from the pixels' flux centroids to their centres, against exact truth."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from shadowcam._shared.flux_centroid import flux_centroid_shift
from shadowcam.lab.edge_refine import centre_times, refine_times


def _rendered(gradient, *, s=4, shape=(24, 30), period=12.0, amplitude=0.6):
    """A pixel's dip time from s x s point samples: the flux-weighted mean of their times.

    Lit image ``1 + amplitude sin(2 pi col / period) (1 + 0.3 cos(2 pi row / 15))``, time
    ``gradient . (row, col)`` frames (an open-shutter dip's centroid is that mean exactly).
    Returns the measured times, the lit levels, the centre truth and the footprint variance.
    """
    offsets = (np.arange(s) + 0.5) / s - 0.5
    rows, cols = np.mgrid[0:shape[0], 0:shape[1]].astype(float)
    r = rows[..., None, None] + offsets[:, None]
    c = cols[..., None, None] + offsets[None, :]
    lit = 1 + amplitude * np.sin(2 * np.pi * c / period) * (1 + 0.3 * np.cos(2 * np.pi * r / 15))
    time = gradient[0] * r + gradient[1] * c
    measured = np.sum(lit * time, axis=(-2, -1)) / np.sum(lit, axis=(-2, -1))
    truth = gradient[0] * rows + gradient[1] * cols
    return measured, lit.mean(axis=(-2, -1)), truth, (s * s - 1) / (12.0 * s * s)


def test_centroid_times_reach_the_centre_truth_in_a_magnified_region():
    # 4.5 frames per px along columns (the mirror's magnified region): the flux centroid is
    # up to 0.06 px off the centre, 0.27 frame; taken to the centre the error is the second
    # order of the footprint (< 0.02 frame)
    measured, lit, truth, variance = _rendered(np.array([0.7, 4.5]))
    inner = (slice(4, -4), slice(4, -4))
    plain, _ = refine_times(measured, np.full(measured.shape, 0.05))
    shift, clipped = flux_centroid_shift(lit, footprint_variance=variance)
    centred, std = refine_times(measured, np.full(measured.shape, 0.05), centroid_shift=shift,
                                shift_std=np.abs(clipped))
    assert np.max(np.abs(measured - truth)[inner]) > 0.2
    assert np.percentile(np.abs(plain - truth)[inner], 95) > 0.15
    assert np.max(np.abs(centred - truth)[inner]) < 0.02
    assert np.all(np.isfinite(std[inner]))


def test_centre_times_adds_the_correction_uncertainty():
    time = np.full((2, 3), 10.0)
    slope = np.zeros((2, 3, 2)) + [1.0, 4.0]
    slope_var = np.zeros((2, 3, 2)) + [0.01, 0.04]
    shift = np.zeros((2, 3, 2)) + [0.1, -0.05]
    shift_std = np.zeros((2, 3, 2)) + [0.0, 0.02]
    got, std = centre_times(time, np.full((2, 3), 0.1), slope, slope_var, shift, shift_std=shift_std)
    np.testing.assert_allclose(got, 10.0 - (0.1 - 0.2))
    want = np.sqrt(0.1**2 + 0.1**2 * 0.01 + 0.05**2 * 0.04 + 4.0**2 * 0.02**2)
    np.testing.assert_allclose(std, want)
    slope[0, 0] = np.nan  # an unknown gradient keeps the time
    got, _ = centre_times(time, np.full((2, 3), 0.1), slope, slope_var, shift)
    assert got[0, 0] == 10.0


@pytest.mark.parametrize("name", ["slope", "slope_var", "centroid_shift", "shift_std"])
def test_centre_times_names_a_mis_shaped_input(name):
    args = dict(slope=np.zeros((2, 3, 2)), slope_var=np.zeros((2, 3, 2)), centroid_shift=np.zeros((2, 3, 2)),
                shift_std=np.zeros((2, 3, 2)))
    args[name] = np.zeros((3, 2, 2))
    with pytest.raises(ValueError, match=name):
        centre_times(np.zeros((2, 3)), np.zeros((2, 3)), args["slope"], args["slope_var"], args["centroid_shift"],
                     shift_std=args["shift_std"])


@settings(max_examples=25, deadline=None)
@given(g_row=st.floats(-2, 2), g_col=st.floats(-2, 2), s=st.integers(2, 6))
def test_centring_never_does_worse_than_the_centroid_times(g_row, g_col, s):
    # time gradients up to 2 frames per px each axis and any point-sample footprint: the
    # centred refinement's error is within the second-order bound |g| * 0.01 px + 1e-6 frame,
    # and never above the uncorrected one's. (Steeper, with the isochrones along a pixel
    # axis, the plane's first pass keeps only the neighbours on the pixel's isochrone: no
    # slope, no correction; see docs/benchmarks.md.)
    measured, lit, truth, variance = _rendered(np.array([g_row, g_col]), s=s, shape=(20, 20))
    inner = (slice(4, -4), slice(4, -4))
    shift, clipped = flux_centroid_shift(lit, footprint_variance=variance)
    assert np.all(np.abs(shift) <= np.sqrt(3 * variance) + 1e-12)
    centred, _ = refine_times(measured, np.full(measured.shape, 0.05), centroid_shift=shift,
                              shift_std=np.abs(clipped))
    bound = 0.01 * np.hypot(g_row, g_col) + 1e-6
    assert np.max(np.abs(centred - truth)[inner]) <= bound
    assert np.max(np.abs(centred - truth)[inner]) <= np.max(np.abs(measured - truth)[inner]) + 1e-9
