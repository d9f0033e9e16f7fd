"""Virtual intrinsics (Fig. 12): a slanted third sweep and unequal speeds give a skewed,
stretched virtual camera; measured from rendered frames, skew = slant within 0.5 deg and
stretch = speed ratio within 1%; the chosen output intrinsics are what the output shows."""

import numpy as np
import pytest

from shadowcam.cameras.intrinsics import (
    apply_affine,
    intrinsics_affine,
    measure_skew_stretch,
    resample_to_intrinsics,
)
from shadowcam.cameras.models import camera_coords_from_shadow_time

SIZE = {"scene": "tabletop", "seed": 3, "height": 40, "width": 40, "frames": 32}
SWEEPS = [{"name": "u"}, {"name": "v", "angle_deg": 90},
          {"name": "w", "angle_deg": 30, "speed": 1.25}]


@pytest.mark.parametrize("pair, slant", [(("u", "w"), 60.0), (("v", "w"), 30.0),
                                         (("u", "v"), 0.0)])
def test_measured_skew_is_the_slant_and_stretch_the_speed_ratio(timed_capture, pair, slant):
    _, gt, shadow_time, _ = timed_capture({**SIZE, "sweeps": SWEEPS})
    measured = [shadow_time["shadow_time"].sel(sweep=n).values for n in pair]
    found = measure_skew_stretch(*measured, gt["t_u"].values, gt["t_v"].values)
    speeds = {"u": 1.0, "v": 1.0, "w": 1.25}
    assert abs(found["skew_deg"] - slant) <= 0.5, found
    assert abs(found["stretch"] / (speeds[pair[1]] / speeds[pair[0]]) - 1) <= 0.01, found


@pytest.mark.parametrize("skew, aspect", [(0.0, 1.0), (20.0, 1.0), (-35.0, 0.5), (10.0, 2.0)])
def test_chosen_intrinsics_are_the_outputs_geometry(skew, aspect):
    affine, shape = intrinsics_affine((24, 32), skew_deg=skew, aspect=aspect)
    v, u = np.mgrid[0:24, 0:32].astype(np.float64)
    x, y = apply_affine(affine, u, v)
    # the output columns lean by the skew; rows are scaled by the aspect
    found = measure_skew_stretch(x, y, u, v)
    assert abs(found["skew_deg"] - abs(skew)) < 1e-9
    assert abs(found["stretch"] - np.hypot(1.0, np.tan(np.radians(skew))) / aspect) < 1e-9
    # the whole dual grid (pixel edges included) lies inside the output
    assert x.min() >= -0.5 and y.min() >= -0.5 and x.max() <= shape[1] - 0.5 and y.max() <= shape[0] - 0.5


def test_dual_view_resampled_to_chosen_intrinsics(timed_capture):
    description = {**SIZE, "sweeps": SWEEPS}
    _, gt, shadow_time, reference = timed_capture(description)
    coords = camera_coords_from_shadow_time(shadow_time, description)
    affine, shape = intrinsics_affine((32, 32), skew_deg=25.0)
    image, coverage = resample_to_intrinsics(reference, coords["u"].values, coords["v"].values,
                                             affine=affine, shape=shape,
                                             valid=coords["valid"].values)
    assert image.shape == (*shape, 3) and coverage.astype(bool).mean() > 0.3  # a parallelogram in its box
    x, y = apply_affine(affine, coords["u"].values, coords["v"].values)
    found = measure_skew_stretch(x, y, gt["t_u"].values, gt["t_v"].values)
    assert abs(found["skew_deg"] - 25.0) <= 0.5


@pytest.mark.parametrize("options, message", [({"skew_deg": 85.0}, "skew_deg"),
                                              ({"aspect": 0.0}, "aspect"),
                                              ({"scale": -1.0}, "scale")])
def test_bad_intrinsics_are_refused(options, message):
    with pytest.raises(ValueError, match=message):
        intrinsics_affine((8, 8), **options)


def test_coords_on_chosen_intrinsics_map_the_grid_corners_exactly():
    import xarray as xr

    from shadowcam.cameras.dual_coords import dual_coords_dataset
    from shadowcam.cameras.intrinsics import coords_to_intrinsics

    v, u = np.mgrid[0:20, 0:30].astype(np.float64)
    coords = dual_coords_dataset(u, v, np.ones(u.shape, bool), method="linear",
                                 info={"model": "linear", "dual_height": 20, "dual_width": 30})
    out = coords_to_intrinsics(coords, skew_deg=30.0, aspect=2.0)
    t = np.tan(np.radians(30.0))
    # bounding box of the mapped grid: width 30 + 20 tan(30), height 2 x 20
    assert (out.attrs["dual_height"], out.attrs["dual_width"]) == (40, int(np.ceil(30 + 20 * t)))
    x, y = out["u"].values, out["v"].values
    # column axis leans by the skew, rows stretched by the aspect, grid centred
    np.testing.assert_allclose(x[5, 7] - x[4, 7], t, atol=1e-5)
    np.testing.assert_allclose(x[4, 8] - x[4, 7], 1.0, atol=1e-5)
    np.testing.assert_allclose(y[5, 7] - y[4, 7], 2.0, atol=1e-5)
    np.testing.assert_allclose((x.min() + x.max()) / 2, (out.attrs["dual_width"] - 1) / 2, atol=1e-4)
    np.testing.assert_allclose((y.min() + y.max()) / 2, (40 - 1) / 2, atol=1e-4)
    assert isinstance(out, xr.Dataset) and out.attrs["intrinsics_affine"].shape == (6,)
    sized = coords_to_intrinsics(coords, size=(24, 36))
    assert (sized.attrs["dual_height"], sized.attrs["dual_width"]) == (24, 36)
    with pytest.raises(ValueError, match="skew_deg"):
        coords_to_intrinsics(coords, skew_deg=85.0)
    with pytest.raises(ValueError, match="size"):
        coords_to_intrinsics(coords, size=(24,))
