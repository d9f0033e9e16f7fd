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
