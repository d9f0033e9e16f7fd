#!/usr/bin/env python
"""Outdoor first pass against the decode, per added frame, at a camera's size (one process).

    .venv/bin/python scripts/benchmark_outdoor_pass1.py [--size 6000x4000] [--frames 8] [--dir /tmp/...] [--source results/synthetic_ridge/capture/frames]

Makes ``frames`` 14-bit lossless-JPEG RGGB DNGs of the given size from the rendered
``synthetic_ridge`` capture (its first frames' decodes resized, each moved by a known
sub-pixel shake, re-mosaiced; with ``--noise`` through the renderer's sensor model, Poisson-
Gaussian noise at every photosite, instead of scaled as they are), then measures, in this one process, the CPU seconds per frame (medians over the frames, so
that the per-job fixed costs and the other users' load spikes drop out):

* decode-only: the direct mosaic read of a frame (:class:`shadowcam.io.mosaic_reader.MosaicReader`),
* pass 1 as the workflow runs it (frames after the first read from the store as luminance,
  straight from the mosaic: :func:`shadowcam.io.frame_store.iter_store_luminance`), from one
  frame handed to the pass to the next,
* the same reading every frame in colour (demosaic, then luminance), interleaved with it,

and prints the ratios to the decode, the store's bytes against the DNGs' and the store's
reads alone (luminance: decompress + luminance kernel; colour, as the lab's passes read a
mosaic store: decompress + demosaic). The pass's results of both reads are
compared bit for bit.

With ``--codecs`` it measures instead, on one benchmark frame and on the same frame with the
renderer's Poisson-Gaussian noise (:func:`shadowcam.synthetic.sensor.simulate_raw`, 14 bits,
written as a lossless-JPEG DNG for its RAW bytes): per Blosc compressor, level and shuffle, the
store / RAW bytes of a one-frame chunk and its decompress and compress CPU per frame (warm, into
a reused buffer), then the luminance kernel against a plain read and write of the frame.
"""

import argparse
import itertools
import os
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


def _make_dngs(folder, size, count, source, *, noise=False):
    """The benchmark's DNGs in `folder` (made once); with `noise`, from the renderer's sensor model with its noise."""
    from shadowcam.io.decode import read_frame
    from shadowcam.io.raw_writer import write_dng
    from shadowcam.outdoor.translation import translate
    from shadowcam.synthetic.sensor import SensorModel, electrons_per_unit_radiance, simulate_raw

    cols, rows = size
    frames = sorted(Path(source).glob("*.dng"))
    if not frames:
        raise SystemExit(f"no DNG frames in {source}: run the workflow on synthetic_ridge first, or give --source")
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(1)
    sensor, scale = SensorModel(bit_depth=14), None
    paths = []
    for k in range(count):
        path = folder / f"{k:04d}.dng"
        paths.append(path)
        if path.exists():
            continue
        image = cv2.resize(read_frame(frames[k % len(frames)]), (cols, rows), interpolation=cv2.INTER_CUBIC)
        shift = rng.uniform(-2, 2, size=2) if k else np.zeros(2)
        image = np.stack([translate(image[..., c], shift, method="opencv_cubic") for c in range(3)], axis=-1)
        if noise:  # Poisson-Gaussian at every photosite, frame 0's exposure as synthetic_ridge's (0.6)
            radiance = np.clip(np.nan_to_num(image), 0, None)
            scale = scale or electrons_per_unit_radiance(radiance, sensor=sensor, target_fraction=0.6)
            raw = simulate_raw(radiance, sensor=sensor, scale=scale, seed=[1, 0, k], noise=True)
            write_dng(path, raw, bit_depth=14, black_level=sensor.black_level, exposure_time=0.01,
                      compression="ljpeg")
            continue
        mosaic = np.empty((rows, cols), np.float32)
        mosaic[0::2, 0::2], mosaic[0::2, 1::2] = image[0::2, 0::2, 0], image[0::2, 1::2, 1]
        mosaic[1::2, 0::2], mosaic[1::2, 1::2] = image[1::2, 0::2, 1], image[1::2, 1::2, 2]
        dn = np.clip(np.nan_to_num(mosaic), 0, 1) * (16383 - 512) + 512
        write_dng(path, np.rint(dn).astype(np.uint16), bit_depth=14, black_level=512, exposure_time=0.01,
                  compression="ljpeg")
    return paths


