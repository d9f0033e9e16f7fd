#!/usr/bin/env python
"""Wide-shadow capture: the first (window) pass alone against the dip-interval pass.

    .venv/bin/python scripts/benchmark_area_first_pass.py [--dataset synthetic_area]

Needs the workflow's results of the dataset (``snakemake --config
'datasets=[synthetic_area]'``): its frame stores and rendered capture. Recomputes the
shadow times with the interval pass switched off (``dip_tracker.without_interval``
replaced by one that returns no interval: what the shadow-time step did before the pass),
then the dual coordinates, dual view and accuracy with the workflow's CLI steps, into
``results/<dataset>/first_pass/``, and prints the shadow-time coverage and p95 (against
the ground truth's ``t_<sweep>``) and the dual view's coverage of what the camera sees,
next to the workflow's own (interval) figures.
"""

import argparse
import json
import subprocess
from pathlib import Path


def _first_pass_shadow_time(results, out):
    from shadowcam import cli
    from shadowcam.lab import dip_tracker

    dip_tracker.without_interval = lambda summary, interval: (summary, None)
    cli.main(["shadow-time", "--frames", str(results / "frames/u.zarr"), str(results / "frames/v.zarr"),
                   "--sweeps", "u", "v", "--method", "edge_fit", "--params", '{"min_coverage":0.01}',
                   "--out", str(out)])


def _step(*args):
    subprocess.run(["shadowcam", *args], check=True)


def _figures(path):
    report = json.loads(Path(path).read_text())
    row = {f"{s} coverage / p95": (round(v["coverage"], 4), round(v["p95"], 3))
           for s, v in report["shadow_time"].items()}
    row.update(_whole_dip_coverage(Path(path).parent / "shadow_time.nc", Path(path).parent))
    row["dual view coverage of visible"] = round(report["dual_image"]["coverage_of_visible"], 4)
    row["dual view rel RMSE masked"] = round(report["dual_image"]["rel_rmse_masked"], 4)
    return row


def _whole_dip_coverage(shadow_time_path, folder):
    """Coverage and p95 of the times over the lit pixels whose whole dip lies in the sweep."""
    import numpy as np
    import xarray as xr

    truth_path = next(p for p in (folder / "capture", folder.parent / "capture") if p.is_dir()) / "ground_truth.nc"
    out = {}
    with xr.open_dataset(shadow_time_path) as st, xr.open_dataset(truth_path) as gt:
        for s in ("u", "v"):
            if f"penumbra_first_{s}" not in gt:
                continue
            whole = (gt["lit"].values.astype(bool) & (gt[f"penumbra_first_{s}"].values >= 0)
                     & (gt[f"penumbra_last_{s}"].values <= st.attrs[f"n_frames_{s}"] - 1))
            time = st["shadow_time"].sel(sweep=s).values
            centre = 0.5 * (gt[f"interval_entry_{s}"].values + gt[f"interval_exit_{s}"].values)
            found = whole & np.isfinite(time)
            out[f"{s} whole-dip coverage / p95 centre"] = (
                round(float(found.sum() / whole.sum()), 4),
                round(float(np.percentile(np.abs(time - centre)[found], 95)), 3))
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dataset", default="synthetic_area")
    args = parser.parse_args(argv)
    results = Path("results") / args.dataset
    out = results / "first_pass"
    out.mkdir(exist_ok=True)
    _first_pass_shadow_time(results, out / "shadow_time.nc")
    manifest = str(results / "capture/capture.json")
    _step("dual-coords", "--shadow-time", str(out / "shadow_time.nc"), "--manifest", manifest, "--model", "uniform",
          "--params", '{"min_coverage":0.01}', "--out", str(out / "dual_coords.nc"))
    _step("dual-view", "--dual-coords", str(out / "dual_coords.nc"), "--shadow-time", str(out / "shadow_time.nc"),
          "--reference", str(results / "frames/reference.zarr"), "--method", "mesh", "--params", '{"min_coverage":0.01}',
          "--intrinsics", "{}", "--out", str(out / "dual_view.nc"))
    _step("accuracy", "--manifest", manifest, "--shadow-time", str(out / "shadow_time.nc"),
          "--dual-coords", str(out / "dual_coords.nc"), "--dual-view", str(out / "dual_view.nc"),
          "--out-json", str(out / "accuracy.json"), "--out-csv", str(out / "accuracy.csv"))
    print(json.dumps({"first pass": _figures(out / "accuracy.json"),
                      "with interval": _figures(results / "accuracy.json")}, indent=1))


if __name__ == "__main__":
    main()
