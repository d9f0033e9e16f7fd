"""``shadowcam track-edges-strip``: the edge-tracking pass on one column strip (one job).

Reads only the strip's window (its columns plus a halo for the registration
shift and the frame-differencing widening, :mod:`shadowcam.outdoor.strips`) of
every frame, tracks it (:func:`shadowcam.outdoor.edges.track_column_strip`) and saves
the strip (``.npz``, written atomically). ``shadowcam track-edges --strips`` merges the
strips of a frame into exactly the single job's edges.

Example::

    shadowcam track-edges-strip --frames results/dev_ridge/frames/timelapse.zarr \\
        --photometry results/dev_ridge/outdoor/photometry.nc --strip 0/3 \\
        --out results/dev_ridge/outdoor/edges.strip0.npz

Offers
------
add_parser : register the step and its options.
run : track the strip and save it.
"""

import logging
from pathlib import Path

from shadowcam.cli.options import parse_params, parse_strip
from shadowcam.io.datasets import open_dataset
from shadowcam.io.frame_store import open_frames
from shadowcam.outdoor.edges import KEYFRAME_OPTIONS, TRACK_OPTIONS, track_column_strip
from shadowcam.outdoor.strips import save_strip

log = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register ``track-edges-strip`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="edge tracking of one column strip of the frames")
    parser.add_argument("--frames", required=True, help="frame store of the time-lapse sweep")
    parser.add_argument("--photometry", required=True, help="results/<ds>/outdoor/photometry.nc")
    parser.add_argument("--strip", required=True, metavar="I/N", help="strip I (from 0) of N equal column strips")
    parser.add_argument("--params", default="{}", help="JSON as for track-edges (keyframe options ignored)")
    parser.add_argument("--out", required=True, help="strip file (.npz)")
    return parser


def run(args):
    """Track the strip ``args.strip`` of ``args.frames`` and save it to ``args.out``."""
    params = parse_params(args.params, allowed=TRACK_OPTIONS | KEYFRAME_OPTIONS)
    if Path(args.out).suffix != ".npz":
        raise ValueError(f"--out must end with .npz; got {args.out}")
    index, count = parse_strip(args.strip)
    strip = track_column_strip(open_frames(args.frames), open_dataset(args.photometry),
                               index=index, count=count, **params)
    save_strip(strip, args.out)
    log.info("wrote %s", args.out)