def _median_cpu(function, repeats=5):
    """Median CPU seconds of `repeats` calls of `function` (warm: the first call is not counted)."""
    function()
    return float(np.median([_timed(function)[1] for _ in range(repeats)]))


def _noisy_dng(path, source):
    """Write `source`'s (a 14-bit RGGB DNG) frame again with the renderer's sensor noise; return its mosaic."""
    from shadowcam.io.decode import mosaic_image
    from shadowcam.io.mosaic_reader import MosaicReader
    from shadowcam.io.raw_writer import write_dng
    from shadowcam.synthetic.sensor import SensorModel, electrons_per_unit_radiance, simulate_raw

    if not path.exists():
        mosaic, levels = MosaicReader(source).read(source)
        radiance = np.clip(mosaic_image(mosaic, cfa_pattern=levels["cfa_pattern"], black_sites=levels["black_sites"],
                                        white_sites=levels["white_sites"]), 0, None)
        sensor = SensorModel(bit_depth=14)
        scale = electrons_per_unit_radiance(radiance, sensor=sensor, target_fraction=0.6)  # synthetic_ridge's exposure
        raw = simulate_raw(radiance, sensor=sensor, scale=scale, seed=[3, 0, 1], noise=True)
        write_dng(path, raw, bit_depth=14, black_level=sensor.black_level, exposure_time=0.01, compression="ljpeg")
    return MosaicReader(path).read(path)


def _codecs(paths, folder):
    """Print the store / RAW bytes and CPU of Blosc settings on a frame, clean and noisy, and the kernel's cost."""
    from numcodecs import Blosc

    from shadowcam.io.luminance import channel_mean, mosaic_luminance
    from shadowcam.io.decode import mosaic_image
    from shadowcam.io.mosaic_reader import MosaicReader

    source = paths[len(paths) // 2]
    noisy_path = folder / f"noisy-{source.name}"
    clean, levels = MosaicReader(source).read(source)
    noisy, _ = _noisy_dng(noisy_path, source)
    frames = {"frame": (clean, source.stat().st_size), "noisy": (noisy, noisy_path.stat().st_size)}
    shuffles = {"bit": Blosc.BITSHUFFLE, "byte": Blosc.SHUFFLE}
    print(f"one {clean.shape[1]}x{clean.shape[0]} frame: RAW {frames['frame'][1] / 1e6:.1f} MB, with the renderer's "
          f"noise {frames['noisy'][1] / 1e6:.1f} MB; Blosc one-frame chunks, CPU per frame, warm")
    print("| codec | shuffle | block | store / RAW | decompress | compress | noisy: store / RAW | decompress | compress |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    settings = [(cname, level, shuffle, 0) for cname, level in (("zstd", 1), ("lz4", 5), ("lz4", 9), ("lz4hc", 5),
                                                                  ("blosclz", 5)) for shuffle in ("bit", "byte")]
    settings.append(("zstd", 1, "bit", 2**20))
    for cname, level, shuffle, block in settings:
        codec = Blosc(cname=cname, clevel=level, shuffle=shuffles[shuffle], blocksize=block)
        cells = [f"{cname} {level}", shuffle, f"{block >> 10} KiB" if block else "auto"]
        for mosaic, raw_bytes in frames.values():
            encoded = codec.encode(mosaic)
            out = np.empty_like(mosaic)
            cells += [f"{len(encoded) / raw_bytes:.3f}", f"{_median_cpu(lambda: codec.decode(encoded, out=out)):.4f} s",
                      f"{_median_cpu(lambda: codec.encode(mosaic), repeats=2):.3f} s"]
        print("| " + " | ".join(cells) + " |", flush=True)
    kwargs = dict(cfa_pattern=levels["cfa_pattern"], black_sites=levels["black_sites"], white_sites=levels["white_sites"])
    warm = np.empty(clean.shape, np.float32)
    print(f"luminance kernel (io.luminance.mosaic_luminance, fresh output) {_median_cpu(lambda: mosaic_luminance(clean, **kwargs)):.4f} s; "
          f"demosaic + channel mean {_median_cpu(lambda: channel_mean(mosaic_image(clean, **kwargs))):.4f} s; "
          f"floor, uint16 read + float32 write: into a fresh array {_median_cpu(lambda: clean.astype(np.float32)):.4f} s, "
          f"into a warm one {_median_cpu(lambda: np.copyto(warm, clean, casting='unsafe')):.4f} s; "
          f"kernel equal to the demosaic's channel mean: "
          f"{np.array_equal(mosaic_luminance(noisy, **kwargs), channel_mean(mosaic_image(noisy, **kwargs)))} (noisy frame)")


