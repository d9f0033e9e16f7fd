"""Workflow test: a several-lights manifest renders and gives one shadow camera per light."""

import json

import pytest
import xarray as xr

DS = "synthetic_lights"
pytestmark = pytest.mark.slow  # renders and runs the several-lights DAG


def test_one_shadow_camera_per_light_with_accuracy_and_figure(tmp_path, workflow_copy, snakemake):
    workdir = workflow_copy(tmp_path)
    result = snakemake(["--cores", "2", "--config", f"datasets=[{DS}]"], workdir)
    assert result.returncode == 0, result.stdout[-4000:]
    folder = workdir / f"results/{DS}/lights"
    with xr.open_dataset(folder / "light_views.nc") as views:
        assert views.sizes["light"] == 3 and views["dual_view"].dims == ("light", "v", "u", "channel")
    lights = json.loads((folder / "accuracy.json").read_text())["lights"]
    # the two point lights in both sweeps and the tube along the u sweep's wire
    for k, sweep in ((0, "u"), (0, "v"), (1, "u"), (1, "v"), (2, "u")):
        assert lights[k][sweep]["coverage"] > 0.8 and lights[k][sweep]["p95_error"] < 0.35
    # the tube across the v sweep's wire: its shadow's contrast is low; flagged, not guessed
    across = lights[2]["v"]
    assert across["contrast"] < 0.1 and across["coverage"] < 0.05
    assert (folder / "lights.png").stat().st_size > 0


def test_the_rendered_capture_is_a_folder_of_frame_files_with_its_truth(tmp_path, workflow_copy, snakemake):
    workdir = workflow_copy(tmp_path)
    target = f"results/{DS}/lights/capture/capture.json"
    result = snakemake(["--cores", "1", "--config", f"datasets=[{DS}]", "--", target], workdir)
    assert result.returncode == 0, result.stdout[-4000:]
    folder = workdir / f"results/{DS}/lights/capture"
    described = json.loads((folder / "capture.json").read_text())
    assert described["lights"]["kinds"] == ["point", "point", "tube"]
    assert len(list((folder / "frames_u").glob("*.tiff"))) == 48 and (folder / "reference.tiff").is_file()
    with xr.open_dataset(folder / "ground_truth.nc") as truth:
        assert truth["t_center_u"].dims == ("light", "y", "x") and truth.sizes["light"] == 3


def test_a_captured_several_lights_manifest_runs_through_the_workflow(tmp_path, workflow_copy, snakemake,
                                                                      write_manifest):
    # a user's capture (files the renderer wrote elsewhere) declared in data_manifest with a
    # lights block (positions in mm): read, not rendered, and scored against its ground truth
    import yaml

    from shadowcam.synthetic.capture_options import capture_options
    from shadowcam.synthetic.lab.light_set_capture import write_light_set_capture

    workdir = workflow_copy(tmp_path / "wf")
    doc = yaml.safe_load((workdir / "data_manifest" / f"{DS}.yaml").read_text())
    doc["synthetic"].update(height=32, width=32)
    rendered = tmp_path / "render.yaml"
    rendered.write_text(yaml.safe_dump(doc))
    shoot = write_light_set_capture(capture_options(rendered), tmp_path / "shoot")
    along = json.loads((shoot / "capture.json").read_text())["lights"]
    write_manifest(workdir / "data_manifest" / "shot_lights.yaml", {
        "name": "shot_lights", "kind": "lab", "light": "point", "root": str(shoot),
        "sweeps": {"u": {"files": "frames_u/*.tiff"}, "v": {"files": "frames_v/*.tiff"}},
        "reference": "reference.tiff", "timing": {"source": "rate", "rate_hz": 1.0},
        "lights": {"kinds": ["point", "point", "tube"],
                   **{f"light_along_{s}": [1e3 * x for x in along[f"light_along_{s}"]] for s in "uv"}},
        "ground_truth": {"format": "shadowcam_lights_nc", "file": "ground_truth.nc"}})
    folder = workdir / "results/shot_lights/lights"
    result = snakemake(["--cores", "2", "--config", "datasets=[shot_lights]"], workdir)
    # nothing rendered: the files are read
    assert result.returncode == 0 and "lights_render" not in result.stdout, result.stdout[-4000:]
    attrs = xr.load_dataset(folder / "light_views.nc").attrs
    assert attrs["light_order"] == "described" and attrs["order_checked"] == 1
    lights = json.loads((folder / "accuracy.json").read_text())["lights"]
    for k, sweep in ((0, "u"), (0, "v"), (1, "u"), (1, "v"), (2, "u")):
        assert lights[k][sweep]["coverage"] > 0.8 and lights[k][sweep]["p95_error"] < 0.35
