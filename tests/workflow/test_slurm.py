"""The whole workflow through a live SLURM scheduler equals a local run.

A single-node SLURM cluster is started on this machine by ``scripts/slurm_cluster.sh``
(root, Debian packages slurm-wlm and munge) and stopped afterwards (unless it was
already running). The tiny synthetic capture is processed twice:

* locally (``profiles/local``) with the default decode (one part per sweep);
* through ``snakemake --profile profiles/slurm`` (executor slurm) with every sweep
  split into two time chunks (decode_part and shadow_time_chunk jobs),

and every product must be identical, so the test checks both the SLURM executor and
that time-chunked decoding changes nothing. Jobs must really have gone through SLURM:
each submitted job has a SLURM job id in Snakemake's log and a SLURM log file, and
``squeue`` reports it COMPLETED.

Skipped (with the reason) where SLURM cannot be started: not root, packages missing, or
the daemons do not come up. ``SHADOWCAM_REQUIRE_SLURM=1`` (set by ``.ci/run``) turns
those skips into failures.
"""

import json
import os
import re
import shutil
import subprocess
import time
from pathlib import Path

import pytest
import xarray as xr
import yaml

from shadowcam.io.frame_store import open_frames

pytestmark = [pytest.mark.slurm, pytest.mark.slow]

REPO = Path(__file__).resolve().parents[2]
SCRIPT = REPO / "scripts" / "slurm_cluster.sh"
DS = "synthetic_tiny"
SWEEPS = ("u", "v", "cal_u", "cal_v")
# 24 frames per sweep in parts of 6 x 2 frames: 2 decode_part and 2 shadow_time_chunk jobs per sweep
PARTS = {"decode": {"chunk_frames": 6, "chunks_per_job": 2}}
RESULTS = ("shadow_time.nc", "dual_coords.nc", "dual_view.nc")


def unavailable(reason):
    """Skip, or fail where SLURM is required (CI)."""
    if os.environ.get("SHADOWCAM_REQUIRE_SLURM") == "1":
        pytest.fail(f"SLURM required (SHADOWCAM_REQUIRE_SLURM=1) but {reason}")
    pytest.skip(reason)


@pytest.fixture(scope="module")
def cluster():
    """A running single-node SLURM cluster (started and stopped here unless already up)."""
    if os.geteuid() != 0:
        unavailable("the SLURM test starts munged/slurmctld/slurmd and needs root")
    if not all(shutil.which(tool) for tool in ("slurmctld", "slurmd", "munged", "sbatch")):
        unavailable("Debian packages slurm-wlm and munge are not installed "
                    "(apt-get install -y slurm-wlm munge; .ci/run does it)")
    was_running = subprocess.run([str(SCRIPT), "status"], capture_output=True).returncode == 0
    env = dict(os.environ, SLURM_CLUSTER_INSTALL="0")
    started = subprocess.run([str(SCRIPT), "start"], env=env, capture_output=True, text=True, timeout=180)
    if started.returncode != 0:
        unavailable(f"the SLURM cluster did not start: {started.stderr.strip()[-500:]}")
    yield
    if not was_running:
        subprocess.run([str(SCRIPT), "stop"], check=True, capture_output=True, timeout=120)


def run_workflow(snakemake, workdir, *args):
    """Run the whole DAG of `DS` in `workdir`; return (stdout, wall seconds)."""
    start = time.perf_counter()
    result = snakemake([*args, "--config", f"datasets=[{DS}]"], workdir, timeout=900)
    seconds = time.perf_counter() - start
    assert result.returncode == 0, result.stdout[-5000:]
    return result.stdout, seconds


@pytest.fixture(scope="module")
def runs(cluster, tmp_path_factory, workflow_copy, snakemake):
    """(local workdir, SLURM workdir, SLURM stdout, wall times)."""
    local = workflow_copy(tmp_path_factory.mktemp("local"))
    _, local_s = run_workflow(snakemake, local, "--profile", "profiles/local")
    remote = workflow_copy(tmp_path_factory.mktemp("slurm"))
    (remote / "parts.yaml").write_text(yaml.safe_dump(PARTS))
    stdout, slurm_s = run_workflow(snakemake, 
        remote, "--profile", "profiles/slurm", "--configfile", "config/config.yaml", "parts.yaml",
        # the status poll interval grows while nothing finishes; poll fast for seconds-long jobs
        "--slurm-init-seconds-before-status-checks", "2",
    )
    print(f"\nsynthetic_tiny whole workflow: local {local_s:.0f} s, SLURM {slurm_s:.0f} s")
    return local, remote, stdout, {"local": local_s, "slurm": slurm_s}


def test_jobs_went_through_slurm(runs):
    _, remote, stdout, _ = runs
    job_ids = re.findall(r"has been submitted with SLURM jobid (\d+)", stdout)
    # render, decode_reference, 8 decode_part, 4 decode (joins), 8 shadow_time_chunk,
    # shadow_time and the per-dataset tail group: 24 SLURM jobs; `all` runs locally
    assert len(job_ids) == 1 + 1 + 4 * 2 + 4 + 4 * 2 + 1 + 1, stdout[-3000:]
    logs = {p.stem for p in (remote / "logs" / "slurm").rglob("*.log")}
    assert set(job_ids) <= logs, "every SLURM job leaves its log under logs/slurm"
    states = subprocess.run(["squeue", "-h", "-t", "all", "-j", ",".join(job_ids), "-o", "%i %T"],
                            capture_output=True, text=True, check=True).stdout.split("\n")
    seen = dict(line.split() for line in states if line.strip())
    assert seen == {job: "COMPLETED" for job in job_ids}


def same_results(a, b, *, ignore=()):
    """Identical datasets, but for run times (attrs ``*_seconds``) and the attrs in `ignore`."""
    def strip(ds):
        ds = ds.copy()
        for holder in [ds, *ds.variables.values()]:
            holder.attrs = {k: v for k, v in holder.attrs.items() if not k.endswith("_seconds") and k not in ignore}
        return ds

    xr.testing.assert_identical(strip(a), strip(b))


def test_slurm_results_equal_local_run(runs):
    local, remote, _, _ = runs
    for name in RESULTS:
        with xr.open_dataset(local / "results" / DS / name, engine="h5netcdf") as a, \
                xr.open_dataset(remote / "results" / DS / name, engine="h5netcdf") as b:
            same_results(a.load(), b.load())
    for sweep in SWEEPS:  # chunked decode through SLURM == one-job local decode
        a, b = (open_frames(w / "results" / DS / "frames" / f"{sweep}.zarr").load() for w in (local, remote))
        # all but the recorded decode option chunk_frames (16 locally, 6 through SLURM)
        same_results(a, b, ignore=("config", "config_digest"))
    accuracy = [json.loads((w / "results" / DS / "accuracy.json").read_text()) for w in (local, remote)]
    for doc in accuracy:  # sha256 of the input files: dual_view.nc records its own run time
        assert set(doc.pop("inputs")) == {f"results/{DS}/{name}" for name in RESULTS}
    assert accuracy[0] == accuracy[1]
    assert not list((remote / "results").rglob(".*.tmp")), "no half-written store left behind"
