"""Restart safety: a run killed mid-way and started again ends identical to an uninterrupted run.

* A decode job killed with SIGKILL leaves only a hidden temporary beside the store, which
  no reader takes for a store; rerunning removes it and writes the same store as an
  uninterrupted decode.
* A join of part stores that fails half-way leaves nothing behind.
* The workflow (tiny synthetic capture, decoded and tracked in 2 time chunks per sweep) is interrupted
  twice -- one running decode job is killed, then Snakemake itself with all its jobs --
  and restarted; its frame stores and shadow times equal those of direct, uninterrupted
  ``shadowcam decode`` / ``shadowcam shadow-time`` calls on the same capture.
"""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from shadowcam.io import frame_store
from shadowcam.io.frame_store import merge_frame_stores, open_frames, write_frames

DS = "synthetic_tiny"
BIN = Path(sys.executable).parent  # this environment's shadowcam and snakemake
pytestmark = pytest.mark.slow  # kills and restarts the CLI and the workflow
SWEEPS = ("u", "v", "cal_u", "cal_v")
PARTS = {"decode": {"chunk_frames": 6, "chunks_per_job": 2}}


def wait_for(predicate, *, timeout=120.0, what="condition"):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        found = predicate()
        if found:
            return found
        time.sleep(0.02)
    raise AssertionError(f"timed out waiting for {what}")


def group_processes(pgid, *words):
    """Pids in process group `pgid` whose command line contains all `words`."""
    pids = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            cmdline = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except OSError:
            continue
        if int(stat.rsplit(")", 1)[1].split()[2]) == pgid and all(w in cmdline for w in words):
            pids.append(int(entry.name))
    return pids


def test_killed_decode_leaves_no_store_and_rerun_is_identical(tmp_path, make_frames, sweep_manifest):
    paths, expected = make_frames(tmp_path / "data" / "u", 60, shape=(256, 256, 3))
    manifest = sweep_manifest(tmp_path, rate_hz=1.0)
    out = tmp_path / "u.zarr"
    command = [str(BIN / "shadowcam"), "decode", "--manifest", str(manifest), "--sweep", "u",
               "--chunk-frames", "2", "--out", str(out)]
    job = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:  # kill it once it has written some chunks, mid-way through the sweep
        wait_for(lambda: any(tmp_path.glob(".u.zarr.*.tmp/image/c/1")) or job.poll() is not None,
                 what="the first chunks")
        assert job.poll() is None, "decode finished before it could be killed; make the sweep longer"
        job.send_signal(signal.SIGKILL)
    finally:
        job.wait()
    assert not out.exists() and len(list(tmp_path.glob(".u.zarr.*.tmp"))) == 1
    with pytest.raises(ValueError, match="unfinished write"):
        open_frames(out)
    assert subprocess.run(command, capture_output=True).returncode == 0  # the rerun
    assert not list(tmp_path.glob(".u.zarr.*")), "the rerun removes the killed job's temporary"
    np.testing.assert_array_equal(open_frames(out)["image"].values, expected)


def test_failed_merge_leaves_nothing(tmp_path, monkeypatch, make_frames):
    paths, _ = make_frames(tmp_path / "frames", 8)
    times = np.arange(8.0)
    parts = [write_frames(paths[s:s + 4], tmp_path / f"p{s}.zarr", times_s=times[s:s + 4], chunk_frames=2,
                          first_frame=s) for s in (0, 4)]
    calls, real_link = [], frame_store._link

    def failing_link(source, target):
        calls.append(target)
        if len(calls) == 3:
            raise OSError("disk full")
        real_link(source, target)

    monkeypatch.setattr(frame_store, "_link", failing_link)
    with pytest.raises(OSError, match="disk full"):
        merge_frame_stores(parts, tmp_path / "u.zarr")
    assert not (tmp_path / "u.zarr").exists() and not list(tmp_path.glob(".u.zarr.*"))
    assert all(p.is_dir() for p in parts), "the parts are untouched and can be merged again"


def start_workflow(workdir):
    env = dict(os.environ, PATH=f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}")
    return subprocess.Popen(
        [str(BIN / "snakemake"), "--profile", "profiles/local", "--configfile", "config/config.yaml",
         "parts.yaml", "--config", f"datasets=[{DS}]", "--", f"results/{DS}/shadow_time.nc"],
        cwd=workdir, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        start_new_session=True,
    )


def test_workflow_killed_and_restarted_equals_uninterrupted(tmp_path, workflow_copy, snakemake):
    workdir = workflow_copy(tmp_path / "wf")
    (workdir / "parts.yaml").write_text(yaml.safe_dump(PARTS))
    frames = workdir / "results" / DS / "frames"

    # 1. kill one running decode_part job: Snakemake reports it failed and stops
    run = start_workflow(workdir)
    victim = wait_for(lambda: group_processes(run.pid, "shadowcam", "decode", "--frames"), what="a decode job")[0]
    os.kill(victim, signal.SIGKILL)
    output = run.communicate(timeout=300)[0]
    assert run.returncode != 0, output[-2000:]
    assert not (workdir / "results" / DS / "shadow_time.nc").exists()

    # 2. restart, then kill Snakemake and all its jobs while sweeps are being decoded
    run = start_workflow(workdir)
    wait_for(lambda: list(frames.glob("*.parts/*.zarr")) or run.poll() is not None, what="a finished part")
    os.killpg(run.pid, signal.SIGKILL)
    run.communicate(timeout=60)
    assert not (workdir / "results" / DS / "shadow_time.nc").exists(), "killed too late to test a restart"

    # 3. restart once more (a killed Snakemake leaves its lock: --unlock, as after a crash)
    assert snakemake(["--unlock", "--cores", "1", "--config", f"datasets=[{DS}]"], workdir).returncode == 0
    run = start_workflow(workdir)
    output = run.communicate(timeout=600)[0]
    assert run.returncode == 0, output[-4000:]
    assert not list((workdir / "results").rglob(".*.tmp")) and not list(frames.glob("*.parts"))

    # uninterrupted reference: one decode per sweep and shadow-time, called directly
    reference = tmp_path / "reference"
    manifest = workdir / "results" / DS / "capture" / "capture.json"
    shadowcam = str(BIN / "shadowcam")
    for sweep in SWEEPS:
        subprocess.run([shadowcam, "decode", "--manifest", str(manifest), "--sweep", sweep, "--chunk-frames", "6",
                        "--out", str(reference / f"{sweep}.zarr")], check=True, capture_output=True)
        xr.testing.assert_identical(open_frames(reference / f"{sweep}.zarr").load(),
                                    open_frames(frames / f"{sweep}.zarr").load())
    subprocess.run([shadowcam, "shadow-time", "--frames", *(str(reference / f"{s}.zarr") for s in SWEEPS),
                    "--sweeps", *SWEEPS, "--method", "edge_fit", "--params", '{"min_coverage": 0.01}',
                    "--manifest", str(manifest), "--out", str(reference / "shadow_time.nc")],
                   check=True, capture_output=True)
    with xr.open_dataset(reference / "shadow_time.nc", engine="h5netcdf") as a, \
            xr.open_dataset(workdir / "results" / DS / "shadow_time.nc", engine="h5netcdf") as b:
        xr.testing.assert_identical(a.load(), b.load())
