"""Tests of the virtual shadow cameras of the lab renderer (shadowcam.synthetic.lab.virtual) and
of the paper's camera conversions: distant light -> orthographic dual (Fig. 7), orthographic
primal -> perspective dual (Fig. 8), two lights -> cross-slit dual (Fig. 10).

Exact geometric facts against the analytic ground truth, stated tolerances.
"""

import numpy as np
import pytest

from shadowcam.synthetic.lab.raycast import intersect_scene
from shadowcam.synthetic.lab.render import (
    pixel_centre_ground_truth,
    prepare_capture,
    render_reciprocal,
)
from shadowcam.synthetic.lab.scene import (
    Box, OrthographicCamera, PinholeCamera, Sphere, camera_rays, dual_camera,
)
from shadowcam.synthetic.lab.scenes import make_scene
from shadowcam.synthetic.lab.sweeps import make_sweeps, true_dual_coordinates
from shadowcam.synthetic.lab.virtual import sweep_pair_camera

H = W = 48
T = 32
STANDARD = [{"name": "u"}, {"name": "v", "angle_deg": 90}]
#: sweep v under a second light moved 2 cm back along the mask normal, its wire 1 cm further on:
#: the slits L1 + s e_v and L2 + s e_u are skew lines
CROSS_SLIT = [{"name": "u"},
              {"name": "v", "angle_deg": 90, "light_offset": [0.0, 0.0, -0.02],
               "plane_offset": 0.01}]


def _good_dips(frames, t):
    """Lit pixels with a valid GT time and a clear dip (README 1.9 contrast criterion)."""
    intensity = frames.sum(-1)
    hi, lo = intensity.max(0), intensity.min(0)
    contrast = (hi - lo) / np.maximum(hi, 1e-30)
    good = np.isfinite(t) & (contrast >= 0.5) & (hi >= 0.05 * np.percentile(hi, 99))
    return intensity, good


def _assert_dips_at_analytic_times(capture, names):
    for name in names:
        t = capture.ground_truth[f"t_{name}"].values
        intensity, good = _good_dips(capture.frames(name), t)
        # most lit, swept pixels are well exposed (the orthographic view sees more of the
        # far ground, which the near light lights dimly)
        assert good.sum() >= 0.75 * np.isfinite(t).sum(), name
        assert (np.abs(intensity.argmin(0) - t)[good] <= 1).mean() >= 0.99, name


def _pixel_grid(width, height):
    x, y = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)
    return x.ravel(), y.ravel()


@pytest.mark.parametrize("light_kind", ["point", "distant"])
def test_standard_pair_camera_is_the_dual_camera(light_kind):
    sc = make_scene("tabletop", seed=3, height=8, width=8, frames=T, light_kind=light_kind)
    pair = sweep_pair_camera(make_sweeps(sc.mask, STANDARD, light=sc.light), ("u", "v"))
    dual = dual_camera(sc.mask, sc.light)
    x, y = _pixel_grid(T, T)
    o_pair, d_pair = camera_rays(pair, x, y)
    o_dual, d_dual = camera_rays(dual, x, y)
    np.testing.assert_allclose(d_pair, d_dual, rtol=0, atol=1e-12)
    if light_kind == "point":  # every ray starts at the light
        np.testing.assert_allclose(o_pair, o_dual, rtol=0, atol=1e-12)
    else:  # the same lines: origins differ along the common direction only
        off = o_pair - o_dual
        np.testing.assert_allclose(np.cross(off, d_dual), 0, atol=1e-12)


def test_parallel_wires_make_no_camera():
    sc = make_scene("tabletop", seed=3, height=8, width=8, frames=T)
    sweeps = make_sweeps(sc.mask, [{"name": "a", "angle_deg": 20},
                                   {"name": "b", "angle_deg": 20 + 1e-8}], light=sc.light)
    with pytest.raises(ValueError, match="names"):
        sweep_pair_camera(sweeps, ("a", "b"))
    # nearly, not exactly parallel (0.5 deg): a valid, strongly skewed camera with finite rays
    sweeps = make_sweeps(sc.mask, [{"name": "a", "angle_deg": 20},
                                   {"name": "b", "angle_deg": 20.5}], light=sc.light)
    origins, dirs = sweep_pair_camera(sweeps, ("a", "b")).rays(*_pixel_grid(4, 4))
    assert np.all(np.isfinite(origins)) and np.all(np.isfinite(dirs))


# ----------------------------------------------------------------------- cross-slit (Fig. 10)


@pytest.fixture(scope="module")
def cross_slit():
    sc = make_scene("tabletop", seed=3, height=H, width=W, frames=T, sweeps=CROSS_SLIT)
    return sc, prepare_capture(sc, supersample=3, calibration=False)


