"""Camera-specific checks: straight edges seen through thick glass are bent in the primal
view and straight in the estimated dual view; parallel edges stay parallel in the
orthographic camera; a third sweep lowers the dual-coordinate error on a noisy render."""

import numpy as np
import pytest

from shadowcam.cameras.accuracy import (
    line_direction_spread,
    redundancy_gain,
    sample_coordinates,
    straightness_primal_dual,
)
from shadowcam.cameras.models import camera_coords_from_shadow_time
from shadowcam.lab.accuracy import dual_coord_errors
from shadowcam.synthetic.lab.edges import square_edge_points
from shadowcam.synthetic.lab.scenes import scene_from_description

SWEEPS = [{"name": "u"}, {"name": "v", "angle_deg": 90},
          {"name": "w", "angle_deg": 45, "speed": 1.0}]


def test_sample_coordinates_is_bilinear_and_keeps_holes():
    v, u = np.mgrid[0:5, 0:6].astype(np.float64)
    u[2, 2] = np.nan
    got = sample_coordinates(2 * u + 1, v, np.array([[0.5, 0.25], [4.75, 3.5], [2.5, 1.5], [6.0, 1.0]]))
    np.testing.assert_allclose(got[:2], [[2.0, 0.25], [10.5, 3.5]])
    assert np.isnan(got[2]).all() and np.isnan(got[3]).all()


def test_glass_unwarped_by_the_dual_view():
    description = {"scene": "tabletop_squares", "seed": 0, "height": 64, "width": 64, "frames": 32,
                   "optics": {"kind": "glass", "shape": "sphere"}}
    from shadowcam.lab.shadow_time import shadow_time_dataset, sweep_shadow_times
    from shadowcam.synthetic.lab.render import prepare_capture

    scene = scene_from_description(description)
    capture = prepare_capture(scene, supersample=2, calibration=False)
    shadow_time = shadow_time_dataset({n: sweep_shadow_times([capture.frames(n)], (64, 64))
                                       for n in capture.sweep_names})
    coords = camera_coords_from_shadow_time(shadow_time, description)
    edges = square_edge_points(scene)
    ok = edges.lit & edges.through_optics & np.all((edges.dual_uv >= 0) & (edges.dual_uv <= 31), axis=1)
    found = straightness_primal_dual(coords["u"].values, coords["v"].values, edges.camera_xy[ok],
                                     edges.label[ok])
    assert found["n_edges"] >= 6
    assert found["primal_rms"] > 1.5 and found["dual_rms"] <= 0.5, found


def test_line_direction_spread():
    t = np.linspace(0, 1, 10)
    lines = [np.column_stack([t, 0.5 * t + k]) for k in range(3)]
    labels = np.repeat(np.arange(3), 10)
    assert line_direction_spread(np.concatenate(lines), labels) < 1e-9
    tilted = np.column_stack([t, -2 * t]) @ np.array([[1.0, 0.0], [0.0, 1.0]])
    spread = line_direction_spread(np.concatenate([lines[0], tilted]), np.repeat([0, 1], 10))
    assert abs(spread - (np.degrees(np.arctan(0.5)) + np.degrees(np.arctan(2.0)))) < 1e-9
    with pytest.raises(ValueError, match="two edges"):
        line_direction_spread(lines[0], np.zeros(10, int))


def test_third_sweep_lowers_the_dual_coordinate_error_on_a_noisy_render(timed_capture):
    description = {"scene": "tabletop", "seed": 3, "height": 40, "width": 40, "frames": 32,
                   "sweeps": SWEEPS}
    _, gt, shadow_time, _ = timed_capture(description, noise_std=0.02)
    truth = gt["t_u"].values, gt["t_v"].values
    two = camera_coords_from_shadow_time(shadow_time, {**description, "sweeps": SWEEPS[:2]})
    three = camera_coords_from_shadow_time(shadow_time, description)
    common = two["valid"].values & three["valid"].values
    e2 = dual_coord_errors(two["u"].values, two["v"].values, *truth, valid=common)
    e3 = dual_coord_errors(three["u"].values, three["v"].values, *truth, valid=common)
    assert redundancy_gain(e2, e3) > 1.05, (e2, e3)
