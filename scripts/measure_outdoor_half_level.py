"""Where the outdoor arrival's error on long penumbrae comes from: levels, shape or cut ramps.

Usage::

    python scripts/measure_outdoor_half_level.py [--size 128 192] [--frames 96]
        [--elevations 8.0 7.2] [--cloud drifting] [--supersample 2]

Renders the ridge sunset with the 0.53 deg disc sun and every nuisance (seed 3), adds 14-bit
Poisson-Gaussian noise, runs the outdoor passes in process (photometry, edge tracking, arrival
map) and reports the combined arrival error against the pixel-centre ground truth (class-3
pixels, median intervals). Then, from the renderer's exact levels of every pixel and frame
(the luminance with the sun unhidden and with it fully hidden, the cloud's attenuation of the
sun term included, :func:`shadowcam.synthetic.outdoor.render.frame_radiance` with a lit
fraction of 1 and of 0), the arrival as the last downward crossing of the half level
``(L + S) / 2`` refined by a line over ``+-k`` frames: noise-free, with the frames' noise
(Gaussian of the Poisson level of the same electrons per unit radiance), and with one level
replaced by a constant (the lit level of frame 0, the shadow level of the last frame). Also
the share of class-3 pixels whose whole penumbra lies inside the sequence (both levels seen)
and the arrival spread of each pixel's render samples.
"""

import argparse

import numpy as np
import xarray as xr

from shadowcam.outdoor.accuracy import PRIMARY_DEFINITION, evaluate_arrivals, map_to_truth_camera
from shadowcam.outdoor.arrival import arrival_map
from shadowcam.outdoor.edges import track_edges
from shadowcam.outdoor.half_level import half_level_crossings
from shadowcam.outdoor.photometric import luminance
from shadowcam.outdoor.photometry import photometry_from_frames
from shadowcam.synthetic.outdoor.capture import render_outdoor_capture
from shadowcam.synthetic.outdoor.render import (SUN_DIAMETER_DEG, frame_radiance, make_outdoor_scene, sample_grid,
                                                sun_lit_fraction, trace_samples)
from shadowcam.synthetic.sensor import SensorModel, electrons_per_unit_radiance, raw_to_linear, simulate_raw

SEED = 3
#: luminance noise over one channel's (RGB weights' root sum of squares)
LUMINANCE_NOISE = 0.68


def half_level_crossing(fraction, times, *, pixels, half_window):
    """Last downward crossing of 0.5 of ``(T, H, W)`` sun fractions (:func:`half_level_crossings`)."""
    out = np.full(fraction.shape[1:], np.nan)
    series = fraction[:, pixels].T
    out[pixels] = half_level_crossings(series, times, half_level=np.full(len(series), 0.5),
                                       half_window=half_window)[0]
    return out


