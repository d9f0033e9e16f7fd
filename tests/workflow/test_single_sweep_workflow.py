"""Workflow: a single-sweep lab capture (the u sweep of the shared dev_spheres) runs the
shadow times, the lab shadow pushbroom and its accuracy, and plans no two-sweep stage."""

import json
from pathlib import Path

import pytest
import xarray as xr
import yaml

REPO = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.slow


def test_single_sweep_capture_gives_its_pushbroom_scored_against_ground_truth(
        tmp_path, shared_data, workflow_copy, snakemake):
    workdir = workflow_copy(tmp_path / "wf")
    manifest = yaml.safe_load((REPO / "data_manifest" / "dev_spheres_u.yaml").read_text())
    manifest["root"] = str(shared_data / "lab-dev" / "dev_spheres")  # the scratch copy is elsewhere
    (workdir / "data_manifest" / "dev_spheres_u.yaml").write_text(yaml.safe_dump(manifest))
    dry = snakemake(["-n", "--quiet", "rules", "--config", "datasets=[dev_spheres_u]"], workdir)
    assert dry.returncode == 0, dry.stdout
    assert "lab_pushbroom" in dry.stdout
    assert "dual_coords" not in dry.stdout and "dual_view" not in dry.stdout
    result = snakemake(["--cores", "2", "--config", "datasets=[dev_spheres_u]"], workdir)
    assert result.returncode == 0, result.stdout
    results = workdir / "results" / "dev_spheres_u"
    with xr.open_dataset(results / "pushbroom.nc") as broom:
        assert broom["pushbroom"].dims == ("time", "row", "channel")
        assert broom.sizes["time"] == 96 and broom.sizes["row"] == 192
        assert broom["time"].attrs["units"] == "frame" and broom["row"].attrs["units"] == "pixel"
    report = json.loads((results / "accuracy.json").read_text())
    assert set(report["shadow_time"]) == {"u"}
    assert report["pushbroom"]["coverage"] >= 0.95
    assert report["pushbroom"]["rel_rmse"] <= 0.08
    assert (results / "pushbroom.png").is_file()
    assert not (results / "dual_coords.nc").exists() and not (results / "dual_view.nc").exists()
