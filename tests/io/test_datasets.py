"""Tests of shadowcam.io.datasets: one writer, provenance carried forward."""

import json

import numpy as np
import pytest
import xarray as xr

from shadowcam.io.datasets import (
    merge_input_checksums,
    open_dataset,
    read_attrs,
    write_dataset,
    write_netcdf,
)


def _dataset(checksums=None):
    ds = xr.Dataset({"a": (("row",), np.arange(3, dtype=np.float32))})
    if checksums is not None:
        ds.attrs["input_checksums"] = json.dumps(checksums)
    return ds


def test_merge_input_checksums_unions_inputs_then_extra():
    first = _dataset({"raw/1.dng": "aa", "raw/2.dng": "bb"})
    second = _dataset({"raw/3.dng": "cc"})
    merged = merge_input_checksums(first, second.attrs, _dataset(),
                                   checksums={"shadow_time.nc": "dd", "raw/1.dng": "ee"})
    assert merged == {"raw/1.dng": "ee", "raw/2.dng": "bb", "raw/3.dng": "cc", "shadow_time.nc": "dd"}


def test_write_dataset_attaches_provenance_and_round_trips(tmp_path):
    path = tmp_path / "out" / "x.nc"
    written = write_dataset(_dataset(), path, config={"k": 2}, step="demo",
                            inputs=(_dataset({"raw/1.dng": "aa"}),), checksums={"in.nc": "bb"})
    back = open_dataset(path)
    np.testing.assert_array_equal(back["a"].values, [0, 1, 2])
    assert json.loads(back.attrs["input_checksums"]) == {"in.nc": "bb", "raw/1.dng": "aa"}
    assert json.loads(back.attrs["config"]) == {"k": 2}
    assert back.attrs["step"] == "demo" == written.attrs["step"]
    assert read_attrs(path)["config_digest"] == written.attrs["config_digest"]
    assert sorted(p.name for p in path.parent.iterdir()) == ["x.nc"]


def test_write_netcdf_keeps_attrs_as_they_are(tmp_path):
    ds = _dataset().assign_attrs(note="kept")
    write_netcdf(ds, tmp_path / "x.nc")
    back = open_dataset(tmp_path / "x.nc")
    assert back.attrs == {"note": "kept"}


def test_missing_input_dataset_names_the_file(tmp_path):
    with pytest.raises(ValueError, match="missing.nc"):
        open_dataset(tmp_path / "missing.nc")
    with pytest.raises(ValueError, match="missing.nc"):
        read_attrs(tmp_path / "missing.nc")
