#!/usr/bin/env python
"""Throughput and memory of the light-field steps, and the error of a sweep's time map.

    .venv/bin/python scripts/benchmark_lightfield.py [--size 96] [--frames 48 96] [--time-error | --rays-error]

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

``--rays-error [--noise-free]``: the rays of the library capture (noisy unless ``--noise-free``) per
shadow-time method, ray anchor and the ray's second point (``rays_dataset(anchor=...,
mask_position_mm=...)``: the other screen's point, or the mask point from the pixel's flux
centroid): direction error against the source's ray at the anchor pixel's
true mask point, renders at 350 / 675 mm at 1 x and 2 x the near camera's pitch against the
naive baseline (rel. RMSE with one gain, band-passed DoG(1, 4 px) error) and the far field's
median error at the capture's angular resolution.
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


def rays_error(noise=True):
    from shadowcam.lightfield import accuracy, hdr, rays, screen
    from shadowcam.lightfield.photometry_export import far_field_grid, rays_resolution_deg
    from shadowcam.lightfield.render import irradiance_on_plane
    from shadowcam.synthetic.lightfield.capture import LightFieldCapture, sweep_frames

    from shadowcam.synthetic.lightfield.capture import FOOTPRINT_VARIANCE_PX2

    capture = LightFieldCapture(shape=(96, 96), n_frames=48, quadrature=1200, noise=noise)
    q = capture.responsivity()
    stacks, truths = {}, {}
    for s in range(2):
        for axis in "xy":
            truths[s, axis] = {}
            frames = sweep_frames(capture, s, axis, responsivity=q, truth=truths[s, axis])
            stacks[s, axis] = list(hdr.merge_stream(
                frames, capture.exposure_times, black_level=capture.sensor.black_level,
                white_level=capture.sensor.white_level, gain=capture.sensor.gain,
                read_noise=capture.sensor.read_noise, responsivity=q))
    near_pitch = capture.homography(0)[0, 1]
    targets = {}
    for factor in (1, 2):
        for z in (350.0, 675.0):
            pitch = factor * near_pitch * z / capture.positions_mm[0]
            shape = (capture.shape[0] // factor,) * 2
            targets[factor, z] = shape, pitch, capture.source.irradiance(centre=(0, 0, z), shape=shape, pixel_size=pitch)
    far_truth = {}
    for method in ("edge_fit", "dip_centroid"):
        maps = []
        for s in range(2):
            found = {a: rays.sweep_mask_positions(iter(stacks[s, a]), capture.shape, mask_start=capture.mask_start,
                                                  mask_step=capture.step, method=method) for a in "xy"}
            xy, area = screen.screen_coordinates(capture.homography(s), capture.shape)
            maps.append(rays.screen_mask_map(found["x"], found["y"], xy=xy, area=area,
                                             position_mm=capture.positions_mm[s]))
        for anchor, through in [(a, t) for t in ("screen", "mask") for a in rays.ANCHORS]:
            ray_set = rays.rays_dataset(maps[0], maps[1], anchor=anchor, **({} if through == "screen" else {
                "mask_position_mm": capture.source.z_mask, "footprint_variance": FOOTPRINT_VARIANCE_PX2}))
            s = 1 if anchor == "far" else 0
            true = capture.source.rays(truths[s, "x"]["mask_centre"], truths[s, "y"]["mask_centre"])
            d = ray_set["direction"].values
            ok = (ray_set["flag"].values == 0) & np.all(np.isfinite(true), -1)
            error = np.hypot(*(d - true)[..., :2][ok].T)
            print(f"{method:12s} anchor {anchor:4s} through {through:6s}: direction error median {np.median(error):.5f},"
                  f" p90 {np.percentile(error, 90):.5f}")
            for (factor, z), (shape, pitch, truth) in targets.items():
                nearest = maps[0 if z < capture.positions_mm[1] else 1]
                rendered = irradiance_on_plane(ray_set, centre=(0, 0, z), shape=shape, pixel_size=pitch).values
                base = accuracy.naive_baseline(nearest["irradiance"], nearest["xy"],
                                               position_mm=nearest["position_mm"], target_position_mm=z,
                                               target_shape=shape, pixel_size=pitch)
                ratio = accuracy.relative_rmse_gain(rendered, truth) / accuracy.relative_rmse_gain(base, truth)
                band = accuracy.bandpass_error(rendered, truth) / accuracy.bandpass_error(base, truth)
                print(f"    {z:.0f} mm {factor} x pitch: render / baseline {ratio:.2f}, band-passed {band:.2f}")
            resolution = rays_resolution_deg(ray_set)
            estimate = far_field_grid(ray_set["direction"].values, ray_set["flux"].values, resolution_deg=resolution)
            size = estimate.shape[0]
            if size not in far_truth:
                far_truth[size] = capture.source.far_field_grid(resolution_deg=resolution, size=size).values
            error = accuracy.far_field_error(estimate.values, far_truth[size])
            print(f"    far field at {resolution:.2f} deg: median error {100 * error:.2f} %")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=96)
    parser.add_argument("--frames", type=int, nargs="+", default=[48, 96])
    parser.add_argument("--time-error", action="store_true", help="the time-map error analysis instead")
    parser.add_argument("--rays-error", action="store_true", help="the rays' error per method and anchor instead")
    parser.add_argument("--noise-free", action="store_true", help="--rays-error of the capture without noise")
    args = parser.parse_args()
    if args.time_error:
        time_error()
    elif args.rays_error:
        rays_error(noise=not args.noise_free)
    else:
        throughput(args.size, args.frames)


if __name__ == "__main__":
    main()