def figures(estimate, truth_s, pixels, interval):
    error = np.abs(estimate - truth_s)[pixels] / interval
    coverage = np.isfinite(error).mean()
    error = error[np.isfinite(error)]
    return (f"median {np.median(error):.3f} p95 {np.percentile(error, 95):.2f} "
            f"beyond 5 {100 * np.mean(error > 5):.2f} % (coverage {100 * coverage:.1f} %)")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, nargs=2, default=(128, 192), metavar=("ROWS", "COLS"))
    parser.add_argument("--frames", type=int, default=96)
    parser.add_argument("--elevations", type=float, nargs=2, default=(8.0, 7.2), metavar=("START", "END"))
    parser.add_argument("--cloud", default="drifting", help="a cloud scenario, or 'none'")
    parser.add_argument("--supersample", type=int, default=2)
    args = parser.parse_args()
    rows, cols = args.size
    cloud = {"none": False, "drifting": True}.get(args.cloud, args.cloud)
    scene = make_outdoor_scene(seed=SEED, height=rows, width=cols, start_elevation_deg=args.elevations[0],
                               end_elevation_deg=args.elevations[1])
    capture = render_outdoor_capture(scene, frames=args.frames, supersample=args.supersample, seed=SEED,
                                     sun_diameter_deg=SUN_DIAMETER_DEG, cloud=cloud)
    truth, times = capture.ground_truth, capture.times_s
    interval = float(np.median(np.diff(times)))
    sensor = SensorModel(bit_depth=14)
    scale = electrons_per_unit_radiance(truth["reference_radiance"].values, sensor=sensor, target_fraction=0.6)
    images = np.stack([raw_to_linear(simulate_raw(f, sensor=sensor, scale=scale, seed=[SEED, k], mosaic=False),
                                     sensor=sensor) for k, f in enumerate(capture.frames)])
    store = xr.Dataset({"image": (("time", "row", "col", "channel"), images)},
                       coords={"time_s": ("time", times), "exposure_s": ("time", 0.004 * 2.0 ** truth["ae_ev"].values)})
    photometry = photometry_from_frames(store)
    arrival = arrival_map(photometry, track_edges(store, photometry))
    estimate = map_to_truth_camera(arrival["arrival_time_s"].values, shift_row=float(truth["shake_dy_px"][0]),
                                   shift_col=float(truth["shake_dx_px"][0]))
    stats = evaluate_arrivals({"combined": estimate}, truth, interval_s=interval,
                              condition="nuisances")["errors"]["combined"][PRIMARY_DEFINITION]
    class3 = truth["shadow_class"].values == 3
    arrival_s = truth["arrival_time_s"].values
    start, end = truth["penumbra_start_time_s"].values, truth["penumbra_end_time_s"].values
    print(f"{rows}x{cols}, {args.frames} frames, sun {args.elevations[0]} -> {args.elevations[1]} deg, "
          f"cloud {args.cloud}: {class3.sum()} class-3 pixels, penumbra median "
          f"{np.nanmedian((end - start)[class3]) / interval:.1f} intervals (p5-p95 "
          f"{np.nanpercentile((end - start)[class3] / interval, 5):.1f}-"
          f"{np.nanpercentile((end - start)[class3] / interval, 95):.1f})")
    print(f"  pipeline (combined): median {stats['median_abs']:.3f} p95 {stats['p95_abs']:.2f} beyond 5 "
          f"{100 * stats['frac_over_5']:.2f} % (coverage {100 * stats['coverage']:.1f} %)")
    inside = class3 & (start > times[0]) & (end < times[-1])
    print(f"  whole penumbra inside the sequence (both levels seen): {100 * inside.sum() / class3.sum():.1f} % "
          f"of class-3; begun before frame 0: {100 * (class3 & ~(start > times[0])).sum() / class3.sum():.1f} %, "
          f"not ended by the last frame: {100 * (class3 & ~(end < times[-1])).sum() / class3.sum():.1f} %")
    sub = truth["subpixel_arrival_time_s"].values
    finite = np.isfinite(sub).all(-1) & class3
    spread = (sub[finite].max(-1) - sub[finite].min(-1)) / interval
    print(f"  arrival spread of a pixel's render samples: median {np.median(spread):.1f} intervals")
    # the renderer's exact levels: sun unhidden (cloud attenuation on the sun term) and sky only
    samples = trace_samples(scene, *sample_grid(rows, cols, args.supersample))
    ones = np.ones(len(samples.sky))
    lit, sky = [], []
    for k, t in enumerate(times):
        full = luminance(frame_radiance(samples, scene, t, shape=(rows, cols), supersample=args.supersample,
                                        lit=ones)[0])
        dark = luminance(frame_radiance(samples, scene, t, shape=(rows, cols), supersample=args.supersample,
                                        lit=0 * ones)[0])
        attenuation = truth["cloud_attenuation"].values[k] if cloud is not False else 1.0
        sky.append(dark)
        lit.append(dark + attenuation * (full - dark))
    lit, sky = np.stack(lit), np.stack(sky)
    gain = truth["exposure_gain"].values[:, None, None]
    clean = []  # the noise-free series in the truth camera (no shake): sky + cloud x visible fraction x sun
    for k, t in enumerate(times):
        shown = luminance(frame_radiance(samples, scene, t, shape=(rows, cols), supersample=args.supersample,
                                         lit=sun_lit_fraction(samples, scene.sun, t))[0])
        attenuation = truth["cloud_attenuation"].values[k] if cloud is not False else 1.0
        clean.append(sky[k] + attenuation * (shown - sky[k]))
    clean = np.stack(clean)
    with np.errstate(invalid="ignore", divide="ignore"):
        noise = LUMINANCE_NOISE * np.sqrt(np.maximum(clean, 0) * gain * scale) / (scale * gain)
        noisy = clean + np.random.default_rng(0).normal(size=clean.shape) * noise
        rng = lit - sky
        cases = [("exact levels, noise-free, 2 frames", (clean - sky) / rng, 1)]
        cases += [(f"exact levels, noisy, k = {k}", (noisy - sky) / rng, k) for k in (1, 3, 5, 8)]
        cases += [("lit level constant (frame 0), noisy, k = 5", (noisy - sky) / (lit[0] - sky), 5),
                  ("shadow level constant (last frame), noisy, k = 5", (noisy - sky[-1]) / (lit - sky[-1]), 5)]
    for label, fraction, k in cases:
        crossing = half_level_crossing(fraction, times, pixels=class3, half_window=k)
        print(f"  half-level crossing, {label}: {figures(crossing, arrival_s, class3, interval)}")
    drift = lit[-1] / lit[0]
    print(f"  lit level last / first frame: median {np.median(drift[class3]):.3f}; shadow-to-lit ratio at "
          f"frame 0, p5-p50-p95: {np.round(np.percentile((sky[0] / lit[0])[class3], [5, 50, 95]), 3).tolist()}")


if __name__ == "__main__":
    main()
