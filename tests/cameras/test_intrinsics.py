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
