#!/usr/bin/env python
"""Wall time of planning (``snakemake -n``) a long sweep at one frame per decode part.

    .venv/bin/python scripts/benchmark_planning.py [--frames 10000] [--kind lab|outdoor]
        [--chunk-frames 1 --chunks-per-job 1] [--repeat 1] [--keep DIR]

Writes a capture of `--frames` tiny (4x4) 8-bit PNG frames per sweep (lab: sweeps u and v;
outdoor: one time-lapse sweep) and its manifest (with checksums) into a scratch folder
under $TMPDIR, copies the workflow beside it and times ``snakemake -n --cores 1`` of the
dataset with ``decode.chunk_frames`` and ``decode.chunks_per_job`` as given (default one
frame per part: one decode_part job per frame). Prints the jobs planned and the wall time
(best of --repeat). Run with PYTHONPATH set to the repository under test.
"""

import argparse
import re
import shutil
import subprocess
import sys
import tempfile
import time
import zlib
from pathlib import Path

import numpy as np
import yaml

REPO = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
WORKFLOW_FILES = ("Snakefile", "workflow", "config", "profiles")


def _png(pixels):
    """Bytes of an 8-bit RGB PNG of `pixels` ((rows, cols, 3) uint8), without an image library."""
    rows, cols, _ = pixels.shape

    def chunk(kind, data):
        body = kind + data
        return len(data).to_bytes(4, "big") + body + zlib.crc32(body).to_bytes(4, "big")

    raw = b"".join(b"\x00" + pixels[r].tobytes() for r in range(rows))
    header = rows.to_bytes(4, "big")
    header = cols.to_bytes(4, "big") + header + bytes([8, 2, 0, 0, 0])
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def make_capture(folder, *, frames, kind, seed=0):
    """Write the frames and data_manifest/plan.yaml (with checksums) under `folder`."""
    from shadowcam.io.manifest import checksums_for

    rng = np.random.default_rng(seed)
    sweeps = ("u", "v") if kind == "lab" else ("timelapse",)
    for sweep in sweeps:
        (folder / "capture" / sweep).mkdir(parents=True)
        for k in range(frames):
            pixels = rng.integers(0, 256, (4, 4, 3), dtype=np.uint8)
            (folder / "capture" / sweep / f"{k:06d}.png").write_bytes(_png(pixels))
    doc = {
        "name": "plan",
        "kind": kind,
        "light": "point" if kind == "lab" else "distant",
        "root": "../capture",
        "sweeps": {s: {"files": f"{s}/*.png"} for s in sweeps},
        "timing": {"source": "rate", "rate_hz": 1.0},
    }
    path = folder / "data_manifest" / "plan.yaml"
    path.parent.mkdir(parents=True)
    path.write_text(yaml.safe_dump(doc))
    path.write_text(yaml.safe_dump({**doc, "checksums": checksums_for(path)}))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--frames", type=int, default=10000)
    parser.add_argument("--kind", choices=("lab", "outdoor"), default="lab")
    parser.add_argument("--chunk-frames", type=int, default=1)
    parser.add_argument("--chunks-per-job", type=int, default=1)
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--keep", type=Path, help="work in this folder and keep it")
    args = parser.parse_args(argv)
    folder = args.keep or Path(tempfile.mkdtemp(prefix="shadowcam-plan-"))
    try:
        if not (folder / "data_manifest" / "plan.yaml").is_file():
            make_capture(folder, frames=args.frames, kind=args.kind)
        for name in WORKFLOW_FILES:
            target = folder / name
            if target.exists():
                shutil.rmtree(target) if target.is_dir() else target.unlink()
            source = REPO / name
            copy = shutil.copytree if source.is_dir() else shutil.copy2
            copy(source, target)
        overrides = folder / "plan_config.yaml"
        overrides.write_text(yaml.safe_dump({
            "datasets": ["plan"],
            "decode": {"chunk_frames": args.chunk_frames, "chunks_per_job": args.chunks_per_job},
        }))
        command = [str(BIN / "snakemake"), "-n", "--cores", "1", "--configfile", "config/config.yaml", overrides.name]
        best = None
        for _ in range(args.repeat):
            start = time.perf_counter()
            result = subprocess.run(command, cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            elapsed = time.perf_counter() - start
            if result.returncode:
                sys.exit(f"snakemake -n failed:\n{result.stdout[-3000:]}")
            best = elapsed if best is None else min(best, elapsed)
        total = re.search(r"^total\s+(\d+)", result.stdout, re.MULTILINE)
        print(f"{args.kind}, {args.frames} frames per sweep, chunk_frames {args.chunk_frames}, "
              f"chunks_per_job {args.chunks_per_job}: {total.group(1) if total else '?'} jobs planned "
              f"in {best:.1f} s (snakemake -n, best of {args.repeat})")
    finally:
        if args.keep is None:
            shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
