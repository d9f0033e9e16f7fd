"""Tests of shadowcam.synthetic.lab.sweeps: general sweeps (Fig. 12) and their exact ground truth.

Geometric facts: the standard pair is reproduced bit for bit, a slanted or slower sweep's time
is the documented affine function of the dual coordinates, the analytic time re-projects onto
the point's mask-plane crossing, degenerate geometry raises a ValueError naming the parameter.
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from shadowcam.synthetic.lab.render import pixel_centre_ground_truth, prepare_capture
from shadowcam.synthetic.lab.scene import make_wire_sweeps, wire_shadow_time
from shadowcam.synthetic.lab.scenes import make_scene
from shadowcam.synthetic.lab.sweeps import (
    dual_affine,
    make_sweeps,
    shadow_crossing,
    true_dual_coordinates,
    wire_position,
)

H = W = 32
T = 24


@pytest.fixture(scope="module")
def scene():
    return make_scene("tabletop", seed=3, height=H, width=W, frames=T)


@pytest.fixture(scope="module")
def points(scene):
    """World points of the camera's pixel centres that a ray hits, (N, 3)."""
    gt = pixel_centre_ground_truth(scene.objects, scene.camera, scene.light, scene.mask,
                                   scene.sweeps)
    return gt["P"][gt["hit"]]


def test_standard_specs_reproduce_make_wire_sweeps(scene):
    general = make_sweeps(scene.mask, [{"name": "u"}, {"name": "v", "angle_deg": 90}],
                          light=scene.light)
    standard = make_wire_sweeps(scene.mask)
    for name in "uv":
        assert np.array_equal(general[name].p0, standard[name].p0)
        assert np.array_equal(general[name].velocity, standard[name].velocity)
        assert general[name].frames == standard[name].frames
        assert general[name].light is scene.light
    assert np.array_equal(general["u"].direction, standard["u"].direction)
    # a wire is a line: the v wire's direction is the standard one reversed
    assert np.array_equal(general["v"].direction, -standard["v"].direction)


def test_default_scene_has_standard_sweeps_without_own_light(scene):
    assert scene.dual_sweeps is None
    assert all(s.light is None for s in scene.sweeps.values())


def test_explicit_standard_pair_renders_the_default_frames(scene):
    """Sweeps declared by specs render exactly the default capture's frames."""
    default = prepare_capture(scene, supersample=2, calibration=False)
    declared = prepare_capture(
        make_scene("tabletop", seed=3, height=H, width=W, frames=T,
                   sweeps=[{"name": "u"}, {"name": "v", "angle_deg": 90}]),
        supersample=2, calibration=False)
    for name in "uv":
        assert np.array_equal(default.frames(name), declared.frames(name))
        assert np.array_equal(default.ground_truth[f"t_{name}"].values,
                              declared.ground_truth[f"t_{name}"].values, equal_nan=True)
    # the virtual camera of the standard pair is the dual camera: same reciprocal render
    np.testing.assert_allclose(declared.ground_truth.reciprocal.values,
                               default.ground_truth.reciprocal.values, rtol=1e-4, atol=1e-7)


@pytest.mark.parametrize("angle_deg, speed", [(30.0, 1.5), (-60.0, 1.0), (90.0, 0.5),
                                              (10.0, 3.0)])
def test_slanted_sweep_time_is_affine_in_dual_coordinates(scene, points, angle_deg, speed):
    """t_w = (cos th (u - c_u) + sin th (v - c_v)) / speed + (T_w - 1)/2 (dual_affine)."""
    sweeps = make_sweeps(scene.mask, [{"name": "u"}, {"name": "v", "angle_deg": 90},
                                      {"name": "w", "angle_deg": angle_deg, "speed": speed}],
                         light=scene.light)
    uvw = np.stack([wire_shadow_time(points, sweeps[n]) for n in "uvw"], axis=-1)
    assert np.all(np.isfinite(uvw))
    coef = dual_affine(scene.mask, sweeps["w"])
    th = math.radians(angle_deg)
    c = (T - 1) / 2
    expected = np.array([math.cos(th) / speed, math.sin(th) / speed,
                         (sweeps["w"].frames - 1) / 2 - (math.cos(th) + math.sin(th)) * c / speed])
    np.testing.assert_allclose(coef, expected, rtol=0, atol=1e-12)
    predicted = uvw[:, 0] * coef[0] + uvw[:, 1] * coef[1] + coef[2]
    np.testing.assert_allclose(predicted, uvw[:, 2], rtol=0, atol=1e-9)
    # the virtual image (t_u, t_w) is the affine image of (u, v): skew = its 2x2 part
    virtual = true_dual_coordinates(points, sweeps, ("u", "w"))
    A = np.array([dual_affine(scene.mask, sweeps["u"]), coef])
    np.testing.assert_allclose(virtual, uvw[:, :2] @ A[:, :2].T + A[:, 2], atol=1e-9)


