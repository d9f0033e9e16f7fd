"""Several lights under one wire sweep: one dip per light at its exact time; tube lights."""

import numpy as np
import pytest

from shadowcam.synthetic.lab.light_sets import (
    TubeLight, light_points, light_set_ground_truth, trace_light_set,
)
from shadowcam.synthetic.lab.render import render_image, sweep_frames
from shadowcam.synthetic.lab.scene import DistantLight, PointLight
from shadowcam.synthetic.lab.scenes import make_scene


@pytest.fixture(scope="module")
def scene():
    return make_scene("tabletop", height=32, width=32, frames=48)


def _smooth(t):
    """Pixels where the times are locally planar (second differences < 0.5 frame along rows
    and columns): a pixel on an object's outline has sub-samples on other surfaces, with
    other times than its centre."""
    pad = np.pad(t, 1, constant_values=np.nan)
    centre = pad[1:-1, 1:-1]
    with np.errstate(invalid="ignore"):
        rows = np.abs(pad[:-2, 1:-1] + pad[2:, 1:-1] - 2 * centre) < 0.5
        cols = np.abs(pad[1:-1, :-2] + pad[1:-1, 2:] - 2 * centre) < 0.5
    return rows & cols


def _render(scene, lights):
    sweep = scene.sweeps["u"]
    paths, source = trace_light_set(scene.objects, scene.camera, lights, supersample=2)
    frames = sweep_frames(paths, sweep, scene.mask).sum(-1)
    reference = render_image(paths).sum(-1)
    gt = light_set_ground_truth(scene.objects, scene.camera, lights, sweep, paths, source)
    return frames, reference, gt


def test_two_point_lights_give_two_dips_at_their_times(scene):
    first = scene.light
    second = PointLight(first.position + 0.012 * scene.mask.e_u, first.intensity)
    frames, reference, gt = _render(scene, [first, second])
    t = gt["t_center"]
    n = frames.shape[0]
    both = (_smooth(t[0]) & _smooth(t[1]) & (np.abs(t[0] - t[1]) > 6) & (t.min(0) > 2)
            & (t.max(0) < n - 3) & (reference > 0.2 * np.median(reference)))
    assert both.sum() > 200
    y, x = np.nonzero(both)
    for k in range(2):
        at = frames[np.rint(t[k][y, x]).astype(int), y, x]
        # the wire (two frames wide) fully blocks light k at its time: the pixel loses
        # about that light's share of its radiance
        expected = reference[y, x] * (1 - gt["share"][k][y, x])
        assert np.mean(np.abs(at - expected) <= 0.25 * reference[y, x]) > 0.95
    np.testing.assert_allclose(np.nansum(gt["share"], axis=0)[reference > 0], 1.0, atol=1e-9)


def test_tube_across_the_wire_spreads_and_weakens_its_shadow(scene):
    """Paper Fig. 11: the shadow of a tube parallel to the wire stays deep; across the wire
    it spreads over [t_first, t_last] and its contrast drops. Outside that interval (plus
    the wire's own width) the frame equals the reference."""
    centre, half = scene.light.position, 0.006
    along = TubeLight(centre - half * scene.mask.e_v, centre + half * scene.mask.e_v)
    across = TubeLight(centre - half * scene.mask.e_u, centre + half * scene.mask.e_u)
    depth, spread = {}, {}
    for name, tube in (("along", along), ("across", across)):
        frames, reference, gt = _render(scene, [tube])
        n = frames.shape[0]
        lo, hi = gt["t_first"][0], gt["t_last"][0]
        ok = (_smooth(lo) & _smooth(hi) & (lo > 4) & (hi < n - 5)
              & (reference > 0.2 * np.median(reference)))
        y, x = np.nonzero(ok)
        ratio = frames[:, y, x] / reference[y, x]
        depth[name] = np.median(1 - ratio.min(axis=0))
        spread[name] = np.median(hi[ok] - lo[ok])
        k = np.arange(n)[:, None]
        outside = (k < lo[y, x] - 3) | (k > hi[y, x] + 3)
        assert np.all(np.abs(ratio[outside] - 1) < 1e-5), name
    assert spread["across"] > 3 * spread["along"]
    assert depth["along"] > 0.9 and depth["across"] < 0.7 * depth["along"]


def test_light_points_split_the_intensity():
    tube = TubeLight((0, 0, 0), (1, 0, 0), (3.0, 3.0, 3.0), samples=6)
    points = light_points(tube)
    assert len(points) == 6
    np.testing.assert_allclose(sum(p.intensity for p in points), tube.intensity)
    with pytest.raises(ValueError, match="distant"):
        light_points(DistantLight((0, 1, 0)))
    with pytest.raises(ValueError, match="tube length"):
        TubeLight((1, 1, 1), (1, 1, 1))
