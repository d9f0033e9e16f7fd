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


def test_a_captured_array_manifest_runs_through_the_workflow(tmp_path, workflow_copy, snakemake, write_manifest):
    # a user's capture (files the renderer wrote elsewhere) declared in data_manifest with a
    # glob of crossings and no spacing: read, not rendered, and scored against its ground truth
    import yaml

    from shadowcam.synthetic.capture_options import capture_options
    from shadowcam.synthetic.lab.array_capture import write_array_capture

    workdir = workflow_copy(tmp_path / "wf")
    source = workdir / "data_manifest" / f"{DS}.yaml"
    doc = yaml.safe_load(source.read_text())
    doc["synthetic"].update(height=32, width=32)
    rendered = tmp_path / "render.yaml"
    rendered.write_text(yaml.safe_dump(doc))
    write_array_capture(capture_options(rendered), tmp_path / "shoot")
    write_manifest(workdir / "data_manifest" / "shot_array.yaml", {
        "name": "shot_array", "kind": "lab", "light": "point", "root": str(tmp_path / "shoot"),
        "sweeps": {"horizontal": {"files": "horizontal/*.tiff"}, "vertical": {"files": "vertical/*.tiff"}},
        "timing": {"source": "rate", "rate_hz": 1.0},
        "camera_array": {"rows": 2, "cols": 3, "crossings": "crossings/*.tiff"},
        "ground_truth": {"format": "shadowcam_array_nc", "file": "ground_truth.nc"}})
    result = snakemake(["--cores", "2", "--config", "datasets=[shot_array]"], workdir)
    assert result.returncode == 0, result.stdout[-4000:]
    assert "array_render" not in result.stdout  # nothing rendered: the files are read
    folder = workdir / "results/shot_array/array"
    with xr.open_dataset(folder / "camera_array.nc") as array:
        assert array.attrs["spacing_source"] == "estimated"
    report = json.loads((folder / "accuracy.json").read_text())
    assert np.all(np.array(report["coordinate_rmse"]) <= 0.3)
    assert report["disparity_rmse"] <= 0.3
