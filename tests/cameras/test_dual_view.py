"""Tests of shadowcam.cameras.dual_view: mesh warp and IDW resampling into the dual grid."""


import numpy as np
import pytest
import xarray as xr
from scipy.ndimage import binary_erosion

from hypothesis import given, settings
from hypothesis import strategies as st

from shadowcam.cameras.dual_coords import apply_homography
from shadowcam.cameras.dual_view import (
    DUAL_VIEW_METHODS,
    camera_colours,
    continuous_steps,
    dual_view_dataset,
    resample_dual_view,
)



def _planar_mapping(homography, rows=64, cols=64):
    r, c = np.mgrid[0:rows, 0:cols]
    uv = apply_homography(homography, np.column_stack([c.ravel(), r.ravel()]).astype(float))
    return uv[:, 0].reshape(rows, cols), uv[:, 1].reshape(rows, cols)


AFFINE = np.array([[0.55, 0.12, 3.0], [-0.08, 0.6, 4.0], [0, 0, 1.0]])
PROJECTIVE = np.array([[0.55, 0.12, 3.0], [-0.08, 0.6, 4.0], [1.5e-3, -1e-3, 1.0]])


def _dual_pixels_inside(homography, rows, cols, shape, margin=1.0):
    """Dual pixel centres whose camera pre-image lies inside the camera grid by `margin`."""
    jj, ii = np.mgrid[0 : shape[0], 0 : shape[1]]
    cr = apply_homography(np.linalg.inv(homography), np.column_stack([ii.ravel(), jj.ravel()]))
    inside = ((cr[:, 0] >= margin) & (cr[:, 0] <= cols - 1 - margin)
              & (cr[:, 1] >= margin) & (cr[:, 1] <= rows - 1 - margin))
    return inside.reshape(shape), cr.reshape(shape + (2,))


def test_mesh_reproduces_linear_colours_exactly_under_affine_map():
    # a colour linear in camera (col, row) is linear in (u, v) under an affine map, and
    # barycentric interpolation reproduces linear functions exactly
    u, v = _planar_mapping(AFFINE)
    r, c = np.mgrid[0:64, 0:64]
    colours = np.stack([0.01 * c + 0.002 * r, 0.5 - 0.004 * r, 0.3 + 0 * c], -1).astype(np.float32)
    img, cov = resample_dual_view(colours, u, v, shape=(48, 48), method="mesh")
    inside, cr = _dual_pixels_inside(AFFINE, 64, 64, (48, 48))
    assert cov[inside].all()
    expect = np.stack([0.01 * cr[..., 0] + 0.002 * cr[..., 1], 0.5 - 0.004 * cr[..., 1],
                       0.3 + 0 * cr[..., 0]], -1)
    np.testing.assert_allclose(img[inside], expect[inside], atol=1e-5)
    assert img.dtype == np.float32


@pytest.mark.parametrize("method, tolerance", [("mesh", 0.01), ("idw", 0.1)])
def test_straight_lines_stay_straight(method, tolerance):
    # a straight camera line maps to a straight dual line under a homography; the line is
    # the 0.5 contour of a colour ramp across it (signed distance, 8 camera pixels wide)
    u, v = _planar_mapping(PROJECTIVE)
    r, c = np.mgrid[0:64, 0:64]
    dist = (0.8 * c - 0.6 * r + 10.0)  # signed distance (pixels) to a straight camera line
    colours = np.clip(0.5 + dist / 8, 0, 1)[..., None].astype(np.float32)
    img, cov = resample_dual_view(colours, u, v, shape=(48, 48), method=method)
    # the 0.5 contour, located per dual row by linear interpolation along u, away from the
    # border of the covered area (where IDW neighbourhoods are one-sided)
    interior = binary_erosion(cov, iterations=2)
    pts = []
    for j in range(48):
        row = np.where(interior[j], img[j, :, 0], np.nan)
        for i in range(47):
            a, b = row[i] - 0.5, row[i + 1] - 0.5
            if np.isfinite(a) and np.isfinite(b) and a * b < 0:
                pts.append((i + a / (a - b), j))
    pts = np.array(pts)
    assert len(pts) >= 15
    line = apply_homography(PROJECTIVE, np.array([[0.0, 10 / 0.6], [40.0, (10 + 32) / 0.6]]))
    d = line[1] - line[0]
    normal = np.array([-d[1], d[0]]) / np.hypot(*d)
    deviation = (pts - line[0]) @ normal
    # mesh: piecewise-linear interpolation of a nearly linear field, second-order error
    # (measured 1e-3 dual px); idw: a smoother with weights uneven across the edge
    assert np.abs(deviation).max() < tolerance


