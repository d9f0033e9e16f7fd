"""Workflow: one kind: lightfield manifest gives the rays, renders at the configured screens,
IES and EULUMDAT files read back by independent readers, the accuracy table and the report
figures from one command; the accuracy is held to the issue's targets where they are met and
to the measured open figure where they are not (docs/benchmarks.md "Light field")."""

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

REPO = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.slow


def test_lightfield_manifest_runs_end_to_end_with_exports_and_report(tmp_path, workflow_copy, snakemake):
    workdir = workflow_copy(tmp_path / "wf")
    shutil.copy2(REPO / "data_manifest" / "synthetic_lightfield.yaml", workdir / "data_manifest")
    config = ["--config", "datasets=[synthetic_lightfield]"]
    dry = snakemake(["-n", "--quiet", "rules", *config], workdir)
    assert dry.returncode == 0, dry.stdout
    for rule in ("render_lightfield", "lightfield_hdr", "lightfield_shadow_times", "lightfield_rays",
                 "lightfield_render", "lightfield_export", "lightfield_truth", "lightfield_accuracy", "lightfield_report"):
        assert rule in dry.stdout, rule
    assert "decode" not in dry.stdout and "dual_view" not in dry.stdout
    result = snakemake(["--cores", "2", *config], workdir)
    assert result.returncode == 0, result.stdout
    out = workdir / "results" / "synthetic_lightfield" / "lightfield"

    with xr.open_dataset(out / "rays.nc") as ray_set:
        assert ray_set["direction"].dims == ("row", "col", "axis") and ray_set.sizes["row"] == 96
        assert ray_set["origin"].attrs["units"] == "mm" and ray_set["flux"].attrs["units"] == "lm"
    with xr.open_dataset(out / "renders.nc") as renders:
        assert np.allclose(renders["position"], [350.0, 675.0])  # config lightfield.render_positions_m
        assert renders["irradiance"].dims == ("position", "row", "col")
    with xr.open_dataset(out / "far_field.nc") as table:
        intensity = table["intensity"].values
        c, gamma = table["C"].values, table["gamma"].values

    photompy = pytest.importorskip("photompy")
    ies = photompy.IESFile.read(str(out / "source.ies")).photometry
    assert np.allclose(ies.thetas, gamma) and np.allclose(ies.phis, c)
    assert np.abs(np.asarray(ies.values) - intensity).max() <= 0.01 * intensity.max()
    pyldt = pytest.importorskip("pyldt")
    ldt = pyldt.LdtReader.read(out / "source.ldt")
    candela = np.asarray(ldt.intensities) * ldt.header.lamp_flux[0] * ldt.header.num_lamps[0] / 1000.0
    assert np.abs(candela - intensity).max() <= 0.01 * intensity.max()

    scores = json.loads((out / "accuracy.json").read_text())
    between, beyond = scores["renders"]["350"], scores["renders"]["675"]
    # pitch_factor 2, far anchor, rays through the mask point (config): measured 0.18 / 0.26
    # (at pitch_factor 1, the target: 0.44 / 0.42, docs/benchmarks.md)
    assert between["ratio"] <= 0.5 and beyond["ratio"] <= 0.5
    assert between["bandpass_render"] >= 0.9 and beyond["bandpass_render"] >= 0.9
    # the far field at the capture's angular resolution: measured 1.25 % (target 5 %)
    assert scores["far_field"]["median_error"] <= 0.05
    assert scores["coverage"] >= 0.5
    table_csv = (out / "accuracy.csv").read_text()
    assert "far-field intensity median |error|" in table_csv and "<= 5" in table_csv
    assert sorted(p.name for p in (out / "figures").glob("*.png")) == [
        "far_field.png", "inputs.png", "renders.png", "time_maps.png"]


def test_captured_lightfield_manifest_runs_with_bracket_times_from_the_files(
        tmp_path, workflow_copy, snakemake, make_lightfield_manifest):
    workdir = workflow_copy(tmp_path / "wf")
    _, rendered = make_lightfield_manifest(workdir / "data_manifest", name="captured_lf", shape=(48, 48),
                                           n_frames=24, quadrature=600, noise=True, exposure="metadata")
    result = snakemake(["--cores", "2", "--config", "datasets=[captured_lf]"], workdir)
    assert result.returncode == 0, result.stdout
    out = workdir / "results" / "captured_lf" / "lightfield"
    description = json.loads((out / "capture" / "capture.json").read_text())
    # DNG ExposureTime is a rational: the times read back within 1 %
    assert np.allclose(description["exposure_times"], rendered["exposure_times"], rtol=0.01)
    assert {k: len(v) for k, v in description["files"].items()} == {
        "near_h": 72, "near_v": 72, "far_h": 72, "far_v": 72}
    with xr.open_dataset(out / "rays.nc") as ray_set:
        assert (ray_set["flag"].values == 0).mean() >= 0.4
    for name in ("renders.nc", "source.ies", "source.ldt", "figures/inputs.png", "figures/time_maps.png"):
        assert (out / name).is_file(), name
    assert not (out / "accuracy.json").exists() and not (out / "truth.nc").exists()  # no ground truth when captured
