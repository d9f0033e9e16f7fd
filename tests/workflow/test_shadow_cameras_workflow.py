"""Workflow: the paper's shadow cameras, each described by a data manifest, render and run
through the dual stages to accuracy.json (small, noise-free renders), and a single-sweep lab
capture (the u sweep of the shared dev_spheres) gives its shadow pushbroom. One Snakemake run
for all of them (module fixture), asking only for the files the assertions read."""

import json
import math
import shutil
from pathlib import Path

import pytest
import xarray as xr
import yaml

from shadowcam.io.capture_plan import capture_plan

pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[2]

#: dataset -> camera model the plan must choose (the light decides the projection)
CAMERAS = {
    "synthetic_orthographic": "orthographic",
    "synthetic_ortho_primal": "perspective",
    "synthetic_intrinsics": "linear",
    "synthetic_cross_slit": "cross_slit",
    "synthetic_mirror": "perspective",
    "synthetic_glass": "perspective",
}
SINGLE = "dev_spheres_u"  # single-sweep lab capture of the shared data
#: dataset -> shadow-time p95 bound (frames) u, v: the workflow's figures with the dips taken
#: from the pixels' flux centroids to their centres (docs/benchmarks.md), plus 0.005
P95_BOUND = {
    "synthetic_orthographic": (0.05, 0.035),
    "synthetic_ortho_primal": (0.06, 0.065),
    "synthetic_intrinsics": (0.045, 0.05),
    "synthetic_cross_slit": (0.045, 0.085),
    "synthetic_mirror": (0.235, 0.055),
    "synthetic_glass": (0.125, 0.08),
}


@pytest.fixture(scope="module")
def camera_run(tmp_path_factory, shared_data, workflow_copy, snakemake):
    """The workdir after one run of every camera dataset and the single-sweep capture (and
    ``planned_single.txt``: the rules a dry run of the single-sweep capture alone plans)."""
    workdir = workflow_copy(tmp_path_factory.mktemp("cameras") / "wf")
    for ds in CAMERAS:
        shutil.copy2(REPO / "data_manifest" / f"{ds}.yaml", workdir / "data_manifest")
    manifest = yaml.safe_load((REPO / "data_manifest" / f"{SINGLE}.yaml").read_text())
    manifest["root"] = str(shared_data / "lab-dev" / "dev_spheres")  # the scratch copy is elsewhere
    (workdir / "data_manifest" / f"{SINGLE}.yaml").write_text(yaml.safe_dump(manifest))
    # what the single-sweep capture plans by default, before anything is built
    dry = snakemake(["-n", "--quiet", "rules", "--config", f"datasets=[{SINGLE}]"], workdir)
    assert dry.returncode == 0, dry.stdout
    (workdir / "planned_single.txt").write_text(dry.stdout)
    datasets = ",".join([*CAMERAS, SINGLE])
    targets = [*(f"results/{ds}/accuracy.json" for ds in [*CAMERAS, SINGLE]),
               f"results/{SINGLE}/pushbroom.nc", f"results/{SINGLE}/pushbroom.png"]
    result = snakemake(["--cores", "2", "--config", f"datasets=[{datasets}]", "--", *targets],
                       workdir)
    assert result.returncode == 0, result.stdout[-4000:]
    return workdir


def test_every_shadow_camera_runs_from_its_manifest_to_accuracy(camera_run):
    workdir = camera_run
    for ds, model in CAMERAS.items():
        results = Path(workdir) / "results" / ds
        planned = capture_plan(Path(workdir) / "data_manifest" / f"{ds}.yaml")
        rendered = capture_plan(results / "capture" / "capture.json")
        assert planned.camera_model == rendered.camera_model == model, ds
        assert {n: s.n_frames for n, s in rendered.sweeps.items()} == \
            {n: s.n_frames for n, s in planned.sweeps.items()}, ds
        report = json.loads((results / "accuracy.json").read_text())
        for sweep in ("u", "v"):
            stats = report["shadow_time"][sweep]
            # measured 0.974 (glass v) to 0.999 (orthographic v); the rest of the lit pixels
            # are cast-shadow boundary pixels (low_contrast), several_minima and wide dips
            assert stats["coverage"] >= 0.97, (ds, sweep)
            # the silhouette pixels' times say they are uncertain; they stay in the p95
            assert 0 <= stats["n_uncertain"] < stats["n_evaluated"], (ds, sweep)
            assert stats["p95_confident"] <= stats["p95"], (ds, sweep)
            assert stats["p95"] <= P95_BOUND[ds]["uv".index(sweep)], (ds, sweep, stats["p95"])
            assert {"shadow_time_p95_frames", "shadow_time_coverage"} <= {
                t["target"] for t in report["targets"] if t["sweep"] == sweep}
        assert math.isfinite(report["dual_coords"]["rmse"]), ds
        if model == "cross_slit":  # the virtual pixel is the pair of times: <= 0.3 dual px
            assert report["dual_coords"]["rmse"] <= 0.3


