"""Workflow test: the wide-shadow area-light capture (synthetic_area) with its viewpoints
entry, centre and exit, scored against the renderer's exact truth (paper Fig. 13)."""

import json

import pytest

DS = "synthetic_area"
VIEWPOINTS = ("entry", "centre", "exit")
pytestmark = pytest.mark.slow  # renders and runs the lab DAG: 63 s on 2 cores, 100 s at load 5-6


def test_area_capture_viewpoints_match_their_reciprocal_renders(tmp_path, workflow_copy, snakemake):
    workdir = workflow_copy(tmp_path)
    config = ["--config", f"datasets=[{DS}]", 'dual_view={"viewpoints": ["entry", "centre", "exit"]}']
    result = snakemake(["--cores", "2", *config], workdir)
    assert result.returncode == 0, result.stdout[-4000:]
    report = json.loads((workdir / f"results/{DS}/accuracy.json").read_text())
    # dip interval against the half-depth crossings of area_truth, over the pixels whose
    # whole dip lies in the 64 frames; measured: coverage u 0.968, v 0.975; p95 entry
    # 0.337 / 0.378, centre 0.154 / 0.238, exit 0.366 / 0.346 frame (entry / exit off by the
    # lit level's residual bias, docs/benchmarks.md)
    for sweep in ("u", "v"):
        interval = report["interval"][sweep]
        assert interval["n_truth"] > 1500
        assert interval["coverage"] >= 0.95
        assert interval["centre"]["p95"] <= 0.3
        assert interval["entry"]["p95"] <= 0.45 and interval["exit"]["p95"] <= 0.45
    # each viewpoint's dual view against its own reciprocal render after one gain: measured
    # relative RMSE 0.236 / 0.235 / 0.235 (the main dual view's 0.235; the 48 px camera
    # splatted onto the 64 x 64 dual grid), coverage of what the camera sees 0.82 / 0.78 /
    # 0.78. Against the other viewpoints' renders the same views score 0.51-0.61: the
    # renders differ by the wire's width, and the bound below separates them.
    for name in VIEWPOINTS:
        scores = report["viewpoints"][name]
        assert scores["rel_rmse_masked"] <= 0.3, (name, scores)
        assert scores["coverage_of_visible"] >= 0.7, (name, scores)
    assert (workdir / f"results/{DS}/figures/viewpoints.png").is_file()
