"""The virtual camera array (paper Fig. 6): wires assigned, coordinates and views against
the renderer's exact wire times and reciprocal views."""

import numpy as np
import pytest

from shadowcam.cameras.array import (
    MINIMA_COUNT, OK, UNEVEN_GAPS, array_accuracy, assign_wires, camera_array,
)
from shadowcam.synthetic.lab.light_motion import render_camera_array
from shadowcam.synthetic.lab.render import pixel_centre_ground_truth
from shadowcam.synthetic.lab.scenes import make_scene

SPACING = 6.0


def _dips(n_frames, centres, *, width=1.2, depth=0.8, shape=(2, 2)):
    """Exposure-integrated box shadows on a slowly brightening lit level (moving light)."""
    k = np.arange(n_frames, dtype=np.float64)
    level = 1.0 + 0.004 * k
    signal = level.copy()
    for c in centres:
        overlap = np.clip(np.minimum(k + 0.5, c + width / 2) - np.maximum(k - 0.5, c - width / 2), 0, 1)
        signal -= level * depth * overlap
    return np.broadcast_to(signal[:, None, None], (n_frames, *shape)).astype(np.float32).copy()


def test_even_dips_are_the_wires_in_order():
    times, reason, _ = assign_wires(_dips(50, [10.3, 18.9, 27.5]), 3, spacing_frames=SPACING)
    assert np.all(reason == OK)
    # centroid of sampled box dips: within 1 / (8 width) of the centres
    np.testing.assert_allclose(times[:, 0, 0], [10.3, 18.9, 27.5], atol=1 / (8 * 1.2) + 2e-3)


def test_streamed_blocks_give_the_wires_of_the_whole_stack():
    frames = _dips(50, [10.3, 18.9, 27.5], shape=(3, 4))
    frames[:, 1, 2] = _dips(50, [9.1, 17.0, 25.2])[:, 0, 0]
    whole, reason, _ = assign_wires(frames, 3, spacing_frames=SPACING)
    streamed, reason_streamed, minima = assign_wires(lambda: (frames[i:i + 7] for i in range(0, 50, 7)), 3,
                                                     spacing_frames=SPACING, shape=(3, 4))
    np.testing.assert_array_equal(streamed, whole)
    np.testing.assert_array_equal(reason_streamed, reason)
    assert minima.n_frames == 50
    with pytest.raises(ValueError, match="shape"):
        assign_wires(lambda: iter([frames]), 3, spacing_frames=SPACING)


def test_uneven_gaps_or_a_wrong_count_are_flagged():
    _, reason, _ = assign_wires(_dips(50, [10.0, 18.0, 30.0]), 3, spacing_frames=SPACING)
    assert np.all(reason == UNEVEN_GAPS)
    _, reason, _ = assign_wires(_dips(60, [10.0, 20.0, 30.0, 40.0]), 3, spacing_frames=SPACING)
    assert np.all(reason == MINIMA_COUNT)
    # a gap shorter than the wire spacing cannot be two wires (1 + g / d >= 1)
    _, reason, _ = assign_wires(_dips(50, [10.0, 14.0, 18.0]), 3, spacing_frames=SPACING)
    assert np.all(reason == UNEVEN_GAPS)


@pytest.mark.parametrize("centres, expected", [
    ([3.0, 11.0], [np.nan, 3.0, 11.0]),     # the first wire's dip before the sweep
    ([30.0, 38.0], [30.0, 38.0, np.nan]),   # the last wire's dip after it
])
def test_a_wire_outside_the_sweep_is_placed_when_only_one_side_fits(centres, expected):
    times, reason, _ = assign_wires(_dips(42, centres), 3, spacing_frames=SPACING)
    assert np.all(reason == OK)
    np.testing.assert_allclose(times[:, 0, 0], expected, atol=0.11)


def test_a_missing_wire_that_could_be_on_either_side_is_flagged():
    times, reason, _ = assign_wires(_dips(30, [5.0, 13.0]), 3, spacing_frames=SPACING)
    # 5 - 8 < 0 and 13 + 8 < 29: only "before" fits
    assert np.all(reason == OK)
    times, reason, _ = assign_wires(_dips(20, [5.0, 13.0]), 3, spacing_frames=SPACING)
    # 5 - 8 < 0 and 13 + 8 > 19: both fit
    assert np.all(reason == MINIMA_COUNT) and np.all(np.isnan(times))


@pytest.fixture(scope="module")
def scene():
    return make_scene("tabletop", height=32, width=32, frames=24)


@pytest.fixture(scope="module")
def capture(scene):
    return render_camera_array(scene, n_rows=2, n_cols=3, spacing_frames=SPACING, supersample=2)


@pytest.fixture(scope="module")
def array(capture):
    return camera_array(capture["frames_horizontal"].values, capture["frames_vertical"].values,
                        capture["crossing_images"].values, spacing_frames=SPACING)


def test_array_dataset_layout(array, capture):
    assert array["view"].dims == ("camera_row", "camera_col", "v", "u", "channel")
    assert array["view"].shape == (2, 3, capture.sizes["t_v"], capture.sizes["t_u"], 3)


def test_coordinates_rectification_disparity_and_views_against_the_renderer(scene, capture, array):
    gt = pixel_centre_ground_truth(scene.objects, scene.camera, scene.light, scene.mask, {})
    depth = (gt["P"] - scene.mask.origin) @ scene.mask.normal
    acc = array_accuracy(array, capture["t_vertical_wire"].values, capture["t_horizontal_wire"].values,
                         reciprocal=capture["reciprocal"].values, depth=depth,
                         disparity_per_inverse_depth=(SPACING, SPACING * scene.mask.focal))
    rmse = np.array(acc["coordinate_rmse"])
    assert rmse.shape == (2, 3) and np.all(rmse <= 0.3)
    # scene shadows that switch as the light moves are flagged, not timed
    assert np.all(np.array(acc["coverage"]) > 0.75)
    # rectified: a point's row (column) is the estimated time of the row's (column's) wire
    assert max(acc["v_rmse_per_row"]) <= 0.3 and max(acc["u_rmse_per_column"]) <= 0.3
    # neighbouring cameras' disparity follows s (1 + g / d)
    assert acc["disparity_rmse"] <= 0.3
    # the views against the reciprocal renders after one gain (holes and edges included)
    assert np.all(np.array(acc["view_rmse"]) < 0.3)
    # never a confident time more than a frame off
    for est, truth in ((array["u"].values, capture["t_vertical_wire"].values),
                       (array["v"].values, capture["t_horizontal_wire"].values)):
        err = np.abs(est - truth)
        assert np.mean(err[np.isfinite(err)] > 1.0) < 0.005
