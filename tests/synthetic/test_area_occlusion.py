"""Tests of the exact occlusion of a continuous area light by the wire, and of its render."""

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from shadowcam.synthetic.lab.area_occlusion import blocked_share, exact_occlusion, extreme_offset
from shadowcam.synthetic.lab.raycast import wire_occlusion_interval
from shadowcam.synthetic.lab.scene import light_plane_axes
from shadowcam.synthetic.lab.scenes import make_scene


@pytest.fixture(scope="module")
def scene():
    return make_scene("tabletop", height=16, width=16, frames=64, light_kind="area", wire_radius_frames=4)


def _numeric_share(point, time, light, sweep, mask, n=400):
    """Share of the source hidden by numeric integration: a dense grid of its points, each
    hidden while the wire covers its line to the point (``wire_occlusion_interval``)."""
    e1, e2 = light_plane_axes(light)
    if light.shape == "tube":
        a = (np.arange(4 * n) + 0.5) / (4 * n) - 0.5
        sources = light.position + light.size * a[:, None] * e1
    else:
        if light.shape == "sphere":  # the disc of its radius facing the point
            normal = (light.position - point) / np.linalg.norm(light.position - point)
            e1 = np.cross(normal, e2 if abs(normal @ e2) < 0.9 else e1)
            e1 /= np.linalg.norm(e1)
            e2 = np.cross(normal, e1)
        x, y = np.meshgrid(*(2 * [(np.arange(n) + 0.5) / n * 2 - 1]))
        inside = x**2 + y**2 < 1
        sources = light.position + 0.5 * light.size * (x[inside][:, None] * e1 + y[inside][:, None] * e2)
    centre, half = wire_occlusion_interval(np.broadcast_to(point, sources.shape), sources, sweep, mask)
    return np.mean(np.abs(time - centre) < half)


@settings(max_examples=25, deadline=None)
@given(x=st.floats(-0.06, 0.06), z=st.floats(-0.08, 0.0), offset=st.floats(-8, 8),
       shape=st.sampled_from(["disc", "sphere", "tube"]), sweep=st.sampled_from(["u", "v"]))
def test_blocked_share_is_the_sources_area_inside_the_wires_strip(scene, x, z, offset, shape, sweep):
    light = replace(scene.light, shape=shape)
    point = np.array([x, -0.05, z])
    wire = scene.sweeps[sweep]
    centre, _ = wire_occlusion_interval(point[None], light.position[None], wire, scene.mask)
    time = centre[0] + offset
    exact = blocked_share(point[None], light, wire, scene.mask, np.array([time]))[0]
    assert exact == pytest.approx(_numeric_share(point, time, light, wire, scene.mask), abs=4e-3)


def test_continuous_render_hides_the_blocked_share_of_each_points_light(scene):
    from shadowcam.synthetic.lab.render import prepare_capture

    capture = prepare_capture(scene, supersample=1, calibration=False)
    frames = capture.frames("u").sum(axis=-1).astype(np.float64)
    gt = capture.ground_truth
    reference = gt["reference_linear"].values.sum(axis=-1).astype(np.float64)
    points = gt["P"].values.reshape(-1, 3).astype(np.float64)
    lit = gt["lit"].values.ravel().astype(bool) & (reference.ravel() > 0)
    share = blocked_share(points[lit], scene.light, scene.sweeps["u"], scene.mask,
                          np.tile(np.arange(64.0), (lit.sum(), 1)))
    expected = reference.ravel()[lit][:, None] * (1 - share)
    # one sub-sample per pixel: its frames are the reference less the hidden share of the
    # light it receives (float32 frames; a pixel on a cast-shadow edge sees part of the light)
    rendered = frames.reshape(64, -1)[:, lit].T
    close = np.abs(rendered - expected) <= 1e-5 * reference.ravel()[lit][:, None]
    assert close.all(axis=1).mean() > 0.95
    # the sampled light (a square) keeps the samples' staircase
    assert exact_occlusion(scene.light) and not exact_occlusion(replace(scene.light, shape="square"))


def test_extreme_offsets_of_the_continuous_sources(scene):
    light = scene.light
    assert extreme_offset(light, scene.mask.e_u) == pytest.approx(0.003)  # the disc faces the mask
    assert extreme_offset(replace(light, shape="sphere"), scene.mask.e_v) == pytest.approx(0.003)
    tube = replace(light, shape="tube")
    axis = light_plane_axes(tube)[0]
    assert extreme_offset(tube, axis) == pytest.approx(0.003)
    assert extreme_offset(tube, light_plane_axes(tube)[1]) == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("motion", ["instant", "shutter", "offsets"])
def test_open_shutter_and_non_planar_motion_of_the_continuous_source(scene, motion):
    # the continuous source's frames against the same scene's finely sampled disc (24 x 24,
    # each sample blocked on its own): an instant exposure, an open shutter (averaged over
    # 16 instants) or the wire pushed off its plane per frame. Each pixel's largest
    # difference over the sweep, relative to its lit level, measured p95 0.021 / 0.004 /
    # 0.021 (the samples' staircase; the open shutter smooths it); bound 0.03. (A pixel on
    # a cast-shadow edge differs more, up to 0.7: the continuous share is applied to the
    # part of the source it sees.)
    from shadowcam.synthetic.lab.render import sweep_frames, trace_light_paths

    light = replace(scene.light, samples_per_side=24)
    paths = trace_light_paths(scene.objects, scene.camera, light, supersample=1)
    options = {"instant": {}, "shutter": {"shutter": 1.0},
               "offsets": {"path_offsets": np.random.default_rng(0).normal(0, 0.3 * scene.mask.delta, 64)}}[motion]
    exact = sweep_frames(paths, scene.sweeps["u"], scene.mask, light=light, **options).sum(axis=-1)
    sampled = sweep_frames(paths, scene.sweeps["u"], scene.mask, **options).sum(axis=-1)
    level = exact.max(axis=0)
    difference = (np.abs(exact - sampled) / np.where(level > 0, level, np.nan)).max(axis=0)
    assert np.nanpercentile(difference, 95) < 0.03
