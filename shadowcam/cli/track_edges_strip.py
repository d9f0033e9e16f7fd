"""``shadowcam track-edges-strip``: the edge-tracking pass on one column strip (one job).

Reads only the strip's window (its columns plus a halo for the registration
shift and the frame-differencing widening, :mod:`shadowcam.outdoor.strips`) of
every frame, tracks it and saves the strip (``.npz``, written atomically).
``shadowcam track-edges --strips`` merges the strips of a frame into exactly
the single job's edges.

Offers
------
add_parser : register the step and its options.
run : track the strip and save it.
save_strip : write a strip (:func:`shadowcam.outdoor.strips.track_strip`) to ``.npz``.
load_strip : read it back.
"""

import logging
from pathlib import Path

import numpy as np

from shadowcam.cli.options import parse_params
from shadowcam.cli.outdoor_io import iter_frames, open_dataset
from shadowcam.cli.track_edges import KEYFRAME_OPTIONS, TRACK_OPTIONS
from shadowcam.io.frame_store import open_frames
from shadowcam.io.images import atomic_path
from shadowcam.outdoor.datasets import photometry_arrays
from shadowcam.outdoor.strips import strip_bounds, strip_halo, strip_window, track_strip

log = logging.getLogger(__name__)

STRIP_KEYS = ("cols", "kept", "width", "edge_row", "confidence", "n_transitions", "coverage_arrival_s",
              "band_count", "valid_count")


def add_parser(subparsers, name):
    """Register ``track-edges-strip`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="edge tracking of one column strip of the frames",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--frames", required=True, help="frame store of the time-lapse sweep")
    parser.add_argument("--photometry", required=True, help="results/<ds>/outdoor/photometry.nc")
    parser.add_argument("--strip", required=True, metavar="I/N", help="strip I (from 0) of N equal column strips")
    parser.add_argument("--params", default="{}", help="JSON as for track-edges (keyframe options ignored)")
    parser.add_argument("--out", required=True, help="strip file (.npz)")
    return parser


def parse_strip(text):
    """Return ``(index, count)`` of an ``I/N`` strip argument."""
    try:
        index, count = (int(v) for v in text.split("/"))
    except ValueError:
        raise ValueError(f"--strip must be I/N (e.g. 0/3); got {text!r}") from None
    if not 0 <= index < count:
        raise ValueError(f"--strip {text}: I must be in [0, N)")
    return index, count


def save_strip(strip, path):
    """Write `strip` to `path` (``.npz``) atomically."""
    with atomic_path(Path(path)) as tmp:
        np.savez(tmp, **{key: np.asarray(strip[key]) for key in STRIP_KEYS})


def load_strip(path):
    """Read a strip written by :func:`save_strip` (dict as :func:`shadowcam.outdoor.strips.track_strip`)."""
    with np.load(path) as data:
        missing = set(STRIP_KEYS) - set(data.files)
        if missing:
            raise ValueError(f"{path} is not an edge-tracking strip: missing {sorted(missing)}; rerun track-edges-strip")
        strip = {key: data[key] for key in STRIP_KEYS}
    for key in ("cols", "kept"):
        strip[key] = tuple(int(v) for v in strip[key])
    for key in ("width", "valid_count"):
        strip[key] = int(strip[key])
    return strip


def run(args):
    """Track the strip ``args.strip`` of ``args.frames`` and save it to ``args.out``."""
    params = parse_params(args.params, allowed=TRACK_OPTIONS | KEYFRAME_OPTIONS)
    options = {k: v for k, v in params.items() if k in TRACK_OPTIONS}
    out = Path(args.out)
    if out.suffix != ".npz":
        raise ValueError(f"--out must end with .npz; got {out}")
    index, count = parse_strip(args.strip)
    frames = open_frames(args.frames)
    arrays = photometry_arrays(open_dataset(args.photometry))
    width = frames.sizes["col"]
    cols = strip_bounds(width, count)[index]
    halo = strip_halo(arrays["shift"], margin=options.get("margin", 2))
    a, b = strip_window(cols, halo, width)
    log.info("strip %d/%d: columns %d:%d, reading %d:%d (halo %d)", index, count, *cols, a, b, halo)
    strip = track_strip(iter_frames(frames.isel(col=slice(a, b))), arrays, frames["time_s"].values,
                        cols=cols, halo=halo, **options)
    out.parent.mkdir(parents=True, exist_ok=True)
    save_strip(strip, out)
    log.info("wrote %s", out)
