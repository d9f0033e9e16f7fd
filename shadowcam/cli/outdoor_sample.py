"""``shadowcam outdoor-sample``: a real-size RAW time-lapse sample and its manifest.

Steadies consecutive frames of a small outdoor capture (e.g. dev_ridge; its
recorded shake from the ground truth undone), upsamples them to a camera's
size, shakes them by a seeded realistic amount (``--shake-px``, sub-pixel to
2 px), adds full-resolution sensor noise and writes 14-bit RGGB DNGs
(:mod:`shadowcam.synthetic.outdoor.sample`, :mod:`shadowcam.io.raw_writer`), a sidecar with
the frame times and the applied shake (``timestamps.json``: ``times_s``,
``shake_dx_px``, ``shake_dy_px``) and a checksummed ``kind: outdoor`` manifest,
for the throughput and memory benchmark (``make bench-outdoor-size``), which
also measures the registration against the recorded shake. No arrival-time
ground truth at that size.

Offers
------
add_parser : register the step and its options.
run : write the sample and print the manifest path.
"""

import datetime
import json
import logging
from pathlib import Path

import numpy as np
import yaml

from shadowcam.io.decode import read_frame
from shadowcam.io.ground_truth import load_ground_truth
from shadowcam.io.manifest import checksums_for, load_manifest
from shadowcam.synthetic.outdoor.sample import parse_size, sample_mosaic, sample_shake, steady_frame, upsample_frame
from shadowcam.io.raw_writer import write_dng
from shadowcam.synthetic.sensor import SensorModel, electrons_per_unit_radiance

log = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register ``outdoor-sample`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="write a real-size DNG time-lapse sample (benchmarks)",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--source", required=True, help="manifest of a small outdoor capture (data_manifest/dev_ridge.yaml)")
    parser.add_argument("--size", default="6000x4000", help="COLSxROWS of the sample (default 6000x4000 = 24 MP)")
    parser.add_argument("--frames", type=int, default=16, help="number of frames")
    parser.add_argument("--first", type=int, default=40, help="first source frame used")
    parser.add_argument("--bit-depth", type=int, default=14, help="sensor bit depth")
    parser.add_argument("--seed", type=int, default=0, help="noise and shake seed")
    parser.add_argument("--shake-px", type=float, default=2.0,
                        help="largest camera shake of the sample, pixels (0: none; default 2)")
    parser.add_argument("--name", required=True, help="dataset name")
    parser.add_argument("--outdir", required=True, help="directory of the frames (root of the new dataset)")
    parser.add_argument("--manifest-out", required=True, help="manifest to write, e.g. <workdir>/data_manifest/<name>.yaml")
    return parser


def run(args):
    """Write the sample frames, timestamps and manifest."""
    rows, cols = parse_size(args.size)
    source = load_manifest(args.source)
    if source.get("kind") != "outdoor" or len(source["sweeps"]) != 1:
        raise ValueError(f"--source {args.source} must be an outdoor capture with one sweep")
    sweep = next(iter(source["sweeps"].values()))
    stop = args.first + args.frames
    if args.frames < 3 or args.first < 0 or stop > len(sweep["paths"]):
        raise ValueError(f"--first {args.first} --frames {args.frames}: the source has {len(sweep['paths'])} frames; "
                         "take at least 3 inside it")
    times = np.asarray(sweep["times_s"][args.first:stop], dtype=np.float64)
    times -= times[0]
    source_dx, source_dy = _source_shake(source, args.first, stop)
    shake_dx, shake_dy = sample_shake(args.frames, seed=args.seed, max_px=args.shake_px)
    sensor = SensorModel(bit_depth=args.bit_depth, black_level=512, gain=1.0, read_noise=3.0)

    def steady(k):
        return steady_frame(read_frame(sweep["paths"][args.first + k]), dx=source_dx[k], dy=source_dy[k])

    scale = electrons_per_unit_radiance(upsample_frame(steady(0), rows=rows, cols=cols), sensor=sensor, target_fraction=0.7)
    outdir = Path(args.outdir)
    (outdir / "frames").mkdir(parents=True, exist_ok=True)
    start_time = datetime.datetime(2026, 1, 15, 16, 0, 0)
    names = []
    for k in range(args.frames):
        raw = sample_mosaic(steady(k), rows=rows, cols=cols, sensor=sensor, scale=scale, seed=[args.seed, k],
                            shake=(shake_dx[k], shake_dy[k]))
        name = f"frames/{k:06d}.dng"
        write_dng(outdir / name, raw, bit_depth=sensor.bit_depth, black_level=sensor.black_level,
                  capture_time=start_time + datetime.timedelta(seconds=float(times[k])))
        names.append(name)
        log.info("wrote %s (%d/%d), shake dx %+.3f dy %+.3f px", name, k + 1, args.frames, shake_dx[k], shake_dy[k])
    sidecar = {"units": "s", "times_s": times.tolist(), "files": names,
               "shake_dx_px": shake_dx.tolist(), "shake_dy_px": shake_dy.tolist(),
               "shake_convention": "frame(u, v) = image(u - dx, v - dy): content moves by +dx (cols), +dy (rows)"}
    (outdir / "timestamps.json").write_text(json.dumps(sidecar))
    manifest = {
        "name": args.name,
        "kind": "outdoor",
        "description": f"{args.frames} frames of {source['name']} (from frame {args.first}) upsampled to "
                       f"{cols}x{rows}, {args.bit_depth}-bit RGGB DNG with full-resolution sensor noise, "
                       f"source shake undone, camera shake <= {args.shake_px:g} px applied (timestamps.json: "
                       "shake_dx_px, shake_dy_px) (benchmark sample, no arrival-time ground truth)",
        "light": "distant",
        "root": str(outdir.resolve()),
        "sweeps": {"timelapse": {"files": "frames/*.dng"}},
        "timing": {"source": "sidecar", "file": "timestamps.json", "key": "times_s"},
        "provenance": f"shadowcam outdoor-sample from {args.source}, seed {args.seed}",
        "licence": source.get("licence", "CC0-1.0"),
    }
    out = Path(args.manifest_out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(yaml.safe_dump(manifest, sort_keys=False))
    manifest["checksums"] = checksums_for(out)
    out.write_text(yaml.safe_dump(manifest, sort_keys=False))
    print(out)


def _source_shake(source, first, stop):
    """Recorded shake ``(dx, dy)`` of the source frames ``first .. stop - 1`` (zeros if unknown)."""
    if "ground_truth" in source:
        truth = load_ground_truth(source)
        if "shake_dx_px" in truth:
            return truth["shake_dx_px"].values[first:stop], truth["shake_dy_px"].values[first:stop]
    log.warning("source %s records no shake: its shake (if any) is upsampled with the frames", source["name"])
    return np.zeros(stop - first), np.zeros(stop - first)
