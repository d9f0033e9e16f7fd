"""Tests of shadowcam.lab.planning (paper Eq. 3) against rendered captures.

A fronto-parallel plane at depth D, a pinhole camera and a point light beside it, a
wire sweeping at distance h from the light. The planner's r (dual pixels per camera
pixel = frames the shadow needs per camera pixel) is compared with the gradient of the
shadow times that the pipeline measures in the render, and its recommended mask speed
is rendered to check the dual resolution it promises.

The renderer's camera is an ideal pinhole (image plane at f) while Eq. 3 uses the thin-lens
image distance f D / (D - f): they differ by f / D, 0.8 % for the 4 mm lens and 0.5 depth
used here; the tolerance, 3 %, covers it and the estimation error of the times.
"""

import math

import numpy as np
import pytest

from shadowcam.cli import main
from shadowcam.synthetic.lab.render import prepare_capture
from shadowcam.lab.planning import dual_resolution_ratio, mask_speed_for_ratio, plan_capture
from shadowcam.synthetic.lab.scene import (
    BackPlane, Material, PointLight, look_at_camera, make_mask_plane, make_wire_sweeps,
)
from shadowcam.synthetic.lab.scenes import Scene
from shadowcam.lab.shadow_time import sweep_shadow_times

SIZE = 64
DEPTH = 0.5          # camera to plane (scene units = metres)
H = 0.05             # light to mask
FOCAL = 0.004        # physical focal length of the camera (its pixel width follows)
FOV_DEG = 40.0
FRAME_TIME = 0.1     # s per frame


def _camera():
    return look_at_camera((0.0, 0.0, 0.0), (0.0, 0.0, -DEPTH), fov_x_deg=FOV_DEG,
                          width=SIZE, height=SIZE)


def _pixel_width():
    return FOCAL / _camera().K[0, 0]  # W = f / f_pixels


def _measured_frames_per_pixel(step, frames):
    """Render a sweep with mask step `step` per frame; |grad t_u| (frames per pixel) from
    the pipeline's shadow times by a least-squares plane fit, and the swept columns."""
    camera = _camera()
    plane = BackPlane((0.0, 0.0, -DEPTH), 1.0, 0.6, 0.0, Material(albedo=(0.7, 0.7, 0.7)))
    light = PointLight((0.02, 0.01, 0.0))
    fov = 2 * math.degrees(math.atan(frames * step / (2 * H)))
    mask = make_mask_plane(light, target=(0.0, 0.0, -DEPTH), frames=frames, f=H, fov_deg=fov)
    assert mask.delta == pytest.approx(step)
    scene = Scene("plane", (plane,), light, camera, mask, make_wire_sweeps(mask))
    capture = prepare_capture(scene, supersample=2, calibration=False)
    result = sweep_shadow_times([capture.frames("u")], (SIZE, SIZE))
    t = result["shadow_time"].astype(np.float64)
    rows, cols = np.nonzero(np.isfinite(t))
    assert len(rows) > 0.9 * SIZE * SIZE
    design = np.column_stack([np.ones(len(rows)), cols, rows])
    coef, *_ = np.linalg.lstsq(design, t[rows, cols], rcond=None)
    return float(np.hypot(coef[1], coef[2]))


def test_eq3_predicts_the_measured_frames_per_pixel():
    step = 9.5e-4  # mask moves 0.95 mm per frame
    speed = step / FRAME_TIME
    predicted = dual_resolution_ratio(pixel_width=_pixel_width(), mask_distance=H, depth=DEPTH,
                                      focal_length=FOCAL, mask_speed=speed,
                                      frame_time=FRAME_TIME)
    measured = _measured_frames_per_pixel(step, 48)
    assert 0.5 < predicted < 0.7
    assert measured == pytest.approx(predicted, rel=0.03)


def test_recommended_speed_gives_the_wanted_dual_resolution():
    plan = plan_capture(pixel_width=_pixel_width(), mask_distance=H, depth=DEPTH,
                        focal_length=FOCAL, frame_time=FRAME_TIME, image_pixels=SIZE,
                        wanted_dual_pixels=40)
    step = plan["mask_step_per_frame"]
    measured = _measured_frames_per_pixel(step, 52)
    # the shadow crosses the 64 camera pixels in 40 frames = 40 dual pixels
    assert measured * SIZE == pytest.approx(40, rel=0.03)


def test_eq3_and_its_inverse_agree_and_scale():
    geometry = dict(pixel_width=5e-6, mask_distance=0.3, depth=2.0, focal_length=0.035,
                    frame_time=0.04)
    r = dual_resolution_ratio(mask_speed=0.002, **geometry)
    assert r == pytest.approx(5e-6 * 0.3 * (2.0 - 0.035) / (0.035 * 2.0 * 0.002 * 0.04))
    assert mask_speed_for_ratio(r, **geometry) == pytest.approx(0.002)
    # twice the speed, half the resolution; a farther mask, more resolution
    assert dual_resolution_ratio(mask_speed=0.004, **geometry) == pytest.approx(r / 2)
    plan = plan_capture(image_pixels=1000, mask_speed=0.002, **geometry)
    assert plan["dual_pixels"] == pytest.approx(1000 * r) and plan["exceeds_camera"] == (r > 1)


@pytest.mark.parametrize("bad", [dict(depth=0.01), dict(pixel_width=0.0),
                                 dict(frame_time=float("nan")), dict(mask_speed=-1.0)])
def test_invalid_geometry_raises_naming_the_parameter(bad):
    geometry = dict(pixel_width=5e-6, mask_distance=0.3, depth=2.0, focal_length=0.035,
                    frame_time=0.04, mask_speed=0.002)
    geometry.update(bad)
    with pytest.raises(ValueError, match=next(iter(bad))):
        dual_resolution_ratio(**geometry)


def test_plan_cli_prints_the_numbers(capsys):
    code = main(["plan", "--pixel-width", "5e-6", "--mask-distance", "0.3", "--depth", "2",
                 "--focal-length", "0.035", "--frame-time", "0.04", "--image-pixels", "1000",
                 "--mask-speed", "0.002", "--wanted-dual-pixels", "250"])
    out = capsys.readouterr().out
    assert code == 0
    r = dual_resolution_ratio(pixel_width=5e-6, mask_distance=0.3, depth=2.0,
                              focal_length=0.035, mask_speed=0.002, frame_time=0.04)
    assert f"r = {r:.4g}" in out and "recommended mask speed" in out
