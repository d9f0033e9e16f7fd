"""Tests of shadowcam.synthetic.lab.render (and the ``shadowcam render`` CLI that wraps it).

Physical facts against the exact analytic ground truth of tiny tabletop captures.
"""

import json

import numpy as np
import pytest
import xarray as xr

from shadowcam.synthetic.lab.render import prepare_capture, render_image, trace_light_paths
from shadowcam.synthetic.lab.raycast import intersect_scene
from shadowcam.synthetic.lab.scene import camera_rays
from shadowcam.synthetic.lab.scenes import make_scene

H = W = 64
T = 32


@pytest.fixture(scope="module")
def capture():
    scene = make_scene("tabletop", seed=3, height=H, width=W, frames=T)
    return prepare_capture(scene, supersample=4, calibration=True)


@pytest.fixture(scope="module")
def centre_capture():
    """Pixel-centre sampling (supersample=1): pixel values are exactly the GT point's radiance."""
    scene = make_scene("tabletop", seed=3, height=H, width=W, frames=T)
    return prepare_capture(scene, supersample=1, calibration=False)


def _good_dips(frames, t):
    """Lit pixels with a valid GT time and a clear dip (README 1.9 contrast criterion)."""
    intensity = frames.sum(-1)
    hi, lo = intensity.max(0), intensity.min(0)
    contrast = (hi - lo) / np.maximum(hi, 1e-30)
    good = np.isfinite(t) & (contrast >= 0.5) & (hi >= 0.05 * np.percentile(hi, 99))
    return intensity, good


@pytest.mark.parametrize("light_kind", ["point", "distant"])
def test_darkest_frame_is_the_analytic_shadow_time(light_kind, capture):
    if light_kind == "point":
        cap = capture
    else:
        scene = make_scene("tabletop", seed=3, height=H, width=W, frames=T, light_kind="distant")
        cap = prepare_capture(scene, supersample=4, calibration=False)
    gt = cap.ground_truth
    for sweep in ("u", "v"):
        t = gt[f"t_{sweep}"].values
        intensity, good = _good_dips(cap.frames(sweep), t)
        # nearly every lit, swept pixel has a clear dip
        assert good.sum() >= 0.95 * np.isfinite(t).sum()
        err = np.abs(intensity.argmin(0) - t)[good]
        assert (err <= 1).mean() > 0.99, sweep
        # integer argmin of a fractional GT: median error is about a quarter frame
        assert np.median(err) < 0.45


def test_area_light_dip_is_centred_on_the_light_centre_time():
    """An extended source widens the dip into a plateau; its deficit centroid stays at t."""
    scene = make_scene("tabletop", seed=3, height=H, width=W, frames=T, light_kind="area")
    cap = prepare_capture(scene, supersample=2, calibration=False)
    ref = cap.reference.sum(-1)
    for sweep in ("u", "v"):
        deficit = np.clip(ref - cap.frames(sweep).sum(-1), 0, None)
        centroid = (deficit * np.arange(T)[:, None, None]).sum(0) / np.maximum(
            deficit.sum(0), 1e-30)
        t = cap.ground_truth[f"t_{sweep}"].values
        inner = np.isfinite(t) & (t > 5) & (t < T - 6) & (deficit.max(0) > 0.5 * ref)
        assert inner.sum() > 0.4 * H * W
        assert (np.abs(centroid - t)[inner] <= 0.5).mean() > 0.99


def test_pixel_centre_point_is_black_in_the_frame_nearest_its_shadow_time(centre_capture):
    """Point light, no ambient: the wire (radius = 1 frame) fully shadows the GT point."""
    gt = centre_capture.ground_truth
    for sweep in ("u", "v"):
        frames = centre_capture.frames(sweep)
        t = gt[f"t_{sweep}"].values
        rows, cols = np.nonzero(np.isfinite(t))
        k = np.rint(t[rows, cols]).astype(int)
        ref = centre_capture.reference[rows, cols]
        assert np.all(frames[k, rows, cols] <= 1e-9 * ref)  # black up to float64 rounding
        # and untouched far from it: identical to the reference
        far = np.abs(np.arange(T)[:, None] - t[rows, cols][None]) > 2
        same = frames[:, rows, cols] == ref[None]
        assert np.all(same.all(-1)[far])


