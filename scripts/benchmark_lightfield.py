#!/usr/bin/env python
"""Throughput and memory of the light-field steps, and the error of a sweep's time map.

    .venv/bin/python scripts/benchmark_lightfield.py [--size 96] [--frames 48 96] [--time-error]

Throughput: renders one sweep (near screen, wire along x) of `--size` x `--size` DNG brackets
per frame count into a scratch folder, then times, in process, the HDR merge
(:func:`shadowcam.lightfield.stages.merge_sweep`), the shadow times
(:func:`shadowcam.lightfield.stages.sweep_dataset`, numba warmed on a first run) and, once,
the rays, the two renders and the far field of the whole capture from its four sweeps.
Prints pixel-frames per second and the tracemalloc peak of each step per frame count (the
peak should not grow with the frame count).

``--time-error``: the shadow times of each sweep of the library capture against the
renderer's truth (the flux-weighted mask coordinate of each pixel's rays), for the
shadow-time methods ``edge_fit`` and ``dip_centroid`` with and without noise: error std,
the part explained by the frame phase ``t mod 1`` (two harmonics), and the error's
correlation between neighbouring pixels. Run with PYTHONPATH set to the repository under test.
"""

import argparse
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np


def _timed(function, *args, **kwargs):
    tracemalloc.start()
    start = time.perf_counter()
    result = function(*args, **kwargs)
    wall = time.perf_counter() - start
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return result, wall, peak / 2**20


def throughput(size, frame_counts):
    from shadowcam.lightfield import stages
    from shadowcam.synthetic.lightfield.capture import LightFieldCapture, write_capture

    with tempfile.TemporaryDirectory() as scratch:
        for i, n_frames in enumerate([frame_counts[0]] + list(frame_counts)):
            capture = LightFieldCapture(shape=(size, size), n_frames=n_frames, quadrature=600)
            folder = Path(scratch) / f"c{i}"
            write_capture(folder, capture)
            description = stages.read_description(folder)
            mask = description["mask"]
            sweeps = {}
            walls = {}
            for screen in description["screens"]:
                for suffix in stages.SWEEP_AXES:
                    sweep = f"{screen['name']}_{suffix}"
                    hdr_path = folder / f"{sweep}.npy"
                    _, merge_wall, merge_peak = _timed(stages.merge_sweep, stages.sweep_files(folder, description, sweep),
                                                       hdr_path, exposure_times=description["exposure_times"],
                                                       sensor=description["sensor"])
                    dataset, times_wall, times_peak = _timed(stages.sweep_dataset, hdr_path, mask_start=mask["start_mm"],
                                                             mask_step=mask["step_mm"])
                    sweeps[(screen["name"], suffix)] = dataset
                    walls.setdefault("merge", []).append((merge_wall, merge_peak))
                    walls.setdefault("times", []).append((times_wall, times_peak))
            if i == 0:
                continue  # numba compile and file-cache warm-up
            pixel_frames = size * size * n_frames
            for step, runs in walls.items():
                wall = np.median([w for w, _ in runs])
                peak = max(p for _, p in runs)
                print(f"{size}x{size} {n_frames:4d} frames  {step:6s} {pixel_frames / wall / 1e6:6.2f} M pixel-frames/s"
                      f"  ({wall:.2f} s per sweep)  peak {peak:6.1f} MB")
            ray_set, wall, peak = _timed(stages.rays_from_sweeps, sweeps, description)
            print(f"{size}x{size} {n_frames:4d} frames  rays   {wall:.2f} s ({size * size / wall / 1e3:.1f} k rays/s)"
                  f"  peak {peak:6.1f} MB")
            _, wall, peak = _timed(stages.render_positions, ray_set, description, [350.0, 675.0])
            print(f"{size}x{size} {n_frames:4d} frames  render {wall:.2f} s (2 planes)  peak {peak:6.1f} MB")
            _, wall, peak = _timed(stages.far_field, ray_set)
            print(f"{size}x{size} {n_frames:4d} frames  far field {wall:.2f} s  peak {peak:6.1f} MB")


def time_error():
    from shadowcam.lightfield import hdr, rays
    from shadowcam.synthetic.lightfield.capture import LightFieldCapture, sweep_frames

    for noise in (False, True):
        capture = LightFieldCapture(shape=(96, 96), n_frames=48, quadrature=1200, noise=noise)
        q = capture.responsivity()
        for method in ("dip_centroid", "edge_fit"):
            for screen in range(2):
                for axis in "xy":
                    truth = {}
                    frames = sweep_frames(capture, screen, axis, responsivity=q, truth=truth)
                    blocks = hdr.merge_stream(frames, capture.exposure_times, black_level=capture.sensor.black_level,
                                              white_level=capture.sensor.white_level, gain=capture.sensor.gain,
                                              read_noise=capture.sensor.read_noise, responsivity=q)
                    found = rays.sweep_mask_positions(blocks, capture.shape, mask_start=capture.mask_start,
                                                      mask_step=capture.step, method=method)
                    true_time = (truth["mask_centre"] - capture.mask_start) / capture.step
                    error = (found["position"] - truth["mask_centre"]) / capture.step
                    ok = np.isfinite(error) & np.isfinite(true_time)
                    phase = 2 * np.pi * (true_time[ok] % 1.0)
                    basis = np.c_[np.cos(phase), np.sin(phase), np.cos(2 * phase), np.sin(2 * phase), np.ones(ok.sum())]
                    coef, *_ = np.linalg.lstsq(basis, error[ok], rcond=None)
                    centred = np.where(ok, error - error[ok].mean(), 0.0)
                    lag = []
                    for ax in (0, 1):
                        both = ok & np.roll(ok, 1, axis=ax)
                        lag.append((centred * np.roll(centred, 1, axis=ax))[both].mean() / (centred[ok] ** 2).mean())
                    speed = np.nanmedian(np.hypot(*np.gradient(true_time)))
                    print(f"noise={noise!s:5} {method:12s} screen {screen} {axis}: error std {error[ok].std():.3f} frame,"
                          f" without the phase part {(error[ok] - basis @ coef).std():.3f}"
                          f" (phase amplitude {np.hypot(coef[0], coef[1]):.3f}); neighbour correlation"
                          f" row {lag[0]:+.2f} col {lag[1]:+.2f}; shadow moves {1 / speed:.2f} px per frame")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=96)
    parser.add_argument("--frames", type=int, nargs="+", default=[48, 96])
    parser.add_argument("--time-error", action="store_true", help="the time-map error analysis instead")
    args = parser.parse_args()
    if args.time_error:
        time_error()
    else:
        throughput(args.size, args.frames)


if __name__ == "__main__":
    main()
