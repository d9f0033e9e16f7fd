"""Tests of the outdoor renderer's window: a strip or crop of a camera at its true resolution."""

import numpy as np
import pytest

from shadowcam.synthetic.lab.scene import camera_rays
from shadowcam.synthetic.outdoor.capture import render_outdoor_capture
from shadowcam.synthetic.outdoor.render import make_outdoor_scene, sample_grid, window_camera

OFF = {"auto_exposure": False, "shake_px": 0.0, "cloud": False, "irregular_timing": False, "dropped_frames": 0}


def test_a_window_pixel_sees_the_ray_of_the_same_pixel_of_the_whole_frame():
    camera = make_outdoor_scene(height=400, width=600).camera
    window = window_camera(camera, (120, 250, 40, 30))
    assert (window.height, window.width) == (40, 30)
    x, y = sample_grid(40, 30)
    origins, directions = camera_rays(window, x, y)
    whole_o, whole_d = camera_rays(camera, x + 250, y + 120)
    np.testing.assert_allclose(directions, whole_d, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(origins, whole_o)


@pytest.mark.parametrize("window", [(0, 0, 4000, 8), (-1, 0, 8, 8), (0, 590, 8, 16), (0, 0, 4, 8), (1, 2, 3)])
def test_a_window_outside_the_frame_or_too_small_is_refused_by_name(window):
    with pytest.raises(ValueError, match="window"):
        make_outdoor_scene(height=400, width=600, window=window)


def test_the_ground_truth_of_a_window_is_the_crop_of_the_whole_frame_ground_truth():
    kwargs = {"frames": 12, "supersample": 1, "seed": 3, "sun_diameter_deg": 0.53, **OFF}
    whole = render_outdoor_capture(make_outdoor_scene(seed=3, height=64, width=96), **kwargs)
    crop = render_outdoor_capture(make_outdoor_scene(seed=3, height=64, width=96, window=(8, 40, 56, 24)), **kwargs)
    for name in ("shadow_class", "arrival_time_s", "penumbra_start_time_s", "penumbra_end_time_s"):
        expected = whole.ground_truth[name].values[8:64, 40:64]
        np.testing.assert_allclose(crop.ground_truth[name].values, expected, rtol=0, atol=1e-6, equal_nan=True,
                                   err_msg=name)
    assert (crop.ground_truth["shadow_class"].values == 3).any()
    # the frames too (noise-free radiance; same samples, same sun)
    np.testing.assert_allclose(crop.frames, whole.frames[:, 8:64, 40:64], rtol=1e-5, atol=1e-6)