def test_intrinsics_from_a_slanted_sweep(camera_run):
    workdir = camera_run
    intrinsics = capture_plan(Path(workdir) / "results" / "synthetic_intrinsics" / "capture"
                              / "capture.json")
    assert intrinsics.timed_sweeps == ("u", "v", "s")
    # the slanted sweep's slant and speed measured from the shadow times alone
    report = json.loads((Path(workdir) / "results" / "synthetic_intrinsics" / "accuracy.json")
                        .read_text())
    rows = {t["target"]: t for t in report["targets"] if t["sweep"] == "s"}
    assert rows["sweep_angle_error_deg"]["value"] <= 0.5 and rows["sweep_angle_error_deg"]["pass"]
    assert rows["sweep_speed_rel_error"]["value"] <= 0.01 and rows["sweep_speed_rel_error"]["pass"]
    # the linear camera's own grid (48 x 48 mask plane): its dual RMSE and the gain of sweep s
    coords_model = report["dual_model"]["model"]
    assert coords_model == "linear" and report["dual_coords"]["rmse"] <= 0.3, report["dual_coords"]
    redundancy = report["redundancy"]
    assert redundancy["sweeps_two"] == "u v" and redundancy["rmse_all"] <= redundancy["rmse_two"]


def test_mirror_and_glass_keep_straight_lines_straight_in_the_dual_view(camera_run):
    workdir = camera_run
    # straight squares' edges seen through the mirror / glass: dual view <= 0.5 px RMS
    for ds in ("synthetic_mirror", "synthetic_glass"):
        report = json.loads((Path(workdir) / "results" / ds / "accuracy.json").read_text())
        row = next(t for t in report["targets"] if t["target"] == "dual_straightness_rms_px")
        assert report["straightness"]["n_edges"] >= 6 and row["value"] <= 0.5 and row["pass"], ds
        # the dual image scored where the camera sees the dual point through the optics
        dual_image = report["dual_image"]
        assert dual_image["n_mask"] >= 300 and dual_image["covered_not_visible"] <= 0.03, ds
        # the optics magnify: triangles kept from the camera-side continuity, not their dual
        # size; measured coverage mirror 0.804, glass 0.724 (covered where not visible 0.009,
        # 0.025; dual RMS straightness 0.11, 0.22 px)
        assert dual_image["coverage_of_visible"] >= 0.65, (ds, dual_image)


def test_orthographic_camera_keeps_parallel_edges_parallel(camera_run):
    workdir = camera_run
    # orthographic: long parallel edges on two depth layers (panels scene) measured in the
    # estimated dual view: the targets (0.5 deg, 1%) against the perspective contrast of the
    # same scene (exact: 6.0 deg, ratio 1.24). Measured with the open shutter: spread 0.394
    # deg, size ratio 0.99986, 10 edges in the family. The spread is 22 of its standard errors
    # (0.018 deg), so it is a systematic tilt between the estimated edges, not their noise
    # (exact coordinates: 0.000 deg): an open problem in docs/benchmarks.md, bounded here by
    # the target only
    ortho = json.loads((Path(workdir) / "results" / "synthetic_orthographic" / "accuracy.json")
                       .read_text())
    found = ortho["parallelism"]
    assert found["n_families"] == 2 and found["size_edges"] >= 8, found
    assert found["spread_deg"] <= 0.5 and abs(found["size_ratio"] - 1) <= 0.01, found
    assert {"dual_parallel_spread_deg", "dual_size_ratio_error"} <= {
        t["target"] for t in ortho["targets"]}


def test_single_sweep_capture_plans_its_pushbroom_and_no_two_sweep_stage(camera_run):
    planned = (camera_run / "planned_single.txt").read_text()
    assert "lab_pushbroom" in planned
    assert "dual_coords" not in planned and "dual_view" not in planned


def test_single_sweep_capture_gives_its_pushbroom_scored_against_ground_truth(camera_run):
    results = camera_run / "results" / SINGLE
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