def test_standard_sweeps_are_the_dual_coordinates(scene):
    for name, row in (("u", [1, 0, 0]), ("v", [0, 1, 0])):
        sweep = make_sweeps(scene.mask, [{"name": name, "angle_deg": 0 if name == "u" else 90}],
                            light=scene.light)[name]
        np.testing.assert_allclose(dual_affine(scene.mask, sweep), row, atol=1e-12)


def test_sweep_in_a_parallel_plane_is_still_affine(scene, points):
    """A parallel wire plane at distance f + h from the light scales (u, v) by (f + h) / f."""
    h = 0.01
    sweep = make_sweeps(scene.mask, [{"name": "w", "plane_offset": h}], light=scene.light)["w"]
    u = wire_shadow_time(points, scene.sweeps["u"], scene.light)
    coef = dual_affine(scene.mask, sweep)
    assert coef[0] == pytest.approx((scene.mask.focal + h) / scene.mask.focal, rel=1e-12)
    np.testing.assert_allclose(coef[0] * u + coef[2], wire_shadow_time(points, sweep),
                               atol=1e-9)


def test_time_under_another_light_is_not_affine(scene):
    sweep = make_sweeps(scene.mask, [{"name": "w", "light_offset": [0.01, 0.0, 0.0]}],
                        light=scene.light)["w"]
    with pytest.raises(ValueError, match="light"):
        dual_affine(scene.mask, sweep)


def test_slanted_sweep_frames_dip_at_the_analytic_time():
    """README 1.9 check on a slanted, faster third sweep: argmin within 1 frame on >= 99%."""
    sc = make_scene("tabletop", seed=3, height=H, width=W, frames=T,
                    sweeps=[{"name": "u"}, {"name": "v", "angle_deg": 90},
                            {"name": "w", "angle_deg": 35, "speed": 1.25}])
    cap = prepare_capture(sc, supersample=3, calibration=False)
    assert cap.sweep_names == ("u", "v", "w")
    t = cap.ground_truth["t_w"].values
    intensity = cap.frames("w").sum(-1)
    hi, lo = intensity.max(0), intensity.min(0)
    good = (np.isfinite(t) & ((hi - lo) / np.maximum(hi, 1e-30) >= 0.5)
            & (hi >= 0.05 * np.percentile(hi, 99)))
    assert good.sum() >= 0.9 * np.isfinite(t).sum()
    assert (np.abs(intensity.argmin(0) - t)[good] <= 1).mean() >= 0.99


# ----------------------------------------------------------------------- degenerate geometry


def test_motion_parallel_to_the_wire_is_rejected(scene):
    with pytest.raises(ValueError, match="motion_deg"):
        make_sweeps(scene.mask, [{"name": "w", "angle_deg": 30, "motion_deg": 120 + 1e-8}],
                    light=scene.light)


def test_light_in_the_wire_plane_is_rejected(scene):
    f = scene.mask.focal
    with pytest.raises(ValueError, match="light"):
        make_sweeps(scene.mask, [{"name": "w", "light_offset": [0.0, 0.0, f * (1 + 1e-9)]}],
                    light=scene.light)
    distant = make_scene("tabletop", seed=3, height=H, width=W, frames=T, light_kind="distant")
    grazing = np.cross(distant.mask.normal, distant.mask.e_u) + 1e-9 * distant.mask.normal
    with pytest.raises(ValueError, match="light"):
        make_sweeps(distant.mask, [{"name": "w", "light_direction": grazing}],
                    light=distant.light)


@pytest.mark.parametrize("spec, key", [
    ({"name": "w", "speed": 0}, "speed"),
    ({"name": "w", "speed": 1, "speed_scene": 1e-3}, "speed_scene"),
    ({"name": "w", "frames": 1}, "frames"),
    ({"name": "w", "angle": 3}, "unknown"),
    ({"name": "cal_w"}, "name"),
    ({"name": "w", "angle_deg": float("nan")}, "angle_deg"),
])
def test_bad_specs_name_the_parameter(scene, spec, key):
    with pytest.raises(ValueError, match=key):
        make_sweeps(scene.mask, [spec], light=scene.light)


# ----------------------------------------------------------------------- stability (hypothesis)

angles = st.one_of(st.floats(-180, 180), st.sampled_from([0.0, 1e-7, 89.9999999, 90.0,
                                                          -90.0, 45.0]))


@settings(max_examples=60, deadline=None)
@given(angle=angles,
       log_speed=st.floats(-1.0, 1.0),
       oblique=st.floats(-89.0, 89.0),
       plane_offset=st.floats(-0.02, 0.03),
       light_offset=st.tuples(st.floats(-0.02, 0.02), st.floats(-0.02, 0.02),
                              st.floats(-0.02, 0.02)))