def test_lambertian_reference_radiance_is_rho_over_pi_I_cos_over_d2(centre_capture):
    gt = centre_capture.ground_truth
    scene = centre_capture.scene
    x, y = np.meshgrid(np.arange(W) + 0.5, np.arange(H) + 0.5)
    hits = intersect_scene(scene.objects, *camera_rays(scene.camera, x.ravel(), y.ravel()))
    matte = np.array([o.material.specular == 0 for o in scene.objects])[hits.object_id]
    lit = gt.lit.values.ravel() & matte
    expected = (hits.albedo / np.pi * scene.light.intensity
                * (gt.cos_L.values.ravel() / gt.dist_L.values.ravel() ** 2)[:, None])
    got = gt.reference_linear.values.reshape(-1, 3)
    assert lit.sum() > 0.5 * H * W
    np.testing.assert_allclose(got[lit], expected[lit], rtol=2e-5)
    # unlit pixel centres are black (no ambient light)
    assert np.all(got[~gt.lit.values.ravel()] == 0)


def test_reciprocal_render_obeys_helmholtz_ratio():
    """README 1.7: L_cam / L_recip = (cos_L / d_L^2) / (cos_C / d_C^2) for the same point."""
    scene = make_scene("tabletop", seed=3, height=128, width=128, frames=48)
    cap = prepare_capture(scene, supersample=1, calibration=False)
    gt = cap.ground_truth
    vis = gt.dual_cam_visible.values
    P = gt.dual_P.values.astype(float)[vis]
    N = intersect_scene(scene.objects, P + 1e-4 * (scene.light.position - P),
                        -(scene.light.position - P) / np.linalg.norm(
                            scene.light.position - P, axis=1, keepdims=True)).normal
    to_l, to_c = scene.light.position - P, scene.camera.center - P
    d_l, d_c = np.linalg.norm(to_l, axis=1), np.linalg.norm(to_c, axis=1)
    cos_l = (N * to_l).sum(1) / d_l
    cos_c = (N * to_c).sum(1) / d_c
    predicted = (cos_l / d_l**2) / (cos_c / d_c**2)
    # camera radiance at the dual point: bilinear interpolation of the pixel-centre reference
    ref = cap.reference.sum(-1)
    lit = gt.lit.values
    xy = gt.dual_cam_xy.values[vis]
    c0 = np.floor(xy).astype(int)
    inner = np.all((c0 >= 0) & (c0 < np.array([127, 127])), axis=1)
    c0c = np.clip(c0, 0, 126)
    corners = [(c0c[:, 1] + i, c0c[:, 0] + j) for i in (0, 1) for j in (0, 1)]
    all_lit = inner & np.all([lit[r, c] for r, c in corners], axis=0)
    f = xy - c0
    cam = ((1 - f[:, 0]) * (1 - f[:, 1]) * ref[corners[0]] + f[:, 0] * (1 - f[:, 1])
           * ref[corners[1]] + (1 - f[:, 0]) * f[:, 1] * ref[corners[2]]
           + f[:, 0] * f[:, 1] * ref[corners[3]])
    recip = gt.reciprocal.values.sum(-1)[vis]
    ok = all_lit & (recip > 0)
    assert ok.sum() > 500
    ratio = cam[ok] / recip[ok] / predicted[ok]
    # textures make bilinear interpolation imperfect at edges; the bulk is exact
    assert np.median(ratio) == pytest.approx(1.0, abs=0.005)
    q25, q75 = np.percentile(ratio, [25, 75])
    assert q25 > 0.98 and q75 < 1.02


def test_calibration_homography_maps_pixels_to_plane_points(capture):
    gt = capture.ground_truth
    Hm = capture.homography
    cols, rows = np.meshgrid(np.arange(W), np.arange(H))
    m = np.stack([cols, rows, np.ones_like(cols)], -1) @ Hm.T
    xy = m[..., :2] / m[..., 2:]
    plane = gt.plane_xy.values
    on_plane = np.isfinite(plane[..., 0])
    assert on_plane.sum() > 0.3 * H * W
    assert np.abs(xy - plane)[on_plane].max() < 1e-3
    np.testing.assert_allclose(gt.calibration_homography.values, Hm)


def test_calibration_sweeps_dip_at_their_gt_time(capture):
    gt = capture.ground_truth
    for sweep in ("u", "v"):
        t = gt[f"t_cal_{sweep}"].values
        intensity, good = _good_dips(capture.frames(f"cal_{sweep}"), t)
        assert good.sum() > 0.2 * H * W
        assert (np.abs(intensity.argmin(0) - t)[good] <= 1).mean() > 0.99


def test_render_image_matches_reference_and_paths_are_static(capture):
    scene = capture.scene
    paths = trace_light_paths(scene.objects, scene.camera, scene.light, supersample=4)
    np.testing.assert_array_equal(render_image(paths), capture.reference)
    assert capture.reference.dtype == np.float32
    with pytest.raises(ValueError, match="supersample"):
        trace_light_paths(scene.objects, scene.camera, scene.light, supersample=0)