def test_holes_and_discontinuities_stay_nan():
    u, v = _planar_mapping(AFFINE)
    valid = np.ones((64, 64), bool)
    valid[20:30, 20:30] = False  # no shadow time here
    u = u.copy()
    u[:, 40:] += 10.0  # a depth discontinuity: 10 dual pixels jump between cols 39 and 40
    colours = np.ones((64, 64, 3), np.float32)
    for method in ("mesh", "idw"):
        img, cov = resample_dual_view(colours, u, v, shape=(60, 60), valid=valid, method=method)
        assert np.array_equal(cov, np.all(np.isfinite(img), axis=2))
        # centre of the hole: camera (24.5, 24.5)
        hole = apply_homography(AFFINE, np.array([[24.5, 24.5]]))[0]
        assert not cov[int(round(hole[1])), int(round(hole[0]))]
        # the gap opened by the discontinuity, half-way between the two sides, row of camera row 32
        left = apply_homography(AFFINE, np.array([[39.0, 32.0]]))[0]
        j, i = int(round(left[1])), int(round(left[0] + 5.0))
        assert not cov[j, i] and np.isnan(img[j, i]).all()
        np.testing.assert_allclose(img[cov], 1.0, rtol=1e-6)  # no darkening by holes


def test_overlapping_samples_are_averaged_not_overwritten():
    # two surfaces mapped onto the same dual area with colours 1 and 3: mesh averages them
    u, v = _planar_mapping(AFFINE, rows=32, cols=64)
    u = u.copy()
    u[:, 32:] -= u[0, 32] - u[0, 0]  # right half folded onto the left half
    v = v.copy()
    v[:, 32:] -= v[0, 32] - v[0, 0]
    colours = np.ones((32, 64, 1), np.float32)
    colours[:, 32:] = 3.0
    img, cov = resample_dual_view(colours, u, v, shape=(40, 40), method="mesh", max_edge=2.0)
    inside, _ = _dual_pixels_inside(AFFINE, 32, 31, (40, 40))
    np.testing.assert_allclose(img[inside, 0], 2.0, rtol=1e-6)


def test_idw_reproduces_constant_and_respects_radius():
    u, v = _planar_mapping(AFFINE)
    colours = np.full((64, 64, 3), 0.25, np.float32)
    img, cov = resample_dual_view(colours, u, v, shape=(80, 80), method="idw", radius=1.0)
    np.testing.assert_allclose(img[cov], 0.25, rtol=1e-6)
    # far outside the mapped area there is no sample within the radius
    assert not cov[79, 0] and not cov[0, 79]


def test_input_validation():
    with pytest.raises(ValueError, match="method"):
        resample_dual_view(np.zeros((4, 4, 3)), np.zeros((4, 4)), np.zeros((4, 4)),
                           shape=(4, 4), method="nearest")
    with pytest.raises(ValueError, match="u/v"):
        resample_dual_view(np.zeros((4, 4, 3)), np.zeros((4, 5)), np.zeros((4, 4)), shape=(4, 4))
    assert set(DUAL_VIEW_METHODS) == {"mesh", "idw"}


def test_camera_colours_and_dataset():
    lit = np.full((2, 3, 4, 3), np.nan, np.float32)
    lit[0] = 1.0
    lit[1, :, :2] = 3.0
    ds = xr.Dataset({"lit_image": (("sweep", "row", "col", "channel"), lit)},
                    coords={"sweep": ["u", "v"], "channel": ["R", "G", "B"]})
    col = camera_colours(ds)
    np.testing.assert_allclose(col[:, :2], 2.0)  # mean of both sweeps
    np.testing.assert_allclose(col[:, 2:], 1.0)  # only sweep u has a value
    ref = np.full((3, 4, 3), 0.5, np.float32)
    assert camera_colours(ds, reference=ref) is not None
    np.testing.assert_array_equal(camera_colours(ds, reference=ref), ref)
    out = dual_view_dataset(np.zeros((5, 6, 3), np.float32), np.zeros((5, 6), bool),
                            method="mesh", params={"max_edge": 2.0})
    assert out["dual_view"].dims == ("v", "u", "channel")
    assert out["dual_view"].dtype == np.float32 and out.attrs["resampling"] == "mesh"


