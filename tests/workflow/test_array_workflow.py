"""Workflow test: a camera-array manifest renders, builds its array and scores it."""

import json

import numpy as np
import pytest
import xarray as xr

DS = "synthetic_array"
pytestmark = pytest.mark.slow  # renders and runs the array DAG


def test_camera_array_dataset_accuracy_and_figure(tmp_path, workflow_copy, snakemake):
    workdir = workflow_copy(tmp_path)
    result = snakemake(["--cores", "2", "--config", f"datasets=[{DS}]"], workdir)
    assert result.returncode == 0, result.stdout[-4000:]
    folder = workdir / f"results/{DS}/array"
    with xr.open_dataset(folder / "camera_array.nc") as array:
        assert array["view"].dims == ("camera_row", "camera_col", "v", "u", "channel")
        assert array["view"].shape[:2] == (2, 3)
    report = json.loads((folder / "accuracy.json").read_text())
    # the manifest's noise-free 48 x 48 render: every camera within 0.3 dual px
    assert np.all(np.array(report["coordinate_rmse"]) <= 0.3)
    assert np.all(np.array(report["coverage"]) > 0.7)
    assert max(report["u_rmse_per_column"] + report["v_rmse_per_row"]) <= 0.3
    assert report["disparity_rmse"] <= 0.3
    assert (folder / "views.png").stat().st_size > 0
