"""Ground truth of a rendered light field (shadowcam.synthetic.lightfield.truth), written once for accuracy and report."""

import numpy as np
import pytest
import xarray as xr

from shadowcam.lightfield.accuracy import lightfield_accuracy
from shadowcam.lightfield.photometry_export import far_field_grid
from shadowcam.synthetic.lightfield.source import ReflectorSource
from shadowcam.synthetic.lightfield.truth import truth_dataset


@pytest.fixture(scope="module")
def source_rays():
    """The source's own ray tubes as a rays dataset (32 x 32 mask points), and renders at two planes."""
    source = ReflectorSource()
    x, y, flux = source.quadrature(32)
    direction = source.rays(x, y).reshape(32, 32, 3)
    ray_set = xr.Dataset({"direction": (("row", "col", "axis"), direction), "flux": (("row", "col"), flux.reshape(32, 32))},
                         attrs={"near_position_mm": 250.0, "far_position_mm": 450.0, "near_pitch_mm": 1.25,
                                "far_pitch_mm": 2.25})
    renders = xr.Dataset({"irradiance": (("position", "row", "col"), np.zeros((2, 24, 20))),
                          "pixel_size": (("position",), [2.5, 4.0])}, coords={"position": [675.0, 350.0]})
    return source, ray_set, renders


def test_truth_is_the_sources_irradiance_per_render_grid_and_its_far_field_on_the_rays_chart(source_rays):
    source, ray_set, renders = source_rays
    truth = truth_dataset(source, renders, ray_set)
    # each plane in the renders' order, at its own pitch
    for k, (z, pitch) in enumerate([(675.0, 2.5), (350.0, 4.0)]):
        expected = source.irradiance(centre=(0, 0, z), shape=(24, 20), pixel_size=pitch)
        assert np.array_equal(truth["irradiance"].values[k], expected)
    # the capture's angular resolution: (1.25 + 2.25) mm over 200 mm
    assert np.isclose(truth.attrs["resolution_deg"], np.degrees(3.5 / 200.0))
    estimate = far_field_grid(direction=ray_set["direction"].values, flux=ray_set["flux"].values,
                              resolution_deg=truth.attrs["resolution_deg"])
    assert truth["far_field"].shape == estimate.shape  # the chart the accuracy step compares on
    # its flux: every quadrature tube of the source lies on the chart (lm = cd sr)
    cell = np.radians(truth.attrs["resolution_deg"]) ** 2
    assert np.isclose(truth["far_field"].values.sum() * cell, source.quadrature(768)[2].sum(), rtol=1e-9)


def test_truth_dataset_names_what_is_missing(source_rays):
    source, ray_set, renders = source_rays
    with pytest.raises(ValueError, match="renders lacks the variables \\['pixel_size'\\]: write it with lightfield-render"):
        truth_dataset(source, renders.drop_vars("pixel_size"), ray_set)


def test_accuracy_rejects_a_truth_not_on_the_renders_grids(source_rays):
    _, _, renders = source_rays
    with pytest.raises(ValueError, match="truth must have shape"):
        lightfield_accuracy(renders, np.ones((5, 5)), [], np.zeros((2, 20, 24)), far_truth=np.ones((5, 5)),
                            flags=np.zeros((4, 4)))