def test_clipped_camera_colours_are_left_out():
    # a pixel whose channel reached the white level in either sweep has a lower bound for a
    # colour: NaN, so no dual pixel takes it, from the lit image or the reference alike
    lit = np.full((2, 3, 4, 3), 0.5, np.float32)
    saturated = np.zeros((2, 3, 4), bool)
    saturated[0, 1, 2] = saturated[1, 2, 0] = True
    ds = xr.Dataset({"lit_image": (("sweep", "row", "col", "channel"), lit),
                     "saturated": (("sweep", "row", "col"), saturated)},
                    coords={"sweep": ["u", "v"], "channel": ["R", "G", "B"]})
    ref = np.full((3, 4, 3), 0.25, np.float32)
    for col, value in ((camera_colours(ds), 0.5), (camera_colours(ds, reference=ref), 0.25)):
        missing = np.isnan(col).all(axis=2)
        assert missing[1, 2] and missing[2, 0] and missing.sum() == 2
        np.testing.assert_array_equal(col[~missing], value)
    image, coverage = resample_dual_view(camera_colours(ds), *np.meshgrid(np.arange(4.0), np.arange(3.0)),
                                         shape=(3, 4), method="idw", k=1, radius=0.1)
    assert coverage.sum() == 10 and not coverage[1, 2] and not coverage[2, 0]


def test_mesh_warp_of_exact_gt_reproduces_reciprocal_render(shared_data):
    gt = np.load(shared_data / "lab-dev" / "dev_spheres" / "gt.npz")
    # README 1.7: camera and reciprocal radiance of a Lambertian point differ by
    # (cos_L / dist_L^2) / (cos_C / dist_C^2); undo it on the camera side
    ratio = (gt["cos_C"] / gt["dist_C"] ** 2) / (gt["cos_L"] / gt["dist_L"] ** 2)
    colours = (gt["reference_linear"] * ratio[..., None]).astype(np.float32)
    img, cov = resample_dual_view(colours, gt["t_u"], gt["t_v"], shape=(96, 96), method="mesh")
    rec, vis = gt["reciprocal"], gt["dual_cam_visible"]
    # coverage: the dual pixels the camera sees, less at most a one-pixel ring of them
    assert (cov & ~vis).sum() <= 0.005 * vis.sum()
    assert (cov & vis).sum() >= 0.95 * vis.sum()
    mask = cov & vis & np.all(np.isfinite(rec), axis=2)
    est, ref = img[mask].astype(np.float64), rec[mask].astype(np.float64)
    # absolute radiometry: same scene units, so the least-squares gain is 1 within 1%
    gain = np.sum(est * ref) / np.sum(est * est)
    assert abs(gain - 1) < 0.01
    # per pixel: half the pixels agree within 1% (README 1.7 IQR 0.998-1.005); the rest
    # differ at texture/silhouette edges (centre sample vs footprint average), so the
    # relative RMSE is bounded by 10%
    per_pixel = est.sum(axis=1) / ref.sum(axis=1)
    assert np.median(np.abs(per_pixel - 1)) < 0.01
    rel_rmse = np.sqrt(np.mean((gain * est - ref) ** 2) / np.mean(ref**2))
    assert rel_rmse < 0.10


def test_front_function_resamples_the_reference_colours_into_the_dual_grid():
    from shadowcam.cameras.dual_view import dual_view_from_coords

    rows, cols = np.mgrid[0:12, 0:16].astype(np.float64)
    colours = np.stack([cols / 16, rows / 12, np.full_like(rows, 0.5)], axis=-1).astype(np.float32)
    coords = xr.Dataset({"u": (("row", "col"), cols), "v": (("row", "col"), rows),
                         "valid": (("row", "col"), np.ones(rows.shape, bool))},
                        attrs={"dual_height": 12, "dual_width": 16, "model": "uniform"})
    reference = xr.Dataset({"image": (("time", "row", "col", "channel"), np.stack([colours, colours]))})
    shadow_time = xr.Dataset(coords={"sweep": ["u", "v"], "channel": ["R", "G", "B"]})
    dataset = dual_view_from_coords(coords, shadow_time, reference=reference, density=False)
    # identity coordinates: the dual view is the camera image
    np.testing.assert_allclose(dataset["dual_view"].values, colours, atol=1e-6)
    assert dataset["coverage"].values.all()
    # with the density (the default): one camera pixel per dual pixel, the same image; the
    # centres on the grid's last row and column belong to no triangle (top-left rule)
    dense = dual_view_from_coords(coords, shadow_time, reference=reference)
    cov = dense["coverage"].values
    assert cov[:-1, :-1].all() and not cov[-1].any() and not cov[:, -1].any()
    np.testing.assert_allclose(dense["dual_view"].values[cov], colours[cov], atol=1e-6)
    assert dataset.attrs["colour_source"] == "reference" and dataset.attrs["dual_coords_model"] == "uniform"
    with pytest.raises(ValueError, match="params"):
        dual_view_from_coords(coords, shadow_time, reference=reference, no_such_option=1)
    with pytest.raises(ValueError, match="coords"):
        dual_view_from_coords(coords.isel(row=slice(0, 6)), shadow_time, reference=reference)


