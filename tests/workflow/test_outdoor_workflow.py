"""Workflow test of the outdoor branch: the whole DAG on dev_ridge in a scratch copy.

Declared as a user would (files in place, checksummed), kind outdoor: decode ->
outdoor-normalise -> track-edges -> arrival -> pushbroom -> outdoor-accuracy ->
outdoor-figures; the lab stages are not run. Outputs are checked against the
dev data's ground truth.
"""

import json
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

REPO = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.slow  # runs the whole DAG


@pytest.fixture(scope="module")
def workdir(tmp_path_factory, shared_data, workflow_copy, snakemake):
    workdir = workflow_copy(tmp_path_factory.mktemp("outdoor"))
    manifest = yaml.safe_load((REPO / "data_manifest" / "dev_ridge.yaml").read_text())
    manifest["root"] = str(shared_data / "outdoor-dev" / "dev_ridge")  # the scratch copy is elsewhere: absolute root
    (workdir / "data_manifest" / "dev_ridge.yaml").write_text(yaml.safe_dump(manifest))
    result = snakemake(["--cores", "2", "--config", "datasets=[dev_ridge]"], workdir)
    logs = "\n".join(p.read_text()[-1500:] for p in sorted((workdir / "logs").rglob("*.log"))) \
        if (workdir / "logs").exists() else ""
    assert result.returncode == 0, result.stdout[-4000:] + logs
    return workdir


def test_outdoor_dag_runs_only_outdoor_stages(workdir):
    out = workdir / "results" / "dev_ridge"
    assert not (out / "shadow_time.nc").exists() and not (out / "dual_view.nc").exists()
    for name in ("keyframes", "edge_over_time", "arrival_map", "pushbroom"):
        assert (out / "outdoor" / "figures" / f"{name}.png").stat().st_size > 10_000
    for step in ("outdoor_normalise", "track_edges", "arrival", "pushbroom", "outdoor_accuracy", "outdoor_figures"):
        assert (workdir / "benchmarks" / "dev_ridge" / f"{step}.tsv").is_file()


def test_outdoor_outputs_carry_dims_units_and_meet_targets(workdir):
    out = workdir / "results" / "dev_ridge" / "outdoor"
    report = json.loads((out / "accuracy.json").read_text())
    assert report["all_targets_pass"] and report["condition"] == "nuisances"
    with xr.open_dataset(out / "edges.nc", engine="h5netcdf") as edges:
        assert edges["edge_row"].dims == ("time", "col") and edges["edge_row"].attrs["units"] == "pixel"
        assert {"time_s", "shift_row", "shift_col", "gain"} <= set(edges.coords)
        assert np.all(np.diff(edges["time_s"].values) > 40)  # irregular seconds, dropped frames kept as gaps
        assert "config_digest" in edges.attrs
    with xr.open_dataset(out / "arrival.nc", engine="h5netcdf") as arrival:
        assert arrival["arrival_time_s"].attrs["units"] == "s"
        assert "flag_meanings" in arrival["reason"].attrs
    with xr.open_dataset(out / "pushbroom.nc", engine="h5netcdf") as pushbroom:
        assert pushbroom["pushbroom"].dims == ("time", "col", "channel")
    assert report["pushbroom"]["median_rel_error"] < 0.05  # against the GT pushbroom after one scale
