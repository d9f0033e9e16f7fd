"""The first outdoor pass's gains against the renderer's, and the arrival they give.

Usage::

    python scripts/measure_outdoor_gain.py [--size 128 192] [--window ROW0 COL0 ROWS COLS]
        [--frames 120] [--elevations 20.0 1.5] [--cloud drifting] [--supersample 3]
        [--point-sun] [--shake 1.0] [--cache DIR]

Renders the ridge sunset (seed 3, every nuisance; `--window` renders that window of a `--size`
camera at its resolution, as the 24 MP strip), adds 14-bit Poisson-Gaussian noise on linear
RGB (no mosaic), runs the outdoor passes in process (photometry, edge tracking, arrival map)
and reports: the lit and sky gains against the truth's ``lit_gain`` and ``sky_gain`` (relative
error, median / p95 / max over the frames; the frames grouped by the share of the lit pixels a
cloud covers), the lit gain's source per frame, and the combined arrival error against the
pixel-centre truth (class-3 pixels, median intervals: median / p95 / beyond 5 (coverage) and
the signed median). With `--cache` the noisy frames and the truth are kept between runs.
"""

import argparse
import hashlib
import json
import os

import numpy as np
import xarray as xr

from shadowcam.outdoor.accuracy import PRIMARY_DEFINITION, evaluate_arrivals, map_to_truth_camera
from shadowcam.outdoor.arrival import arrival_map
from shadowcam.outdoor.edges import track_edges
from shadowcam.outdoor.photometry import photometry_from_frames
from shadowcam.synthetic.outdoor.capture import noisy_frame_store, render_outdoor_capture
from shadowcam.synthetic.outdoor.render import SUN_DIAMETER_DEG, make_outdoor_scene

SEED = 3


def render(args):
    rows, cols = args.size
    cloud = {"none": False, "drifting": True}.get(args.cloud, args.cloud)
    scene = make_outdoor_scene(seed=SEED, height=rows, width=cols, start_elevation_deg=args.elevations[0],
                               end_elevation_deg=args.elevations[1], window=args.window)
    capture = render_outdoor_capture(scene, frames=args.frames, supersample=args.supersample, seed=SEED,
                                     sun_diameter_deg=0.0 if args.point_sun else SUN_DIAMETER_DEG, cloud=cloud,
                                     shake_px=args.shake)
    return noisy_frame_store(capture, seed=SEED), capture.ground_truth


def load(args):
    if not args.cache:
        return render(args)
    key = hashlib.sha1(json.dumps({k: v for k, v in vars(args).items() if k != "cache"},
                                  sort_keys=True).encode()).hexdigest()[:12]
    store_path = os.path.join(args.cache, f"{key}-frames.nc")
    truth_path = os.path.join(args.cache, f"{key}-truth.nc")
    if not os.path.exists(truth_path):
        os.makedirs(args.cache, exist_ok=True)
        store, truth = render(args)
        store.to_netcdf(store_path)
        truth.to_netcdf(truth_path)
    return xr.load_dataset(store_path), xr.load_dataset(truth_path)


def add_render_arguments(parser):
    """The render's options (size, window, frames, elevations, cloud, supersample, sun, shake, cache)."""
    parser.add_argument("--size", type=int, nargs=2, default=(128, 192), metavar=("ROWS", "COLS"))
    parser.add_argument("--window", type=int, nargs=4, default=None, metavar=("ROW0", "COL0", "ROWS", "COLS"))
    parser.add_argument("--frames", type=int, default=120)
    parser.add_argument("--elevations", type=float, nargs=2, default=(20.0, 1.5), metavar=("START", "END"))
    parser.add_argument("--cloud", default="drifting", help="a cloud scenario, or 'none'")
    parser.add_argument("--supersample", type=int, default=3)
    parser.add_argument("--point-sun", action="store_true")
    parser.add_argument("--shake", type=float, default=1.0)
    parser.add_argument("--cache", default=None)
    return parser


def main():
    args = add_render_arguments(argparse.ArgumentParser(description=__doc__.splitlines()[0])).parse_args()
    store, truth = load(args)
    photometry = photometry_from_frames(store)
    arrival = arrival_map(photometry, track_edges(store, photometry))
    estimate = map_to_truth_camera(arrival["arrival_time_s"].values, shift_row=float(truth["shake_dy_px"][0]),
                                   shift_col=float(truth["shake_dx_px"][0]))
    times = truth["times_s"].values
    interval = float(np.median(np.diff(times)))
    stats = evaluate_arrivals({"combined": estimate}, truth, interval_s=interval,
                              condition="nuisances")["errors"]["combined"][PRIMARY_DEFINITION]
    class3 = truth["shadow_class"].values == 3
    signed = ((estimate - truth["arrival_time_s"].values) / interval)[class3]
    print(f"{vars(args)}")
    print(f"  arrival (combined): median {stats['median_abs']:.3f} p95 {stats['p95_abs']:.2f} beyond 5 "
          f"{100 * stats['frac_over_5']:.2f} % (coverage {100 * stats['coverage']:.1f} %), signed median "
          f"{np.nanmedian(signed):+.2f}")
    # the share of the lit-at-start pixels under a cloud (mean transmittance below 0.95)
    lit0 = truth["shadow_class"].values != 0
    lit0 &= truth["lit_center"].values[0].astype(bool)
    covered = (truth["cloud_attenuation"].values[:, lit0] < 0.95).mean(axis=1)
    for name in ("lit", "sky"):
        est = photometry[f"gain{'' if name == 'lit' else '_sky'}"].values
        true = truth[f"{name}_gain"].values
        err = np.abs(est / true - 1)
        line = f"  {name} gain error: median {np.nanmedian(err):.4f} p95 {np.nanpercentile(err, 95):.4f} " \
               f"max {np.nanmax(err):.4f}"
        for lo, hi in ((0, 0.01), (0.01, 0.4), (0.4, 0.8), (0.8, 1.01)):
            sel = (covered >= lo) & (covered < hi)
            if sel.any():
                line += f"; cloud over {lo:.0%}-{min(hi, 1):.0%} of the lit ({sel.sum()} frames): " \
                        f"median {np.nanmedian(err[sel]):.4f} max {np.nanmax(err[sel]):.4f}"
        print(line)
    if "gain_source" in photometry:
        sources, counts = np.unique(photometry["gain_source"].values, return_counts=True)
        print("  lit gain source: " + ", ".join(f"{s} {c}" for s, c in zip(sources, counts)))


if __name__ == "__main__":
    main()