def test_ground_truth_dataset_has_standard_names(capture):
    gt = capture.ground_truth
    for name, dims in {"t_u": ("row", "col"), "t_v": ("row", "col"), "lit": ("row", "col"),
                       "reciprocal": ("v", "u", "channel"), "dual_cam_visible": ("v", "u"),
                       "P": ("row", "col", "xyz"), "t_cal_u": ("row", "col"),
                       "plane_xy": ("row", "col", "plane_axis"),
                       "reference_linear": ("row", "col", "channel")}.items():
        assert gt[name].dims == dims, name
        assert "units" in gt[name].attrs and "long_name" in gt[name].attrs
    assert gt.lit.dtype == bool
    assert gt.sizes["u"] == gt.sizes["v"] == T
    # t values lie in [0, T-1] where defined and only on lit pixels
    t = gt.t_u.values
    assert np.nanmin(t) >= 0 and np.nanmax(t) <= T - 1
    assert not np.any(np.isfinite(t) & ~gt.lit.values)


def test_render_cli_writes_a_complete_capture(tmp_path):
    import rawpy
    import yaml

    from shadowcam.cli import main
    from shadowcam.io.provenance import file_sha256
    from shadowcam.synthetic.sensor import SensorModel, mosaic_rggb

    manifest = tmp_path / "tiny.yaml"
    manifest.write_text(yaml.safe_dump({
        "name": "tiny", "kind": "lab", "light": "distant", "synthetic": {
            "scene": "tabletop", "seed": 5, "height": 32, "width": 32, "frames": 12,
            "format": "dng", "bit_depth": 12, "noise": True, "calibration": True}}))
    out = tmp_path / "capture"
    assert main(["render", "--manifest", str(manifest), "--out", str(out), "--no-noise"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["capture", "tiny.yaml"]  # no temp
    cap = json.loads((out / "capture.json").read_text())
    assert cap["name"] == "tiny" and cap["kind"] == "lab" and cap["root"] == "."
    assert cap["light"] == "distant"  # the manifest's top-level light type is rendered
    assert cap["sweeps"]["u"] == {"files": "frames_u/*.dng", "axis": "u"}
    assert cap["sweeps"]["cal_v"] == {"files": "cal_v/*.dng", "axis": "v"}
    assert cap["dual"] == {"width": 12, "height": 12}
    assert cap["ground_truth"] == {"format": "shadowcam_nc", "file": "ground_truth.nc",
                                   "noise": "noise_free"}
    assert cap["timing"] == {"source": "rate", "rate_hz": 1.0}
    assert cap["licence"] == "CC0-1.0"
    assert np.shape(cap["calibration_plane"]["homography"]) == (3, 3)
    assert len(cap["checksums"]) == 4 * 12 + 2
    for rel, digest in cap["checksums"].items():
        assert file_sha256(out / rel) == digest
    gt = xr.open_dataset(out / "ground_truth.nc", engine="h5netcdf")
    # noise-free DNG = round(black + scale * mosaic(reference))
    sensor = SensorModel(bit_depth=12)
    with rawpy.imread(str(out / "reference.dng")) as raw:
        got = raw.raw_image_visible.copy()
    expected = np.clip(np.rint(sensor.black_level + gt.attrs["electrons_per_unit_radiance"]
                               * mosaic_rggb(gt.reference_linear.values.astype(np.float64))),
                       0, sensor.white_level)
    assert np.abs(got.astype(float) - expected).max() <= 1  # float32 GT storage rounding
    assert gt.attrs["step"] == "render" and json.loads(gt.attrs["input_checksums"])
    assert json.loads(gt.attrs["geometry"])["light"]["type"] == "DistantLight"
    gt.close()
    # explicit flags, tiff, re-render replaces the directory atomically
    assert main(["render", "--scene", "tabletop", "--height", "24", "--width", "24",
                 "--frames", "6", "--format", "tiff", "--out", str(out)]) == 0
    assert not (out / "cal_u").exists()
    assert len(list((out / "frames_v").glob("*.tiff"))) == 6
    # user errors: no traceback, exit code 2, nothing written
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: bad\nkind: lab\n")
    assert main(["render", "--manifest", str(bad), "--out", str(tmp_path / "x")]) == 2
    assert not (tmp_path / "x").exists()


def test_nonplanar_wire_offsets_shift_the_dip_as_central_projection_predicts(centre_capture):
    """A wire pushed a distance e off its plane (away from the light) at in-plane position s
    shadows like a planar wire at s h / (h + e): the dip of a pixel with planar GT time t
    moves to frame c + (t - c)(h + e)/h, c = (T-1)/2 (the frame through M0)."""
    cap = centre_capture
    h, c = cap.scene.mask.focal, (T - 1) / 2.0
    t = cap.ground_truth["t_u"].values
    planar = cap.frames("u")
    zero = cap.frames("u", path_offsets=np.zeros(T))
    np.testing.assert_allclose(zero, planar, rtol=0, atol=1e-6 * planar.max())
    e = 0.2 * h
    moved = cap.frames("u", path_offsets=np.full(T, e))
    intensity, good = _good_dips(moved, t)
    predicted = c + (t - c) * (h + e) / h
    far = good & (np.abs(t - c) > 8)  # the shift there exceeds 1.6 frames
    assert far.sum() > 100
    removed = intensity.max(0) - intensity  # centroid of the dip: midpoint of dark frames
    with np.errstate(invalid="ignore"):
        centroid = (np.arange(T)[:, None, None] * removed).sum(0) / removed.sum(0)
    err = np.abs(centroid - predicted)[far]
    assert np.median(err) < 0.3 and np.percentile(err, 95) <= 0.6
    assert np.median(np.abs(centroid - t)[far]) > 1.5  # it really moved
    with pytest.raises(ValueError, match="path_offsets"):
        cap.frames("u", path_offsets=np.zeros(T - 1))


def test_open_shutter_makes_the_sampled_dip_centroid_the_shadow_time():
    """shutter = 1: each frame integrates the moving wire over the whole frame interval, so
    the sampled dip's deficit-weighted centroid follows the analytic time to < 0.01 frame;
    an instant exposure samples a hard-edged boxcar and quantises it (errors > 0.1 frame)."""
    from shadowcam.synthetic.lab.render import prepare_capture, sweep_frames
    from shadowcam.synthetic.lab.scenes import make_scene

    scene = make_scene("tabletop", seed=0, height=16, width=16, frames=12)
    capture = prepare_capture(scene, supersample=1, calibration=False)
    truth = capture.ground_truth
    reference = capture.reference.astype(np.float64)
    k = np.arange(12)[:, None, None]
    for name in ("u", "v"):
        t = truth[f"t_{name}"].values.astype(np.float64)
        inner = np.isfinite(t) & (t > 2.5) & (t < 12 - 3.5) & truth["lit"].values.astype(bool)
        assert inner.sum() > 20
        errors = {}
        for shutter in (0.0, 1.0):
            frames = capture.frames(name, shutter=shutter).astype(np.float64)
            deficit = (reference[None] - frames).sum(axis=-1)[:, inner]  # (T, n)
            centroid = (k[:, :, 0] * deficit).sum(axis=0) / deficit.sum(axis=0)
            errors[shutter] = np.abs(centroid - t[inner]).max()
        assert errors[1.0] < 0.01 < 0.1 < errors[0.0], errors
    with pytest.raises(ValueError, match="shutter"):
        sweep_frames(capture._paths["u"], scene.sweeps["u"], scene.mask, shutter=1.5)


def test_ground_truth_carries_the_straight_edge_points_of_a_squares_plane():
    from shadowcam.synthetic.lab.edges import square_edge_points
    from shadowcam.synthetic.lab.scenes import scene_from_description

    description = {"scene": "tabletop_squares", "seed": 0, "height": 32, "width": 32, "frames": 16}
    scene = scene_from_description(description)
    gt = prepare_capture(scene, supersample=1, calibration=False).ground_truth
    edges = square_edge_points(scene)
    assert gt.sizes["edge_point"] == len(edges.label) > 20
    np.testing.assert_allclose(gt["edge_camera_xy"].values, edges.camera_xy, atol=1e-5)
    # without optics the camera sees every edge point directly, on the camera's pixel grid
    assert not gt["edge_through_optics"].values.any()
    xy = gt["edge_camera_xy"].values
    assert np.all((xy >= -0.5) & (xy <= 31.5))
    # a point on an edge of constant plane x sits on a pixel-centre row (and vice versa)
    on_row = np.isclose(xy[:, 1], np.round(xy[:, 1]), atol=1e-6)
    on_col = np.isclose(xy[:, 0], np.round(xy[:, 0]), atol=1e-6)
    assert np.all(on_row | on_col)


@pytest.mark.parametrize("supersample", [1, 2, 4, 7])
def test_declared_footprint_variance_is_the_sub_samples_second_moment(supersample):
    from shadowcam.synthetic.lab.render import _subpixel_grid, footprint_variance

    x, y = _subpixel_grid(1, 1, supersample)
    assert footprint_variance(supersample) == pytest.approx(np.mean((x - 0.5) ** 2), abs=1e-15)
    assert footprint_variance(supersample) == pytest.approx(np.mean((y - 0.5) ** 2), abs=1e-15)
    with pytest.raises(ValueError, match="supersample"):
        footprint_variance(0)