def test_front_function_fails_on_a_nearly_empty_dual_view():
    from shadowcam.cameras.dual_view import dual_view_from_coords

    rows, cols = np.mgrid[0:12, 0:16].astype(np.float64)
    colours = np.ones(rows.shape + (3,), np.float32)
    valid = np.zeros(rows.shape, bool)
    valid[:2, :2] = True  # a 2x2 patch of camera pixels covers ~1 of 1600 dual pixels
    coords = xr.Dataset({"u": (("row", "col"), cols), "v": (("row", "col"), rows),
                         "valid": (("row", "col"), valid)},
                        attrs={"dual_height": 40, "dual_width": 40, "model": "uniform"})
    reference = xr.Dataset({"image": (("row", "col", "channel"), colours)})
    shadow_time = xr.Dataset(coords={"sweep": ["u", "v"], "channel": ["R", "G", "B"]})
    with pytest.raises(ValueError, match=r"of 1,600 dual pixels of the 40x40 dual view covered .*4 of 192 camera "
                                         r"pixels have dual coordinates"):
        dual_view_from_coords(coords, shadow_time, reference=reference)
    dataset = dual_view_from_coords(coords, shadow_time, reference=reference, min_coverage=0)
    assert dataset["coverage"].values.sum() < 16


def _magnified(scale, angle=0.0, rows=12, cols=12):
    r, c = np.mgrid[0:rows, 0:cols].astype(float)
    ca, sa = np.cos(angle), np.sin(angle)
    return scale * (ca * c - sa * r), scale * (sa * c + ca * r)


@settings(max_examples=40, deadline=None)
@given(scale=st.floats(2.5, 8.0), angle=st.floats(-np.pi, np.pi), jump_col=st.integers(3, 8),
       jump=st.floats(4.0, 20.0))
def test_continuous_steps_keep_magnified_surfaces_and_flag_jumps(scale, angle, jump_col, jump):
    # a surface magnified `scale` times (steps longer than max_edge) is continuous everywhere;
    # a jump of `jump` steps between columns jump_col - 1 and jump_col is a discontinuity,
    # and so are the steps next to it (their neighbour across the jump disagrees)
    u, v = _magnified(scale, angle)
    valid = np.ones(u.shape, dtype=bool)
    for step in ((0, 1), (1, 0)):
        ok = continuous_steps(u, v, valid=valid, step=step)
        inside = np.zeros(u.shape, dtype=bool)
        inside[: u.shape[0] - step[0], : u.shape[1] - step[1]] = True
        assert np.array_equal(ok, inside)
    u2 = u + np.where(np.arange(u.shape[1]) >= jump_col, jump * scale, 0.0)
    ok = continuous_steps(u2, v, valid=valid, step=(0, 1))
    flagged = sorted(set(np.nonzero(~ok[:, :-1])[1].tolist()))
    assert flagged == [jump_col - 2, jump_col - 1, jump_col]
    assert continuous_steps(u2, v, valid=valid, step=(1, 0))[:-1].all()


def test_continuous_steps_short_steps_and_folds():
    # steps up to max_edge are always kept; a fold (the step turns back) is a discontinuity
    u = np.tile(np.array([0, 3, 6, 9, 6, 3, 0], float), (3, 1))
    v = np.zeros_like(u)
    valid = np.ones(u.shape, dtype=bool)
    ok = continuous_steps(u, v, valid=valid, step=(0, 1))
    assert ok[0, :6].tolist() == [True, True, False, False, True, True]
    assert continuous_steps(u / 2, v, valid=valid, step=(0, 1), max_edge=2.0)[0, :6].all()
    valid[0, 1] = False  # a step touching an invalid pixel is never continuous
    ok = continuous_steps(u, v, valid=valid, step=(0, 1))
    assert not ok[0, 0] and not ok[0, 1]
    with pytest.raises(ValueError, match="smooth_tol"):
        resample_dual_view(np.ones(u.shape + (1,)), u, v, shape=(4, 12), smooth_tol=1.5)


