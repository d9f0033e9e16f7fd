"""``shadowcam shadow-time``: per-pixel shadow times of a capture's sweeps.

Streams each sweep's frame store (one time chunk at a time) through the
shadow-time method and writes ``results/<ds>/shadow_time.nc``.

Offers
------
add_parser : register the step and its options.
run : compute and write the dataset.
"""

import json
import logging
import os
from pathlib import Path

from shadowcam.cli.options import parse_params
from shadowcam.frame_store import iter_frame_chunks, open_frames
from shadowcam.provenance import attach_provenance
from shadowcam.shadow_time import SHADOW_TIME_METHODS, shadow_time_dataset, sweep_shadow_times

log = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register ``shadow-time`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="per-pixel shadow times of the sweeps",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--frames", nargs="+", required=True, help="frame stores, one per sweep")
    parser.add_argument("--sweeps", nargs="+", required=True, help="sweep names, same order")
    parser.add_argument("--method", default="edge_fit", choices=sorted(SHADOW_TIME_METHODS))
    parser.add_argument("--params", default="{}", help="JSON: half_window, method_params, classify_params")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/shadow_time.nc")
    return parser


def run(args):
    """Compute the shadow times of every sweep and write one dataset."""
    if len(args.frames) != len(args.sweeps):
        raise ValueError(f"--frames has {len(args.frames)} stores but --sweeps names {len(args.sweeps)}")
    params = parse_params(args.params, allowed={"half_window", "method_params", "classify_params"})
    per_sweep, checksums = {}, {}
    for path, sweep in zip(args.frames, args.sweeps):
        frames = open_frames(path)
        n_frames = frames.sizes["time"]
        shape = (frames.sizes["row"], frames.sizes["col"])
        log.info("sweep %s: %d frames of %dx%d from %s", sweep, n_frames, shape[0], shape[1], path)

        def progress(done, sweep=sweep, n_frames=n_frames):
            log.info("sweep %s: %d/%d frames", sweep, done, n_frames)

        per_sweep[sweep] = sweep_shadow_times(
            (block for _, block in iter_frame_chunks(frames)), shape,
            method=args.method, cfa_pattern=frames.attrs.get("cfa_pattern") or None,
            half_window=params.get("half_window", 4), method_params=params.get("method_params"),
            classify_params=params.get("classify_params"), progress=progress,
        )
        checksums.update(json.loads(frames.attrs.get("input_checksums", "{}")))
    config = {"method": args.method, **params}
    dataset = attach_provenance(shadow_time_dataset(per_sweep), config=config,
                                input_checksums=checksums, step="shadow-time")
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(out.name + ".tmp")
    dataset.to_netcdf(tmp, engine="h5netcdf")
    os.replace(tmp, out)
    log.info("wrote %s", out)
