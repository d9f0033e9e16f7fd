#!/usr/bin/env python
"""Wall time of decoding one sweep in one job vs in time-part jobs, on this machine.

    .venv/bin/python scripts/benchmark_decode_parts.py [--rows 2000 --cols 3000 --frames 48]
        [--chunk-frames 4 --chunks-per-job 3 --cores 2 --repeat 2]

Writes a capture of seeded 12-bit RGGB DNG frames (uncompressed, like the renderer's) and
its manifest into a scratch folder under $TMPDIR, then runs the workflow's decode of the
sweep (``results/bench/frames/u.zarr``) with ``snakemake --cores CORES``: once with one
decode_part job for the whole sweep, once split into parts of chunk_frames x
chunks_per_job frames, and prints the wall times (best of --repeat) and the speed-up.
Other processes on the machine make the figures noisy.
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

from shadowcam.io.manifest import checksums_for
from shadowcam.io.raw_writer import write_dng

REPO = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


def make_capture(folder, *, rows, cols, frames, seed=0):
    """Write `frames` DNGs and data_manifest/bench.yaml (with checksums) under `folder`."""
    rng = np.random.default_rng(seed)
    (folder / "capture").mkdir(parents=True)
    for k in range(frames):
        mosaic = rng.integers(256, 4095, (rows, cols), dtype=np.uint16)
        write_dng(folder / "capture" / f"{k:06d}.dng", mosaic, bit_depth=12, black_level=256)
    doc = {"name": "bench", "kind": "lab", "light": "point", "root": "../capture",
           "sweeps": {"u": {"files": "*.dng", "axis": "u"}, "v": {"files": "*.dng", "axis": "v"}},
           "timing": {"source": "rate", "rate_hz": 1.0}}
    manifest = folder / "data_manifest" / "bench.yaml"
    manifest.parent.mkdir()
    manifest.write_text(yaml.safe_dump(doc))
    manifest.write_text(yaml.safe_dump({**doc, "checksums": checksums_for(manifest)}))


def decode_seconds(folder, *, chunk_frames, chunks_per_job, cores):
    """Wall seconds of a fresh decode of sweep u with the given part size."""
    (folder / "parts.yaml").write_text(yaml.safe_dump(
        {"decode": {"chunk_frames": chunk_frames, "chunks_per_job": chunks_per_job}}))
    shutil.rmtree(folder / "results", ignore_errors=True)
    env = dict(os.environ, PATH=f"{BIN}{os.pathsep}{os.environ['PATH']}")
    start = time.perf_counter()
    subprocess.run([str(BIN / "snakemake"), "--profile", "profiles/local", "--cores", str(cores),
                    "--configfile", "config/config.yaml", "parts.yaml", "--config", "datasets=[bench]",
                    "--", "results/bench/frames/u.zarr"], cwd=folder, env=env, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rows", type=int, default=2000)
    parser.add_argument("--cols", type=int, default=3000)
    parser.add_argument("--frames", type=int, default=48)
    parser.add_argument("--chunk-frames", type=int, default=4)
    parser.add_argument("--chunks-per-job", type=int, default=3)
    parser.add_argument("--cores", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="shadowcam-bench-"))
    try:
        for name in ("Snakefile", "workflow", "config", "profiles"):
            (shutil.copytree if (REPO / name).is_dir() else shutil.copy2)(REPO / name, folder / name)
        make_capture(folder, rows=args.rows, cols=args.cols, frames=args.frames)
        whole, parts = (
            min(decode_seconds(folder, chunk_frames=args.chunk_frames, chunks_per_job=per_job, cores=args.cores)
                for _ in range(args.repeat))
            for per_job in (10**6, args.chunks_per_job))
        per_part = args.chunk_frames * args.chunks_per_job
        jobs = -(-args.frames // per_part)
        print(f"decode of one sweep: {args.frames} DNG frames of {args.rows}x{args.cols} (12-bit), "
              f"--cores {args.cores}, chunk_frames {args.chunk_frames}; load {os.getloadavg()[0]:.1f} "
              f"on {os.cpu_count()} CPUs")
        print(f"  1 decode job              : {whole:7.1f} s  ({args.frames / whole:.1f} frames/s)")
        print(f"  {jobs} jobs of {per_part} frames + join : {parts:7.1f} s  ({args.frames / parts:.1f} frames/s)")
        print(f"  speed-up                  : {whole / parts:7.2f}x  (best of {args.repeat})")
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
