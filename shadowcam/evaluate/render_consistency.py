"""Benchmark command: consistency of rendered outdoor captures with their ground truth.

Usage::

    python -m shadowcam.evaluate.render_consistency results/synthetic_ridge/capture [more capture dirs]

For each capture (``shadowcam render`` output with ``kind: outdoor``) it prints the GT class
counts, how fast the shadow edge moves, and the errors of a naive per-site detector run on
the DNG files themselves (README 2.8 style): per RAW site ``I_k = (DN - black) / gain_k``
(``exposure_gain`` from the GT, or 1 for the "as delivered" variant); detected frame = first k
with ``I_k < 0.5 max(I_{k-10} .. I_{k-1})``; evaluated on the sites of class-3 pixels. Errors
are ``t(k_det) - arrival_time_s`` in units of the median capture interval (a perfect frame-level
detector is in [0, 1) intervals late). Render time and memory come from Snakemake's
``benchmarks/<ds>/render.tsv``.

Offers
------
naive_detection : first frame of a halving of a running recent maximum, per site.
capture_report : the figures of one capture directory (dict).
main : the command.
"""

import argparse
import json
from pathlib import Path

import numpy as np

from shadowcam.io.frame_times import median_interval


def naive_detection(stack, *, window=10, ratio=0.5):
    """First frame whose value drops below `ratio` x the max of the previous `window` frames.

    Parameters
    ----------
    stack : (K, rows, cols) ndarray
    window : int, keyword-only
    ratio : float, keyword-only

    Returns
    -------
    (rows, cols) int ndarray
        Frame index, -1 where never.
    """
    from shadowcam.outdoor.accuracy import NaiveBaseline

    stack = np.asarray(stack, dtype=np.float64)
    if stack.ndim != 3:
        raise ValueError(f"stack: expected (K, rows, cols), got {stack.shape}")
    # the pipeline's streaming baseline, timed in frame indices
    baseline = NaiveBaseline(stack.shape[1:], window=window, fraction=ratio)
    for k, frame in enumerate(stack):
        baseline.update(frame[..., None], k)
    return np.where(np.isnan(baseline.arrival_s), -1, baseline.arrival_s).astype(int)


def capture_report(capture_dir):
    """Figures of one rendered outdoor capture (see the module docstring)."""
    import rawpy
    import xarray as xr

    from shadowcam.io.manifest import load_manifest
    from shadowcam.synthetic.outdoor.capture import edge_speed

    capture_dir = Path(capture_dir)
    manifest = load_manifest(capture_dir / "capture.json")
    with xr.open_dataset(capture_dir / manifest["ground_truth"]["file"],
                         engine="h5netcdf") as gt:
        gt = gt.load()
    raws = []
    for path in manifest["sweeps"]["timelapse"]["paths"]:
        with rawpy.imread(path) as raw:
            raws.append(raw.raw_image_visible.astype(np.float64)
                        - raw.black_level_per_channel[0])
    raws = np.stack(raws)
    times = gt["times_s"].values
    interval = median_interval(times)
    cls = gt["shadow_class"].values
    arrives = cls == 3
    report = {
        "capture": str(capture_dir),
        "frames": int(len(times)),
        "size": list(cls.shape),
        "median_interval_s": interval,
        "class_counts": json.loads(gt.attrs["class_counts"]),
    }
    fast, per_px = edge_speed(gt["arrival_frame"].values, cls)
    report["edge_fast_pair_fraction"] = fast
    report["edge_median_frames_per_px"] = per_px
    gains = {"as delivered": np.ones(len(times)), "gain removed": gt["exposure_gain"].values}
    for name, gain in gains.items():
        det = naive_detection(raws / gain[:, None, None])
        found = arrives & (det >= 0)
        err = (times[np.maximum(det, 0)] - gt["arrival_time_s"].values) / interval
        e = err[found]
        never = cls == 1
        report[f"naive detector ({name})"] = {
            "evaluated": int(arrives.sum()),
            "not_detected": int((arrives & (det < 0)).sum()),
            "median_error_intervals": float(np.median(e)),
            "p95_abs_error_intervals": float(np.percentile(np.abs(e), 95)),
            "within_0_1_intervals": float(np.mean((e >= 0) & (e < 1))),
            "abs_error_over_5": float(np.mean(np.abs(e) > 5)),
            "false_detections_never_shadowed": int((never & (det >= 0)).sum()),
        }
    return report


def main(argv=None):
    """Print the figures of each capture directory as JSON."""
    parser = argparse.ArgumentParser(prog="python -m shadowcam.evaluate.render_consistency",
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("captures", nargs="+", type=Path, help="rendered capture directories")
    args = parser.parse_args(argv)
    for capture in args.captures:
        print(json.dumps(capture_report(capture), indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