def test_mesh_covers_a_magnified_surface_but_not_the_gap_of_a_jump():
    # camera pixels 3 dual pixels apart (optics magnify): the warp covers every dual pixel of the
    # magnified grid; a jump of 12 dual pixels between camera columns 5 and 6 leaves that gap empty
    rows, cols = 10, 12
    u, v = _magnified(3.0, rows=rows, cols=cols)
    colours = np.ones((rows, cols, 1))
    img, cov = resample_dual_view(colours, u, v, shape=(30, 60), method="mesh")
    expected = np.zeros((30, 60), dtype=bool)
    expected[: 3 * (rows - 1) + 1, : 3 * (cols - 1) + 1] = True
    assert np.array_equal(cov, expected)
    np.testing.assert_allclose(img[cov], 1.0)
    u2 = u + np.where(np.arange(cols) >= 6, 12.0, 0.0)
    _, cov2 = resample_dual_view(colours, u2, v, shape=(30, 60), method="mesh")
    cols_covered = np.nonzero(cov2[: 3 * (rows - 1) + 1].all(axis=0))[0]
    # kept: camera columns 0..4 (steps before the one next to the jump) and 7..11 shifted by 12
    assert cols_covered.tolist() == list(range(0, 13)) + list(range(33, 46))
    assert not cov2[:, 13:33].any()


# --------------------------------------------------------------------------- camera-pixel density


def _density_view(u, v, colours, shape, **params):
    return resample_dual_view(colours, u, v, shape=shape, method="mesh", density=True, **params)


def test_density_counts_pixel_centres_on_shared_edges_and_vertices_once():
    # identity map: every dual pixel centre is a mesh vertex shared by up to six triangles
    r, c = np.mgrid[0:20, 0:20].astype(float)
    colours = np.ones((20, 20, 3), dtype=np.float32)
    img, cov = _density_view(c, r, colours, (20, 20))
    assert cov[:19, :19].all()
    np.testing.assert_allclose(img[1:19, 1:19], 1.0, rtol=1e-12)  # not 2, 3 or 6 times
    # and the plain warp is unchanged by the option's default
    plain, _ = resample_dual_view(colours, c, r, shape=(20, 20), method="mesh")
    np.testing.assert_allclose(plain[1:19, 1:19], 1.0)


@pytest.mark.parametrize("scale", [0.5, 1.7, 3.0])
def test_density_is_camera_pixels_per_dual_pixel_under_an_affine_map(scale):
    # u, v = scale * R (col, row): camera pixels per dual pixel = 1 / scale^2 exactly
    a = np.deg2rad(20.0)
    r, c = np.mgrid[0:40, 0:40].astype(float)
    u = scale * (np.cos(a) * c - np.sin(a) * r) + 30.0
    v = scale * (np.sin(a) * c + np.cos(a) * r) + 2.0
    colours = np.stack([0.2 + 0.01 * c, 0.5 + 0 * c, 0.1 + 0.002 * r], -1).astype(np.float32)
    img, cov = _density_view(u, v, colours, (64, 64))
    colour, _ = resample_dual_view(colours, u, v, shape=(64, 64), method="mesh")
    np.testing.assert_allclose(img[cov], colour[cov] / scale**2, rtol=1e-5)


def test_density_smoothing_reaches_triangles_smaller_than_a_dual_pixel():
    # Camera pixels 0.4 dual px apart (6.25 per dual pixel, as in the lab captures), dual
    # coordinates with white noise of 0.03 dual px (a timing noise of 0.03 frame): a single
    # triangle's area is off by ~15 % (each edge's two components carry sigma sqrt 2 over a
    # 0.4 step), so the density must be smoothed over the mesh around it, not only over the
    # few triangles that happen to hold a dual pixel centre.
    rng = np.random.default_rng(3)
    r, c = np.mgrid[0:120, 0:120].astype(float)
    u = 0.4 * c + 1.3 + 0.03 * rng.standard_normal(c.shape)
    v = 0.4 * r + 0.7 + 0.03 * rng.standard_normal(r.shape)
    colours = np.ones((120, 120, 3), dtype=np.float32)
    inner = (slice(4, 44), slice(4, 44))
    errors = {}
    for passes in (0, 2):
        img, cov = _density_view(u, v, colours, (50, 50), density_passes=passes)
        assert cov[inner].all()
        errors[passes] = np.sqrt(np.mean((img[inner][..., 0] / 6.25 - 1.0) ** 2))
    assert errors[0] > 0.08  # the unsmoothed areas' own noise (expected ~0.15)
    # two passes average each area over the triangles of about two camera pixels around it
    assert errors[2] < errors[0] / 3.0