def test_cross_slit_ray_of_true_dual_coordinates_hits_the_pixel_point(cross_slit):
    sc, _ = cross_slit
    gt = pixel_centre_ground_truth(sc.objects, sc.camera, sc.light, sc.mask, sc.sweeps)
    both = gt["lit"] & gt["lit_v"]
    assert both.sum() > 0.3 * both.size
    points = gt["P"][both]
    tu_tv = true_dual_coordinates(points, sc.sweeps, ("u", "v"))
    camera = sweep_pair_camera(sc.sweeps, ("u", "v"))
    origins, dirs = camera.rays(tu_tv[:, 0] + 0.5, tu_tv[:, 1] + 0.5)
    hits = intersect_scene(sc.objects, origins, dirs)
    assert np.all(hits.hit)
    np.testing.assert_allclose(hits.point, points, rtol=0, atol=1e-6)


def test_cross_slit_rays_meet_both_slits_and_no_common_centre(cross_slit):
    sc, _ = cross_slit
    camera = sweep_pair_camera(sc.sweeps, ("u", "v"))
    origins, dirs = camera.rays(*_pixel_grid(T, T))
    assert np.all(np.isfinite(dirs))
    for sweep in (sc.sweeps["u"], sc.sweeps["v"]):
        # distance between each ray's line and the slit (line through the light along the wire)
        normal = np.cross(dirs, sweep.direction)
        gap = np.abs(((sweep.light.center - origins) * normal).sum(1)) / np.linalg.norm(normal,
                                                                                      axis=1)
        assert gap.max() < 1e-12
    # not a pinhole: the rays do not share a point (least-squares centre misses them by > 1 mm)
    proj = np.eye(3)[None] - dirs[:, :, None] * dirs[:, None, :]
    centre = np.linalg.solve(proj.sum(0), np.einsum("nij,nj->i", proj, origins))
    miss = np.linalg.norm(np.cross(centre - origins, dirs), axis=1)
    assert miss.max() > 1e-3


def test_cross_slit_capture_renders_with_its_ground_truth(cross_slit):
    sc, cap = cross_slit
    gt = cap.ground_truth
    # sweep v is rendered and timed under its own light
    assert "lit_v" in gt and not np.array_equal(gt["lit_v"].values, gt["lit"].values)
    _assert_dips_at_analytic_times(cap, ("u", "v"))
    # the reciprocal view: dual points lie on the cross-slit rays of their dual pixels
    camera = sweep_pair_camera(sc.sweeps, ("u", "v"))
    dual_p = gt["dual_P"].values.reshape(-1, 3).astype(np.float64)
    hit = np.all(np.isfinite(dual_p), axis=1)
    assert hit.mean() > 0.9
    xy, _ = camera.project(dual_p[hit])
    np.testing.assert_allclose(xy, np.stack(_pixel_grid(T, T), -1)[hit], atol=1e-3)
    recip = gt["reciprocal"].values
    assert np.all(np.isfinite(recip)) and recip.max() > 0


# ----------------------------------------------------------------------- distant light (Fig. 7)


@pytest.fixture(scope="module")
def distant():
    return make_scene("tabletop", seed=3, height=H, width=W, frames=T, light_kind="distant",
                      sweeps=STANDARD, dual_sweeps=("u", "v"))


def test_distant_light_dual_maps_parallel_edges_to_parallel_lines(distant):
    box = next(o for o in distant.objects if isinstance(o, Box))
    hx, hy, hz = box.half_extents
    corners = [box.center + box.rotation @ np.array([sx * hx, -hy, sz * hz])
               for sx in (-1, 1) for sz in (-1, 1)]
    up = box.rotation @ np.array([0.0, 2 * hy, 0.0])  # four vertical edges, different depths
    s = np.linspace(0, 1, 5)[:, None]

    def edge_directions(sweeps, light=None):
        out = []
        for corner in corners:
            uv = true_dual_coordinates(corner + s * up, sweeps, ("u", "v"), light=light)
            step = np.diff(uv, axis=0)
            unit = step / np.linalg.norm(step, axis=1, keepdims=True)
            np.testing.assert_allclose(unit, unit[:1].repeat(4, 0), atol=1e-9)  # straight
            out.append(unit[0])
        return np.array(out), step

    dirs, step = edge_directions(distant.sweeps)
    # orthographic: equal steps along the edge stay equal (affine, no foreshortening)
    np.testing.assert_allclose(step, step[:1].repeat(4, 0), rtol=1e-9)
    cross = dirs[:, 0, None] * dirs[None, :, 1] - dirs[:, 1, None] * dirs[None, :, 0]
    assert np.abs(cross).max() < 1e-9
    # contrast: under the point light (perspective dual) the edges converge
    point = make_scene("tabletop", seed=3, height=8, width=8, frames=T)
    dirs, _ = edge_directions(point.sweeps, light=point.light)
    cross = dirs[:, 0, None] * dirs[None, :, 1] - dirs[:, 1, None] * dirs[None, :, 0]
    assert np.abs(cross).max() > 1e-3