def test_times_reproject_onto_the_mask_plane_crossing(scene, points, angle, log_speed, oblique,
                                                      plane_offset, light_offset):
    """Speeds over 100x, slants near 0/90 deg, oblique motion, offset planes and lights: the
    time is finite and the wire at that time passes through the point's crossing (1e-9 rel)."""
    sweep = make_sweeps(scene.mask, [{"name": "w", "angle_deg": angle,
                                      "motion_deg": angle + oblique,
                                      "speed": 10.0 ** log_speed,
                                      "plane_offset": plane_offset,
                                      "light_offset": list(light_offset)}],
                        light=scene.light)["w"]
    t = wire_shadow_time(points, sweep)
    assert np.all(np.isfinite(t))
    crossing = shadow_crossing(points, sweep)
    across = sweep.velocity / np.linalg.norm(sweep.velocity)
    miss = (crossing - wire_position(sweep, t)) @ across
    scale = np.linalg.norm(crossing - scene.mask.origin, axis=1) + scene.mask.n_u * scene.mask.delta
    assert np.all(np.abs(miss) <= 1e-9 * scale)


@settings(max_examples=40, deadline=None)
@given(angle=st.floats(-180, 180), log_speed=st.floats(-1.0, 1.0))
def test_distant_light_times_reproject(angle, log_speed):
    sc = make_scene("tabletop", seed=3, height=8, width=8, frames=T, light_kind="distant")
    sweep = make_sweeps(sc.mask, [{"name": "w", "angle_deg": angle, "speed": 10.0 ** log_speed}],
                        light=sc.light)["w"]
    pts = np.random.default_rng(0).uniform(-0.1, 0.1, size=(200, 3))
    t = wire_shadow_time(pts, sweep)
    assert np.all(np.isfinite(t))
    miss = (shadow_crossing(pts, sweep) - wire_position(sweep, t)) @ (
        sweep.velocity / np.linalg.norm(sweep.velocity))
    assert np.all(np.abs(miss) <= 1e-9 * (1 + np.abs(t) * np.linalg.norm(sweep.velocity)))
    coef = dual_affine(sc.mask, sweep)
    assert np.all(np.isfinite(coef))


def test_scene_from_description_selects_the_variants():
    from shadowcam.synthetic.lab.scene import OrthographicCamera
    from shadowcam.synthetic.lab.scenes import scene_from_description

    plain = scene_from_description({"scene": "tabletop", "seed": 3, "height": H, "width": W,
                                    "frames": T, "format": "tiff", "noise": False})
    default = make_scene("tabletop", seed=3, height=H, width=W, frames=T)
    assert plain.dual_sweeps is None and plain.sweeps.keys() == default.sweeps.keys()
    for name in "uv":
        assert np.array_equal(plain.sweeps[name].p0, default.sweeps[name].p0)
    varied = scene_from_description({
        "scene": "tabletop", "seed": 3, "height": H, "width": W, "frames": T,
        "light": "distant", "camera": "orthographic",
        "sweeps": [{"name": "u"}, {"name": "v", "angle_deg": 90, "speed": 0.5},
                   {"name": "w", "angle_deg": 30}],
        "dual_sweeps": ["u", "w"]})
    assert isinstance(varied.camera, OrthographicCamera)
    assert varied.dual_sweeps == ("u", "w")
    assert varied.sweeps["v"].frames == 2 * T  # half speed: twice the frames
    assert all(s.light is varied.light for s in varied.sweeps.values())
    with pytest.raises(ValueError, match="dual_sweeps"):
        make_scene("tabletop", height=8, width=8, sweeps=[{"name": "u"}], dual_sweeps=("u", "x"))
    with pytest.raises(ValueError, match="camera_kind"):
        scene_from_description({"scene": "tabletop", "camera": "fisheye"})


def test_single_sweep_capture_uses_the_standard_dual_camera():
    """A lone (pushbroom) sweep under its own light renders and is timed under that light."""
    sc = make_scene("tabletop", seed=3, height=16, width=16, frames=T,
                    sweeps=[{"name": "p", "angle_deg": 10, "light_offset": [0.005, 0, 0]}])
    assert sc.dual_sweeps is None
    cap = prepare_capture(sc, supersample=1, calibration=False)
    assert cap.sweep_names == ("p",)
    gt = cap.ground_truth
    lit = gt["lit_p"].values
    t = wire_shadow_time(gt["P"].values[lit].astype(np.float64), sc.sweeps["p"])
    np.testing.assert_allclose(gt["t_p_all"].values[lit], t, rtol=1e-6, atol=1e-4)
    assert cap.frames("p").shape == (sc.sweeps["p"].frames, 16, 16, 3)


def test_default_frames_are_the_camera_models_frames_to_cross():
    """The renderer's default frame count is the one the capture plan predicts."""
    from shadowcam.cameras.models import frames_to_cross
    from shadowcam.synthetic.lab.scenes import make_scene

    scene = make_scene("tabletop", height=8, width=8, frames=20,
                       sweeps=[{"name": "a", "angle_deg": 60.0, "speed": 0.7},
                               {"name": "b", "angle_deg": 90.0, "speed": 2.0}])
    assert scene.sweeps["a"].frames == frames_to_cross((20, 20), 60.0, 0.7) == 40
    assert scene.sweeps["b"].frames == frames_to_cross((20, 20), 90.0, 2.0) == 10
