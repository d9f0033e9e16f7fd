"""Benchmark: the edge-tracking pass as one job and as column strips (peak memory, time, equality).

Builds a wide frame store by tiling the dev_ridge frames side by side (``--tiles``
copies, so the shadow edge, the shake and the levels are real), its photometry
by tiling the first pass's per-pixel maps, then runs ``shadowcam track-edges``
(one job) and ``shadowcam track-edges-strip`` for each of N strips followed by the
merge, each step in its own process, and prints wall time, CPU time and peak RSS
per job and whether the merged edges.nc equals the single job's bit for bit.
Timings are noisy on a shared machine.

    .venv/bin/python scripts/benchmark_edge_strips.py --tiles 16 --strips 2 3 --out /tmp/strips-bench
"""

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import xarray as xr

REPO = Path(__file__).resolve().parents[1]


#: runs one step and prints the process's own peak RSS (VmHWM: ru_maxrss would include the
#: parent's memory at fork time)
CHILD = """import sys
from shadowcam.cli import main
code = main(sys.argv[1:])
peak = [line for line in open('/proc/self/status') if line.startswith('VmHWM')][0].split()[1]
print('PEAK_KB', peak, file=sys.stderr)
sys.exit(code)
"""


def run_step(args):
    """Run ``shadowcam *args`` in a child process; return (wall s, cpu s, peak RSS MiB) of that child."""
    start = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-c", CHILD, *args], stderr=subprocess.PIPE, text=True)
    _, status, usage = os.wait4(proc.pid, 0)
    log = proc.stderr.read()
    if os.waitstatus_to_exitcode(status):
        raise SystemExit(log[-2000:])
    wall = time.perf_counter() - start
    peak_kb = int(log.split("PEAK_KB")[-1].split()[0])
    return round(wall, 2), round(usage.ru_utime + usage.ru_stime, 2), round(peak_kb / 1024, 1)


def prepare(out, tiles):
    from shadowcam.io.decode import iter_frames
    from shadowcam.io.frame_store import write_frames
    from shadowcam.io.datasets import write_netcdf
    from shadowcam.io.manifest import load_manifest
    from shadowcam.outdoor.datasets import photometry_dataset
    from shadowcam.outdoor.normalise import normalise_frames

    sweep = load_manifest(REPO / "data_manifest" / "dev_ridge.yaml")["sweeps"]["timelapse"]
    photometry = normalise_frames(image for _, image, _ in iter_frames(sweep["paths"]))
    for key in ("sky", "lit_at_start", "lit_level", "shadow_level", "reference"):
        photometry[key] = np.concatenate([photometry[key]] * tiles, axis=1)
    write_netcdf(photometry_dataset(photometry, sweep["times_s"]), out / "photometry.nc")
    pngs = out / "pngs"
    pngs.mkdir(exist_ok=True)
    import cv2
    paths = []
    for index, (_, image, _) in enumerate(iter_frames(sweep["paths"])):
        wide = np.concatenate([image] * tiles, axis=1)
        path = pngs / f"{index:06d}.tiff"
        cv2.imwrite(str(path), wide[..., ::-1])  # float32 TIFF, linear
        paths.append(path)
    write_frames(paths, out / "frames.zarr", times_s=sweep["times_s"])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tiles", type=int, default=16, help="copies of the 192-column frames side by side")
    parser.add_argument("--strips", type=int, nargs="+", default=[2, 3])
    parser.add_argument("--out", type=Path, default=Path("/tmp/strips-bench"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    if not (args.out / "frames.zarr").is_dir():
        prepare(args.out, args.tiles)
    common = ["--frames", str(args.out / "frames.zarr"), "--photometry", str(args.out / "photometry.nc")]
    single = args.out / "edges_single.nc"
    report = {"single": run_step(["track-edges", *common, "--out", str(single)])}
    with xr.open_dataset(single, engine="h5netcdf") as ref:
        ref = ref.load()
    for count in args.strips:
        jobs = []
        for index in range(count):
            jobs.append(run_step(["track-edges-strip", *common, "--strip", f"{index}/{count}",
                                  "--out", str(args.out / f"strip{count}_{index}.npz")]))
        merged = args.out / f"edges_{count}.nc"
        files = [str(args.out / f"strip{count}_{index}.npz") for index in range(count)]
        merge = run_step(["track-edges", *common, "--strips", *files, "--out", str(merged)])
        with xr.open_dataset(merged, engine="h5netcdf") as got:
            equal = all(np.array_equal(got[k].values, ref[k].values, equal_nan=ref[k].dtype.kind == "f")
                        for k in ref.data_vars)
        report[f"{count} strips"] = {"jobs (wall s, cpu s, peak MiB)": jobs, "merge": merge, "equal": equal}
    print(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
