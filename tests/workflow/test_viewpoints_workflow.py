"""Workflow tests of dual_view.viewpoints: one Snakemake run (module fixture) of the small
lab capture (synthetic_tiny: one dual view per viewpoint across the dip interval) and the
wide-shadow area-light capture (synthetic_area: each viewpoint against its own reciprocal
render, paper Fig. 13), asking only for the files the assertions read."""

import csv
import json

import numpy as np
import pytest
import xarray as xr

TINY, AREA = "synthetic_tiny", "synthetic_area"
VIEWPOINTS = ("entry", "centre", "exit")
pytestmark = pytest.mark.slow  # renders and runs the lab DAG of both datasets


@pytest.fixture(scope="module")
def viewpoint_run(tmp_path_factory, workflow_copy, snakemake):
    """The workdir after one run of both datasets with the three viewpoints."""
    workdir = workflow_copy(tmp_path_factory.mktemp("viewpoints"))
    targets = [f"results/{TINY}/shadow_time.nc", f"results/{TINY}/accuracy.json",
               *(f"results/{TINY}/viewpoints/{name}/dual_view.png" for name in VIEWPOINTS),
               f"results/{AREA}/accuracy.json", f"results/{AREA}/figures"]
    # the outer viewpoints are asked of both: the thin-wire capture (a point light) has none
    config = ["--config", f"datasets=[{TINY},{AREA}]",
              'dual_view={"viewpoints": ["entry", "centre", "exit", "penumbra_first", "penumbra_last"]}']
    result = snakemake(["--cores", "2", *config, "--", *targets], workdir)
    assert result.returncode == 0, result.stdout[-4000:]
    return workdir


def test_each_viewpoint_gets_its_shadow_times_and_dual_view(viewpoint_run):
    workdir = viewpoint_run
    with xr.open_dataset(workdir / f"results/{TINY}/shadow_time.nc") as main:
        entry, exit_ = main["interval_entry"].values, main["interval_exit"].values
    for name, fraction in (("entry", 0.0), ("exit", 1.0), ("centre", 0.5)):
        folder = workdir / f"results/{TINY}/viewpoints/{name}"
        with xr.open_dataset(folder / "shadow_time.nc") as view:
            np.testing.assert_allclose(view["shadow_time"].values, entry + fraction * (exit_ - entry),
                                       rtol=1e-6, equal_nan=True)
            assert view.attrs["viewpoint_fraction"] == fraction
        for stem in ("dual_coords.nc", "dual_view.nc", "dual_view.png"):
            assert (folder / stem).is_file()
    # the exit view sees each point later in each sweep than the entry view: its dual
    # coordinates are larger by the interval's length
    with xr.open_dataset(workdir / f"results/{TINY}/viewpoints/entry/dual_coords.nc") as a, \
            xr.open_dataset(workdir / f"results/{TINY}/viewpoints/exit/dual_coords.nc") as b:
        shift = (b["u"] - a["u"]).values
    assert np.nanmedian(shift) > 0.5
    # a point light has no extreme points: no outer viewpoints are made for it
    assert not (workdir / f"results/{TINY}/viewpoints/penumbra_first").exists()


def test_area_capture_viewpoints_match_their_reciprocal_renders(viewpoint_run):
    workdir = viewpoint_run
    report = json.loads((workdir / f"results/{AREA}/accuracy.json").read_text())
    # dip interval against the continuous disc's exact times (area_truth), over the pixels
    # whose whole dip lies in the 64 frames; the wide dips' half-hidden crossings and outer
    # edges from the penumbra law. Measured: coverage u 0.972, v 0.978; p95 entry 0.083 /
    # 0.071, centre 0.079 / 0.060, exit 0.084 / 0.069, first contact 0.088 / 0.080, last
    # release 0.090 / 0.069 frame (target 0.2)
    for sweep in ("u", "v"):
        interval = report["interval"][sweep]
        assert interval["n_truth"] > 1500
        assert interval["coverage"] >= 0.95 and interval["outer_coverage"] >= 0.95
        for part in ("entry", "centre", "exit", "first", "last"):
            assert interval[part]["p95"] <= 0.2, (sweep, part, interval[part])
    # each viewpoint's dual view (mesh carrying the camera-pixel density) against its own
    # reciprocal render after one gain: measured relative RMSE 0.131 / 0.125 / 0.125 (the
    # main dual view's 0.126), coverage of what the camera sees 0.87 / 0.86 / 0.85 (dips cut by
    # the sweep's ends timed from one crossing). Against the other viewpoints' renders
    # (which differ by the wire's width) the views scored 0.51-0.61 on the 4 x 4-sample render:
    # the bound separates them.
    # the views from the disc's extreme points (penumbra law's outer edges): measured 0.134 /
    # 0.127, coverage 0.84 / 0.79
    for name in VIEWPOINTS + ("penumbra_first", "penumbra_last"):
        scores = report["viewpoints"][name]
        assert scores["rel_rmse_masked"] <= 0.2, (name, scores)
        assert scores["coverage_of_visible"] >= 0.7, (name, scores)
    assert (workdir / f"results/{AREA}/figures/viewpoints.png").is_file()
    # the table (accuracy.csv, shown as figures/accuracy.html) has the same two sections
    with open(workdir / f"results/{AREA}/accuracy.csv", newline="") as handle:
        table = {row["quantity"]: row for row in csv.DictReader(handle)}
    for name in VIEWPOINTS:
        row = table[f"dual view relative RMSE, GT valid mask, viewpoint {name}"]
        assert float(row["value"]) == pytest.approx(100 * report["viewpoints"][name]["rel_rmse_masked"], rel=5e-3)
    for sweep in ("u", "v"):
        row = table[f"dip interval centre |error| p95, sweep {sweep}"]
        assert float(row["value"]) == pytest.approx(report["interval"][sweep]["centre"]["p95"], rel=5e-3)
    html = (workdir / f"results/{AREA}/figures/accuracy.html").read_text()
    assert "dip interval centre |error| p95, sweep u" in html and "viewpoint exit" in html
