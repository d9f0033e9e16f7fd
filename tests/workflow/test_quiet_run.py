"""A small workflow run says only what is the user's business, and still reruns what changed.

Step logs carry no zarr warning about Snakemake's ``.snakemake_timestamp``; the dry run
does not print every frame of a sweep on one line; a changed frame decodes its sweep again.
"""

import os
import time

import numpy as np
import pytest

pytestmark = pytest.mark.slow

FRAMES = 30


@pytest.fixture
def capture_workdir(tmp_path, workflow_copy, write_image, write_manifest):
    workdir = workflow_copy(tmp_path / "wf")
    rng = np.random.default_rng(3)
    for sweep in ("u", "v"):
        for k in range(FRAMES):
            path = workdir / "data" / sweep / f"frame_{k:04d}.png"
            path.parent.mkdir(parents=True, exist_ok=True)
            write_image(path, rng.integers(0, 65536, (6, 8, 3)).astype(np.uint16))
    write_manifest(workdir / "data_manifest" / "quiet.yaml", {
        "name": "quiet", "kind": "lab", "light": "point", "root": "../data",
        "sweeps": {"u": {"files": "u/*.png", "axis": "u"}, "v": {"files": "v/*.png", "axis": "v"}},
        "timing": {"source": "rate", "rate_hz": 2.0}, "provenance": "test", "licence": "CC0-1.0"})
    return workdir


def test_logs_dry_run_and_rerun(capture_workdir, snakemake):
    target = ["results/quiet/frames/u.zarr", "--config", "datasets=[quiet]"]
    # two decode parts, so that `decode` opens part stores Snakemake has stamped
    (capture_workdir / "parts.yaml").write_text("decode: {chunk_frames: 4, chunks_per_job: 4}\n")
    config = ["--configfile", "config/config.yaml", "parts.yaml"]
    run = snakemake(["--cores", "1", *target, *config], capture_workdir)
    assert run.returncode == 0, run.stdout[-3000:]
    logs = sorted((capture_workdir / "logs" / "quiet").glob("decode_u*.log"))
    assert len(logs) == 3
    for log in logs:
        assert ".snakemake_timestamp" not in log.read_text(), log.read_text()

    dry = snakemake(["-n", "--cores", "1", "--config", "datasets=[quiet]", *config], capture_workdir)
    assert dry.returncode == 0, dry.stdout[-3000:]
    crowded = max(dry.stdout.splitlines(), key=lambda line: line.count("frame_0"))
    assert crowded.count("frame_0") <= 1, crowded  # no line lists the frames of a sweep
    assert "Nothing to be done" in snakemake(["-n", *target, *config], capture_workdir).stdout

    frame = capture_workdir / "data" / "u" / "frame_0005.png"
    later = time.time() + 60
    os.utime(frame, (later, later))
    again = snakemake(["-n", *target, *config], capture_workdir)
    assert "rule decode:" in again.stdout and "rule decode_part:" in again.stdout, again.stdout[-3000:]