def test_density_sums_the_branches_and_draws_nothing_across_the_jump():
    # two camera halves (a direct view and a mirror branch) land on overlapping dual pixels:
    # the density view is the sum of the two; triangles across the jump between the halves
    # (a step of 10 dual px between steps of 1) would add to the right branch's pixels
    r, c = np.mgrid[0:30, 0:30].astype(float)
    u = np.where(c < 15, c, 39.0 - c)  # right half: u = 24 .. 10, mirrored
    v = np.where(c < 15, r, r + 5.0)
    colours = np.stack([0.3 + 0 * c, np.where(c < 15, 1.0, 2.0), 0.1 + 0 * c], -1).astype(np.float32)
    img, cov = _density_view(u, v, colours, (40, 30))
    np.testing.assert_allclose(img[6:29, 11:14, 1], 3.0, rtol=1e-9)
    np.testing.assert_allclose(img[6:34, 15:24, 1], 2.0, rtol=1e-9)
    np.testing.assert_allclose(img[1:29, 1:10, 1], 1.0, rtol=1e-9)
    assert not cov[:, 25:].any() and not cov[35:].any()


def test_density_needs_the_mesh_warp():
    from shadowcam.cameras.dual_view import dual_view_from_coords

    coords = xr.Dataset({"u": (("row", "col"), np.zeros((4, 4))), "v": (("row", "col"), np.zeros((4, 4))),
                         "valid": (("row", "col"), np.ones((4, 4), bool))},
                        attrs={"dual_height": 4, "dual_width": 4})
    with pytest.raises(ValueError, match="density"):
        dual_view_from_coords(coords, None, reference=None, method="idw", density=True)


def _plane_hits(optics, focal, size, depth_z, pitch=1e-3):
    """Dual (u, v) (plane position / `pitch`) of the camera pixel centres of a pinhole at
    the origin looking along +z (or back along -z after a mirror), through `optics`."""
    from shadowcam.synthetic.lab.optics import trace_through_optics

    r, c = np.mgrid[0:size, 0:size].astype(float)
    x, y = (c - (size - 1) / 2) / focal, (r - (size - 1) / 2) / focal
    dirs = np.stack([x.ravel(), y.ravel(), np.ones(size * size)], 1)
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    bent = trace_through_optics(optics, np.zeros_like(dirs), dirs)
    s = (depth_z - bent.origins[:, 2]) / bent.directions[:, 2]
    hit = bent.origins + s[:, None] * bent.directions
    return hit[:, 0].reshape(size, size) / pitch, hit[:, 1].reshape(size, size) / pitch


def test_density_through_a_slab_is_the_slab_magnification():
    # a plane at depth Z behind a slab (thickness t, index n) perpendicular to the axis is
    # seen as if at Z - t (1 - 1/n) (paraxial); dual px per camera px m = (Z - t(1 - 1/n)) /
    # (f pitch), so the density view of a uniform colour is 1 / m^2 (field +-0.5 deg)
    from shadowcam.synthetic.lab.optics import GlassSlab

    focal, size, depth, thick, index, pitch = 3000.0, 40, 0.5, 0.1, 1.5, 1e-4
    slab = GlassSlab((0.0, 0.0, 0.2), (0.0, 0.0, 1.0), thick, index)
    u, v = _plane_hits((slab,), focal, size, depth, pitch)
    m = (depth - thick * (1 - 1 / index)) / (focal * pitch)
    np.testing.assert_allclose(np.diff(u, axis=1).mean(), m, rtol=1e-4)
    colours = np.ones((size, size, 3), dtype=np.float32)
    img, cov = _density_view(u + 40.0, v + 40.0, colours, (80, 80))
    assert cov.sum() > 3000
    np.testing.assert_allclose(img[cov], 1.0 / m**2, rtol=2e-4)
    direct = _density_view(*(a + 40.0 for a in _plane_hits((), focal, size, depth, pitch)), colours, (80, 80))[0]
    ratio = np.nanmedian(img[..., 0]) / np.nanmedian(direct[..., 0])
    np.testing.assert_allclose(ratio, (depth / (depth - thick * (1 - 1 / index))) ** 2, rtol=2e-4)