def _per_frame(stream, cpu):
    """Yield the items of `stream`, appending to `cpu` the CPU seconds from each item handed out to the next."""
    last = None
    for item in stream:
        now = _clock()[0]
        if last is not None:
            cpu.append(now - last)  # the pass's work on the previous item and the read of this one
        last = now
        yield item


def main():
    from shadowcam.io.frame_store import iter_store_frames, iter_store_luminance, open_frames, write_frames
    from shadowcam.io.mosaic_reader import MosaicReader
    from shadowcam.outdoor.normalise import normalise_frames

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--size", default="6000x4000", help="COLSxROWS")
    parser.add_argument("--frames", type=int, default=8)
    parser.add_argument("--dir", type=Path, default=Path("/tmp/shadowcam-bench-pass1"))
    parser.add_argument("--source", type=Path, default=Path("results/synthetic_ridge/capture/frames"),
                        help="rendered DNG frames the benchmark's frames are made from")
    parser.add_argument("--noise", action="store_true",
                        help="make the frames with the renderer's sensor noise at every photosite")
    parser.add_argument("--codecs", action="store_true",
                        help="measure the store's codecs and the luminance kernel instead of pass 1")
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    n = args.frames
    paths = _make_dngs(args.dir / f"dng-{args.size}{'-noisy' if args.noise else ''}", size, n, args.source,
                       noise=args.noise)
    if args.codecs:
        _codecs(paths, args.dir)
        return
    reader = MosaicReader(paths[0])
    decode = []
    for path in paths[1:]:
        _, cpu, _ = _timed(reader.read, path)
        decode.append(cpu)
    store, store_cpu, _ = _timed(write_frames, paths, args.dir / f"store{n}.zarr", times_s=np.arange(float(n)),
                                 chunk_frames=1)
    frames = open_frames(store)
    store_bytes = sum(f.stat().st_size for f in (store / "mosaic").rglob("*") if f.is_file())
    raw_bytes = sum(p.stat().st_size for p in paths)
    reads = {"luminance": [], "colour": []}
    for _ in range(2):  # the store's reads alone, whole frames one at a time
        for name, cpu in reads.items():
            later = frames.isel(time=slice(1, n))
            for _ in _per_frame(iter_store_luminance(later) if name == "luminance" else iter_store_frames(later), cpu):
                pass
    first = frames["image"].isel(time=0).values
    runs = {}
    for name in ("luminance", "colour", "luminance", "colour"):  # interleaved: the load changes
        later = frames.isel(time=slice(1, n))
        stream = iter_store_luminance(later) if name == "luminance" else iter_store_frames(later)
        cpu = []
        result = normalise_frames(itertools.chain([first], _per_frame(stream, cpu)))
        runs.setdefault(name, []).extend(cpu[1:])  # frame 1's time includes the reference's set-up
        runs.setdefault(name + " result", result)
    same = all(np.array_equal(runs["luminance result"][k], runs["colour result"][k], equal_nan=True)  # blocks without a level: NaN
               for k in runs["colour result"])
    per_decode = float(np.median(decode))
    print(f"size {args.size}, {n} frames, RAW {sum(p.stat().st_size for p in paths) / n / 1e6:.1f} MB/frame; "
          f"results of the two reads bit for bit equal: {same}")
    print(f"decode-only (direct mosaic read) {per_decode:.3f} s CPU per frame (median of {len(decode)}); "
          f"the whole store write {store_cpu / n:.3f} s CPU per frame; store / RAW bytes (mosaic) "
          f"{store_bytes / raw_bytes:.3f}")
    for name, cpu in reads.items():
        per_read = float(np.median(cpu))
        print(f"the store's {name} read alone {per_read:.3f} s CPU per frame (median of {len(cpu)}) "
              f"-> {per_read / per_decode:.2f} x decode")
    for name in ("luminance", "colour"):
        per = float(np.median(runs[name]))
        print(f"pass 1 reading {name}: {per:.3f} s CPU per frame (median of {len(runs[name])}: read + pass) "
              f"-> {per / per_decode:.2f} x decode")
    print("load average (1, 5, 15 min) at the end: " + ", ".join(f"{v:.1f}" for v in os.getloadavg()))


if __name__ == "__main__":
    main()
