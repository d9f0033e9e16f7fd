#!/usr/bin/env python
"""Outdoor first pass against the decode, per added frame, at a camera's size (one process).

    .venv/bin/python scripts/benchmark_outdoor_pass1.py [--size 6000x4000] [--frames 4] [--dir /tmp/...]

Makes ``2 * frames`` 14-bit lossless-JPEG RGGB DNGs of the given size from the rendered
``synthetic_ridge`` capture (its first frames' decodes resized, each moved by a known
sub-pixel shake, re-mosaiced), then times, in this one process (CPU and wall):

* decode-only: the sweep's DNGs -> mosaic store (:func:`shadowcam.io.frame_store.write_frames`),
* pass 1 as the workflow runs it (:func:`shadowcam.outdoor.photometry.photometry_from_frames`:
  frames after the first read as luminance straight from the mosaic),
* pass 1 reading every frame in colour (demosaic, then luminance),

for ``frames`` and ``2 * frames`` frames, and prints the per-added-frame seconds and the
ratios to the decode. The pass's results of both reads are compared bit for bit.
"""

import argparse
import itertools
import resource
import time
from pathlib import Path

import cv2
import numpy as np


def _clock():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime, time.perf_counter()


def _timed(function, *args, **kwargs):
    cpu, wall = _clock()
    out = function(*args, **kwargs)
    cpu1, wall1 = _clock()
    return out, cpu1 - cpu, wall1 - wall


def _make_dngs(folder, size, count):
    from shadowcam.io.decode import read_frame
    from shadowcam.io.raw_writer import write_dng
    from shadowcam.outdoor.translation import translate

    cols, rows = size
    source = sorted(Path("/work/main/results/synthetic_ridge/capture/frames").glob("*.dng"))
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(1)
    paths = []
    for k in range(count):
        path = folder / f"{k:04d}.dng"
        paths.append(path)
        if path.exists():
            continue
        image = cv2.resize(read_frame(source[k % len(source)]), (cols, rows), interpolation=cv2.INTER_CUBIC)
        shift = rng.uniform(-2, 2, size=2) if k else np.zeros(2)
        image = np.stack([translate(image[..., c], shift, method="opencv_cubic") for c in range(3)], axis=-1)
        mosaic = np.empty((rows, cols), np.float32)
        mosaic[0::2, 0::2], mosaic[0::2, 1::2] = image[0::2, 0::2, 0], image[0::2, 1::2, 1]
        mosaic[1::2, 0::2], mosaic[1::2, 1::2] = image[1::2, 0::2, 1], image[1::2, 1::2, 2]
        dn = np.clip(np.nan_to_num(mosaic), 0, 1) * (16383 - 512) + 512
        write_dng(path, np.rint(dn).astype(np.uint16), bit_depth=14, black_level=512, exposure_time=0.01,
                  compression="ljpeg")
    return paths


def _colour_pass(frames):
    from shadowcam.io.frame_store import iter_store_frames
    from shadowcam.outdoor.normalise import normalise_frames

    return normalise_frames(iter_store_frames(frames, what="colour pass"))


def main():
    from shadowcam.io.frame_store import iter_store_luminance, open_frames, write_frames
    from shadowcam.outdoor.normalise import normalise_frames

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--size", default="6000x4000", help="COLSxROWS")
    parser.add_argument("--frames", type=int, default=4, help="the short run; the long run has twice as many")
    parser.add_argument("--dir", type=Path, default=Path("/tmp/shadowcam-bench-pass1"))
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    paths = _make_dngs(args.dir / f"dng-{args.size}", size, 2 * args.frames)
    raw_bytes = sum(p.stat().st_size for p in paths)
    rows = {}
    for n in (args.frames, 2 * args.frames):
        store, decode_cpu, decode_wall = _timed(write_frames, paths[:n], args.dir / f"store{n}.zarr",
                                                times_s=np.arange(float(n)), chunk_frames=1)
        frames = open_frames(store)
        fast, fast_cpu, fast_wall = _timed(lambda: normalise_frames(itertools.chain(
            [frames["image"].isel(time=0).values], iter_store_luminance(frames.isel(time=slice(1, n))))))
        slow, slow_cpu, slow_wall = _timed(_colour_pass, frames)
        same = all(np.array_equal(fast[key], slow[key]) for key in slow)
        rows[n] = dict(decode=(decode_cpu, decode_wall), fast=(fast_cpu, fast_wall), slow=(slow_cpu, slow_wall))
        print(f"{n} frames: decode {decode_cpu:.2f} s CPU / {decode_wall:.2f} wall; pass 1 (luminance read) "
              f"{fast_cpu:.2f} / {fast_wall:.2f}; pass 1 (colour read) {slow_cpu:.2f} / {slow_wall:.2f}; "
              f"results bit for bit equal: {same}", flush=True)
    a, b = rows[args.frames], rows[2 * args.frames]
    print(f"size {args.size}, RAW {raw_bytes / len(paths) / 1e6:.1f} MB/frame")
    for clock, i in (("CPU", 0), ("wall", 1)):
        decode = (b["decode"][i] - a["decode"][i]) / args.frames
        for name in ("fast", "slow"):
            added = (b[name][i] - a[name][i]) / args.frames
            whole = b[name][i] / b["decode"][i]
            print(f"{clock}: per added frame decode {decode:.3f} s, pass 1 {name} {added:.3f} s -> "
                  f"{added / decode:.2f} x decode (whole run {whole:.2f})")


if __name__ == "__main__":
    main()