def test_density_in_a_flat_mirror_is_the_mirrored_camera():
    # a flat mirror at z = D sends the view back to a plane at z = -P: the mirrored camera
    # (centre at z = 2D) sees it at distance 2D + P, so m = (2D + P) / (f pitch) and the
    # colour at camera pixel (c, r) lands where the mirrored camera projects it
    from shadowcam.synthetic.lab.optics import PlaneMirror

    focal, size, dist, back = 500.0, 40, 0.2, 0.3
    mirror = PlaneMirror((0.0, 0.0, dist), (0.0, 0.0, 1.0))
    u, v = _plane_hits((mirror,), focal, size, -back)
    m = (2 * dist + back) / (focal * 1e-3)  # 1.4 dual px per camera px
    r, c = np.mgrid[0:size, 0:size].astype(float)
    np.testing.assert_allclose(u, m * (c - (size - 1) / 2), rtol=1e-9, atol=1e-9)
    colours = np.stack([0.2 + 0.01 * c, 0.4 + 0.005 * r, 0.3 + 0 * c], -1).astype(np.float32)
    img, cov = _density_view(u + 30.0, v + 30.0, colours, (60, 60))
    jj, ii = np.mgrid[0:60, 0:60]
    cc, rr = (ii - 30.0) / m + (size - 1) / 2, (jj - 30.0) / m + (size - 1) / 2  # mirrored camera
    expect = np.stack([0.2 + 0.01 * cc, 0.4 + 0.005 * rr, 0.3 + 0 * cc], -1) / m**2
    assert cov.sum() > 1000
    np.testing.assert_allclose(img[cov], expect[cov], rtol=1e-5)


@pytest.mark.parametrize("density", [False, True])
def test_three_corners_leaves_only_the_triangles_of_the_untimed_pixel(density):
    # identity map x 2, one untimed camera pixel p: the fixed diagonal loses the two quads in
    # which p lies on the diagonal (p = top-right, bottom-left); with three_corners their other
    # diagonal's triangle of the three timed pixels is drawn, so only the four triangles with
    # vertex p stay empty: the open diamond |d_row| + |d_col| < 1 camera px around p
    r, c = np.mgrid[0:8, 0:8].astype(float)
    u, v = 2.0 * c, 2.0 * r
    colours = np.stack([0.1 * c + 0.05 * r, 0.2 + 0 * c, 0.3 + 0 * c], -1).astype(np.float32)
    valid = np.ones((8, 8), dtype=bool)
    valid[3, 3] = False
    plain, cov0 = resample_dual_view(colours, u, v, shape=(15, 15), valid=valid, method="mesh",
                                     density=density)
    more, cov1 = resample_dual_view(colours, u, v, shape=(15, 15), valid=valid, method="mesh",
                                    density=density, three_corners=True)
    jj, ii = np.mgrid[0:14, 0:14]  # the last camera row and column's edges (u or v = 14)
    l1 = np.abs(jj / 2 - 3) + np.abs(ii / 2 - 3)  # are owned by no triangle under density
    if density:  # centres on the diamond's edges belong to the missing triangles or not
        assert (cov1[:14, :14] | (l1 <= 1)).all() and not (cov1[:14, :14] & (l1 < 1)).any()
    else:
        np.testing.assert_array_equal(cov1[:14, :14], l1 >= 1)
    assert (cov0 <= cov1).all() and (cov1 & ~cov0).any()
    np.testing.assert_array_equal(more[cov0], plain[cov0])
    scale = 0.25 if density else 1.0  # 1/4 camera pixel per dual pixel
    jj, ii = np.mgrid[0:15, 0:15]
    np.testing.assert_allclose(more[cov1, 0], scale * (0.1 * ii[cov1] / 2 + 0.05 * jj[cov1] / 2),
                               rtol=1e-6)