def test_distant_light_dual_size_does_not_depend_on_depth(distant):
    """A sphere's dual footprint is a circle of diameter 2 r / delta wherever it stands."""
    delta = distant.mask.delta
    to_light = distant.light.direction
    a = np.cross(to_light, distant.mask.e_u)
    a /= np.linalg.norm(a)
    b = np.cross(to_light, a)
    phi = np.linspace(0, 2 * np.pi, 16, endpoint=False)[:, None]
    for sphere in (o for o in distant.objects if isinstance(o, Sphere)):
        for depth in (0.0, -0.05, 0.1):  # moved along the light direction
            centre = sphere.center + depth * to_light
            rim = centre + sphere.radius * (np.cos(phi) * a + np.sin(phi) * b)
            uv = true_dual_coordinates(rim, distant.sweeps, ("u", "v"))
            uv_c = true_dual_coordinates(centre[None], distant.sweeps, ("u", "v"))
            np.testing.assert_allclose(np.linalg.norm(uv - uv_c, axis=1),
                                       sphere.radius / delta, rtol=1e-9)


def test_distant_light_reciprocal_footprint_is_depth_invariant(distant):
    """Rendered: the orthographic dual view of one sphere at two depths along the light has
    the same footprint, of area pi (r / delta)^2 up to the pixels on its rim."""
    sphere = next(o for o in distant.objects if isinstance(o, Sphere))
    dual = dual_camera(distant.mask, distant.light)
    assert isinstance(dual, OrthographicCamera)
    counts = []
    for depth in (0.0, -0.06):
        moved = Sphere(sphere.center + depth * distant.light.direction, sphere.radius,
                       sphere.material)
        recip = render_reciprocal((moved,), distant.camera, distant.light, distant.mask,
                                  supersample=1)
        counts.append(int(recip["dual_hit"].sum()))
    assert counts[0] == counts[1]
    r_px = sphere.radius / distant.mask.delta
    assert abs(counts[0] - np.pi * r_px**2) <= 2 * np.pi * r_px + 4


def test_distant_light_capture_renders(distant):
    cap = prepare_capture(distant, supersample=3, calibration=False)
    _assert_dips_at_analytic_times(cap, ("u", "v"))
    gt = cap.ground_truth
    assert np.all(np.isfinite(gt["reciprocal"].values)) and gt["reciprocal"].values.max() > 0
    # dual coordinates of every lit pixel = its analytic times
    lit = gt["lit"].values
    uv = true_dual_coordinates(gt["P"].values[lit].astype(np.float64), distant.sweeps,
                               ("u", "v"))
    np.testing.assert_allclose(uv[:, 0], gt["t_u_all"].values[lit], atol=1e-4)


# ----------------------------------------------------------------------- orthographic primal (Fig. 8)


@pytest.fixture(scope="module")
def orthographic():
    sc = make_scene("tabletop", seed=3, height=H, width=W, frames=T, camera_kind="orthographic")
    return sc, prepare_capture(sc, supersample=3, calibration=True)


def test_orthographic_camera_frames_dip_at_the_analytic_times(orthographic):
    sc, cap = orthographic
    assert isinstance(sc.camera, OrthographicCamera)
    assert np.isfinite(cap.ground_truth["t_u"].values).mean() > 0.5
    _assert_dips_at_analytic_times(cap, ("u", "v", "cal_u", "cal_v"))


def test_orthographic_camera_has_a_perspective_dual_lit_by_a_distant_light(orthographic):
    sc, cap = orthographic
    assert isinstance(dual_camera(sc.mask, sc.light), PinholeCamera)
    gt = cap.ground_truth
    recip = gt["reciprocal"].values.sum(-1)
    visible = gt["dual_cam_visible"].values
    assert visible.mean() > 0.3
    # where the camera sees the dual point, the camera-as-distant-light lights it
    assert (recip[visible] > 0).mean() > 0.95
    # dual_cam_xy: the orthographic projection of dual_P
    xy = gt["dual_cam_xy"].values[visible].astype(np.float64)
    p = gt["dual_P"].values[visible].astype(np.float64)
    cam = sc.camera
    expect = (p - cam.center) @ cam.R[:2].T / cam.pixel_size + np.array([W, H]) / 2 - 0.5
    np.testing.assert_allclose(xy, expect, atol=1e-3)


def test_orthographic_calibration_map_is_affine_and_exact(orthographic):
    _, cap = orthographic
    gt = cap.ground_truth
    H_map = gt["calibration_homography"].values
    np.testing.assert_array_equal(H_map[2], [0, 0, 1])
    rows, cols = np.mgrid[0:H, 0:W]
    xy = np.stack([cols, rows, np.ones_like(cols)], -1) @ H_map.T
    plane = gt["plane_xy"].values
    ok = np.all(np.isfinite(plane), axis=-1)
    np.testing.assert_allclose(xy[..., :2][ok], plane[ok], atol=1e-6)
