"""Plan-time facts of job sizes: part counts beyond four digits, capped chunks, a memory ceiling."""

import os
import re

import numpy as np
import pytest

pytestmark = pytest.mark.slow


def _dry_run(snakemake, workdir, ds, *config):
    return snakemake(["-n", "--cores", "1", "--config", f"datasets=[{ds}]", *config], workdir)


def _mem_mb(stdout, rule):
    """mem_mb of every job of `rule` in a dry run's job listing."""
    jobs = re.split(r"\n(?=\[.*\]\nrule |rule )", stdout)
    return [int(re.search(r"mem_mb=(\d+)", job).group(1)) for job in jobs if job.lstrip("[").find(f"rule {rule}:") >= 0
            and re.search(r"mem_mb=(\d+)", job)]


def test_ten_thousand_and_one_parts_are_planned(tmp_path, workflow_copy, write_image, write_manifest, snakemake):
    workdir = workflow_copy(tmp_path / "wf")
    folder = workdir / "data" / "frames"
    folder.mkdir(parents=True)
    first = write_image(folder / "000000.png", np.full((4, 4, 3), 100, np.uint8))
    for index in range(1, 10001):
        os.link(first, folder / f"{index:06d}.png")
    write_manifest(workdir / "data_manifest" / "long.yaml", {
        "name": "long", "kind": "outdoor", "light": "distant", "root": "../data",
        "sweeps": {"timelapse": {"files": "frames/*.png"}}, "timing": {"source": "rate", "rate_hz": 1.0},
    })
    result = _dry_run(snakemake, workdir, "long", "decode={chunk_frames: 1, chunks_per_job: 1}")
    assert result.returncode == 0, result.stdout[-3000:]
    assert re.search(r"^decode_part\s+10001$", result.stdout, re.MULTILINE), result.stdout[-3000:]
    assert "timelapse.parts/10000.zarr" in result.stdout and "timelapse.parts/9999.zarr" in result.stdout


def test_chunk_longer_than_the_sweep_sizes_jobs_like_the_sweep(tmp_path, workflow_copy, snakemake):
    workdir = workflow_copy(tmp_path / "wf")
    # synthetic_tiny: 24 frames per sweep
    whole = _dry_run(snakemake, workdir, "synthetic_tiny", "decode={chunk_frames: 24, chunks_per_job: 1}")
    huge = _dry_run(snakemake, workdir, "synthetic_tiny", "decode={chunk_frames: 1000000, chunks_per_job: 1}")
    assert whole.returncode == 0 and huge.returncode == 0, huge.stdout[-3000:]
    for rule in ("decode_part", "shadow_time_chunk"):
        assert _mem_mb(huge.stdout, rule) and _mem_mb(huge.stdout, rule) == _mem_mb(whole.stdout, rule)


def test_a_job_above_the_memory_ceiling_stops_the_plan(tmp_path, workflow_copy, snakemake):
    workdir = workflow_copy(tmp_path / "wf")
    result = _dry_run(snakemake, workdir, "synthetic_tiny", "max_job_mem_mb=400")
    assert result.returncode != 0
    assert ("error: dataset 'synthetic_tiny' (data_manifest/synthetic_tiny.yaml): frames of 48 x 48 pixels "
            "(0.0023 MP) need ") in result.stdout, result.stdout[-3000:]
    assert "above max_job_mem_mb 400 MB (config)" in result.stdout
    assert "Traceback" not in result.stdout and "Job stats" not in result.stdout


def test_sweep_joined_in_groups_equals_a_single_decode(tmp_path, workflow_copy, snakemake):
    import subprocess
    import sys
    from pathlib import Path

    import xarray as xr

    from shadowcam.io.frame_store import open_frames

    workdir = workflow_copy(tmp_path / "wf")
    parts = workdir / "workflow" / "rules" / "parts.smk"
    text = parts.read_text()
    assert "\nPARTS_PER_GROUP = 100\n" in text
    parts.write_text(text.replace("\nPARTS_PER_GROUP = 100\n", "\nPARTS_PER_GROUP = 5\n"))
    store = "results/synthetic_tiny/frames/u.zarr"  # 24 frames: 12 parts of 2, in 3 groups
    result = snakemake(["--cores", "1", "--config", "datasets=[synthetic_tiny]",
                        "decode={chunk_frames: 2, chunks_per_job: 1}", "--", store], workdir)
    assert result.returncode == 0, result.stdout[-3000:]
    assert re.search(r"^decode_group\s+3$", result.stdout, re.MULTILINE), result.stdout[-3000:]
    reference = tmp_path / "u.zarr"
    subprocess.run([str(Path(sys.executable).parent / "shadowcam"), "decode", "--manifest",
                    str(workdir / "results/synthetic_tiny/capture/capture.json"), "--sweep", "u",
                    "--chunk-frames", "2", "--out", str(reference)], check=True, capture_output=True)
    xr.testing.assert_identical(open_frames(reference).load(), open_frames(workdir / store).load())
    assert not (workdir / "results/synthetic_tiny/frames/u.groups").exists()
