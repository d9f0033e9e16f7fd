"""The sky mask computed once per sweep: the same mask, and bit-identical first-pass parts."""

import numpy as np
import pytest
import xarray as xr

from shadowcam.outdoor.datasets import sky_mask_dataset
from shadowcam.outdoor.photometry import photometry_from_frames, sweep_sky_mask
from shadowcam.outdoor.sky_mask import auto_sky_mask
from shadowcam.synthetic.outdoor.capture import render_outdoor_capture
from shadowcam.synthetic.outdoor.render import make_outdoor_scene


@pytest.fixture(scope="module")
def store():
    capture = render_outdoor_capture(make_outdoor_scene(seed=3, height=48, width=72), frames=12, supersample=1,
                                     seed=3, cloud=False)
    return xr.Dataset({"image": (("time", "row", "col", "channel"), capture.frames)},
                      coords={"time_s": ("time", capture.times_s), "exposure_s": ("time", np.full(12, 0.004))})


def test_the_sweep_mask_is_the_automatic_mask_of_the_first_frame(store):
    mask, source = sweep_sky_mask(store, {"name": "x"}, sky_params={"min_blue_fraction": 0.36})
    assert source == "auto" and mask.dtype == bool
    np.testing.assert_array_equal(mask, auto_sky_mask(store["image"].values[0], min_blue_fraction=0.36))
    assert 0 < mask.sum() < mask.size  # sky above the ridge, terrain below


@pytest.mark.parametrize("part", [(0, 6), (6, 12)])
def test_a_time_part_given_the_sweep_mask_is_identical_to_one_computing_it(store, part):
    mask, source = sweep_sky_mask(store, {"name": "x"})
    own = photometry_from_frames(store, part=part)
    given = photometry_from_frames(store, part=part, sky=mask, sky_source=source)
    xr.testing.assert_identical(given, own)


def test_the_mask_dataset_holds_the_mask_and_its_source():
    mask = np.array([[True, False], [False, False]])
    dataset = sky_mask_dataset(mask, source="auto")
    np.testing.assert_array_equal(dataset["sky_mask"].values.astype(bool), mask)
    assert dataset.attrs["sky_source"] == "auto"
    with pytest.raises(ValueError, match="mask"):
        sky_mask_dataset(mask[0], source="auto")