def test_front_function_carries_the_density_by_default():
    # the mesh carries the density for every camera (pixel-transport reciprocity); explicit
    # density=False gives the colours; the optics attribute does not change the choice
    from shadowcam.cameras.dual_view import dual_view_from_coords
    from shadowcam.cameras.models import capture_dual_coords

    rows, cols = np.mgrid[0:12, 0:16].astype(np.float64)
    colours = np.full(rows.shape + (3,), 0.6, np.float32)
    coords = xr.Dataset({"u": (("row", "col"), 2.0 * cols), "v": (("row", "col"), 2.0 * rows),
                         "valid": (("row", "col"), np.ones(rows.shape, bool))},
                        attrs={"dual_height": 24, "dual_width": 32, "model": "uniform"})
    reference = xr.Dataset({"image": (("row", "col", "channel"), colours)})
    shadow_time = xr.Dataset(coords={"sweep": ["u", "v"], "channel": ["R", "G", "B"]})
    plain = dual_view_from_coords(coords, shadow_time, reference=reference)
    mirror = coords.assign_attrs(optics="mirror")
    dense = dual_view_from_coords(mirror, shadow_time, reference=reference)
    colour = dual_view_from_coords(mirror, shadow_time, reference=reference, density=False)
    cov = dense["coverage"].values
    np.testing.assert_allclose(dense["dual_view"].values[cov], 0.6 / 4, rtol=1e-6)  # 1/4 px per dual px
    np.testing.assert_allclose(colour["dual_view"].values[colour["coverage"].values], 0.6, rtol=1e-6)
    np.testing.assert_array_equal(plain["dual_view"].values, dense["dual_view"].values)
    assert "camera_pixel_density" in dense.attrs and "camera_pixel_density" in plain.attrs
    assert "camera_pixel_density" not in colour.attrs
    # the dual-coords front function marks a description with optics, and only that one
    st = xr.Dataset({"shadow_time": (("sweep", "row", "col"), np.stack([cols, rows]))},
                    coords={"sweep": ["u", "v"]}, attrs={"n_frames_u": 16, "n_frames_v": 12})
    description = {"light": "point", "sweeps": [{"name": "u", "angle_deg": 0.0, "speed": 1.0},
                                                {"name": "v", "angle_deg": 90.0, "speed": 1.0}]}
    found = capture_dual_coords(st, {**description, "optics": "glass"}, camera_model="perspective")
    assert found.attrs["optics"] == "glass"
    assert "optics" not in capture_dual_coords(st, {**description, "optics": "none"},
                                               camera_model="perspective").attrs


def test_mesh_smoothing_of_the_density_stays_on_the_surface():
    from shadowcam.cameras.dual_view import mesh_smoothed_areas

    # two strips of triangles that share no vertex: a silhouette between them
    left = np.array([[0, 1, 2], [1, 3, 2], [2, 3, 4], [3, 5, 4]])
    right = left + 6
    triangles = np.concatenate([left, right])
    areas = np.array([1.0, 1.2, 0.8, 1.0, 9.0, 9.0, 9.0, 9.0])
    smoothed = mesh_smoothed_areas(triangles, areas, n_vertices=12, passes=3)
    np.testing.assert_allclose(smoothed[4:], 9.0)  # the far surface's areas are untouched
    assert smoothed[:4].max() - smoothed[:4].min() < areas[:4].max() - areas[:4].min()
    assert np.all((smoothed[:4] > 0.8) & (smoothed[:4] < 1.2))
    np.testing.assert_array_equal(mesh_smoothed_areas(triangles, areas, n_vertices=12, passes=0), areas)
    with pytest.raises(ValueError, match="passes"):
        mesh_smoothed_areas(triangles, areas, n_vertices=12, passes=-1)


def test_smoothed_density_halves_the_noise_of_noisy_coordinates():
    # an affine camera -> dual map with 0.15 dual px of coordinate noise: the density of a
    # uniform colour is 1/4 camera px per dual px; the smoothed Jacobian's density is closer
    rng = np.random.default_rng(3)
    rows, cols = np.mgrid[0:40, 0:40].astype(np.float64)
    u = 2.0 * cols + rng.normal(0, 0.15, cols.shape) + 2
    v = 2.0 * rows + rng.normal(0, 0.15, rows.shape) + 2
    colours = np.ones(rows.shape + (1,), np.float32)
    errors = {}
    for passes in (0, 2):
        img, cov = resample_dual_view(colours, u, v, shape=(84, 84), method="mesh", density=True,
                                      density_passes=passes)
        inner = cov.copy()
        inner[:8], inner[-8:], inner[:, :8], inner[:, -8:] = False, False, False, False
        errors[passes] = np.sqrt(np.mean((img[inner, 0] / 0.25 - 1) ** 2))
    assert errors[2] < 0.5 * errors[0], errors
