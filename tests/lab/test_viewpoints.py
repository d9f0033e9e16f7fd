"""Tests of the viewpoint shadow times across the dip interval."""

import numpy as np
import pytest
import xarray as xr

from shadowcam.lab.viewpoints import VIEWPOINTS, shadow_time_at, viewpoint_fraction


def _dataset(entry, exit_, entry_std=0.1, exit_std=0.2):
    dims = ("sweep", "row", "col")
    shape = (1,) + np.shape(entry)
    data = {name: (dims, np.broadcast_to(np.asarray(value, np.float32), shape).copy(), {"units": "frame"})
            for name, value in (("interval_entry", entry), ("interval_exit", exit_),
                                ("interval_entry_std", entry_std), ("interval_exit_std", exit_std),
                                ("shadow_time", 0.5 * (np.asarray(entry) + np.asarray(exit_))),
                                ("time_std", 0.1), ("confidence", 1.0))}
    return xr.Dataset(data, coords={"sweep": ["u"]})


@pytest.mark.parametrize("viewpoint, fraction", [("entry", 0.0), ("centre", 0.5), ("exit", 1.0), (0.25, 0.25),
                                                 ("0.75", 0.75)])
def test_the_time_is_the_fraction_across_the_interval(viewpoint, fraction):
    entry = np.array([[10.0, 20.5], [np.nan, 3.0]])
    exit_ = np.array([[18.0, 21.5], [7.0, 11.0]])
    out = shadow_time_at(_dataset(entry, exit_), viewpoint)
    expected = entry + fraction * (exit_ - entry)
    np.testing.assert_allclose(out["shadow_time"].values[0], expected, rtol=1e-6)
    np.testing.assert_allclose(out["time_std"].values[0, 0, 0], np.hypot((1 - fraction) * 0.1, fraction * 0.2),
                               rtol=1e-6)
    assert out["confidence"].values[0, 1, 0] == 0  # no entry: no time
    assert out.attrs["viewpoint_fraction"] == fraction
    assert viewpoint_fraction(viewpoint) == fraction


def test_named_viewpoints():
    assert VIEWPOINTS == {"entry": 0.0, "centre": 0.5, "exit": 1.0}


@pytest.mark.parametrize("bad", ["middle", 1.5, -0.1, None])
def test_unknown_viewpoints_are_refused(bad):
    with pytest.raises(ValueError, match="viewpoint"):
        viewpoint_fraction(bad)


def test_a_dataset_without_intervals_says_what_to_do():
    ds = _dataset([[1.0]], [[2.0]]).drop_vars(["interval_entry", "interval_exit"])
    with pytest.raises(ValueError, match="recompute it"):
        shadow_time_at(ds, "entry")


@pytest.mark.parametrize("viewpoint, start", [("penumbra_first", 0.0), ("penumbra_last", 1.0)])
def test_outer_viewpoints_take_the_penumbras_outer_edges(viewpoint, start):
    entry, exit_ = np.array([[10.0, 20.5]]), np.array([[18.0, 28.5]])
    ds = _dataset(entry, exit_)
    outer = {"penumbra_first": entry - 3.0, "penumbra_last": exit_ + 3.0}
    for name, value in outer.items():
        ds[name] = (("sweep", "row", "col"), value[None].astype(np.float32))
        ds[f"{name}_std"] = (("sweep", "row", "col"), np.full((1, 1, 2), 0.05 if name.endswith("first") else 0.07,
                                                              np.float32))
    out = shadow_time_at(ds, viewpoint)
    np.testing.assert_allclose(out["shadow_time"].values[0], outer[viewpoint])
    np.testing.assert_allclose(out["time_std"].values[0], 0.05 if start == 0.0 else 0.07, rtol=1e-6)
    assert viewpoint_fraction(viewpoint) == start
    # a capture whose dips were not wide has no outer edges
    with pytest.raises(ValueError, match="penumbra law"):
        shadow_time_at(_dataset(entry, exit_), viewpoint)
