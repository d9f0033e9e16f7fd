"""``shadowcam shadow-time``: per-pixel shadow times of a capture's sweeps.

Streams each sweep's frame store (one time chunk at a time) through the
shadow-time method and writes ``results/<ds>/shadow_time.nc``. With
``--partials SWEEP FILE...`` (per sweep) the dips were tracked per time chunk
by ``shadowcam shadow-time-chunk`` jobs: their partials are merged instead
(the result is the same bit for bit).

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
from shadowcam.io.frame_store import iter_frame_chunks, open_frames
from shadowcam.io.provenance import attach_provenance
from shadowcam.lab.dip_tracker import DipPartial, merge_partials
from shadowcam.lab.shadow_time import (
    SHADOW_TIME_METHODS,
    shadow_time_dataset,
    summary_shadow_times,
    sweep_shadow_times,
)

log = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register ``shadow-time`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="per-pixel shadow times of the sweeps",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--frames", nargs="+", required=True, help="frame stores, one per sweep")
    parser.add_argument("--sweeps", nargs="+", required=True, help="sweep names, same order")
    parser.add_argument("--method", default="edge_fit", choices=sorted(SHADOW_TIME_METHODS))
    parser.add_argument("--params", default="{}", help="JSON: half_window, method_params, classify_params")
    parser.add_argument("--partials", nargs="+", action="append", metavar="SWEEP FILE",
                        help="a sweep name and the partial files of all its time chunks (repeat per sweep); "
                             "default: stream the frames")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/shadow_time.nc")
    return parser


def _partials_by_sweep(groups, sweeps):
    """{sweep: [partial paths]} from the ``--partials`` groups; every sweep needs one group."""
    by_sweep = {group[0]: group[1:] for group in groups or []}
    if groups and (set(by_sweep) != set(sweeps) or any(not files for files in by_sweep.values())):
        raise ValueError(f"--partials must name each of the sweeps {sorted(sweeps)} once, each with "
                         f"its partial files; got {sorted(by_sweep)}")
    return by_sweep


def run(args):
    """Compute the shadow times of every sweep and write one dataset."""
    if len(args.frames) != len(args.sweeps):
        raise ValueError(f"--frames has {len(args.frames)} stores but --sweeps names {len(args.sweeps)}")
    params = parse_params(args.params, allowed={"half_window", "method_params", "classify_params"})
    partials = _partials_by_sweep(args.partials, args.sweeps)
    per_sweep, checksums = {}, {}
    for path, sweep in zip(args.frames, args.sweeps):
        frames = open_frames(path)
        n_frames = frames.sizes["time"]
        shape = (frames.sizes["row"], frames.sizes["col"])
        options = dict(method=args.method, cfa_pattern=frames.attrs.get("cfa_pattern") or None,
                       method_params=params.get("method_params"), classify_params=params.get("classify_params"))
        if sweep in partials:
            log.info("sweep %s: merging %d time chunks of %d frames", sweep, len(partials[sweep]), n_frames)
            summary = merge_partials([DipPartial.load(p) for p in partials[sweep]], n_frames=n_frames)
            per_sweep[sweep] = summary_shadow_times(summary, **options)
        else:
            log.info("sweep %s: %d frames of %dx%d from %s", sweep, n_frames, shape[0], shape[1], path)

            def progress(done, sweep=sweep, n_frames=n_frames):
                log.info("sweep %s: %d/%d frames", sweep, done, n_frames)

            per_sweep[sweep] = sweep_shadow_times(
                (block for _, block in iter_frame_chunks(frames)), shape,
                half_window=params.get("half_window", 4), progress=progress, **options)
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
