"""``shadowcam shadow-time-chunk``: track the dips of one time chunk of a sweep (one job).

Feeds the frames ``[START - pad, STOP + pad)`` of a frame store to a
``DipTracker`` that owns frames ``[START, STOP)`` and saves its ``DipPartial``
(``.npz``, written atomically). ``shadowcam shadow-time --partials`` merges the
partials of every chunk into the same result as one streaming pass.

Example::

    shadowcam shadow-time-chunk --frames results/dev_spheres/frames/u.zarr --owned 0:64 \\
        --out results/dev_spheres/shadow_time/u.part0.npz

Offers
------
add_parser : register the step and its options.
run : track the chunk and save the partial.
"""

import logging
from pathlib import Path


from shadowcam.cli.options import parse_frame_range, parse_params
from shadowcam.lab.dip_tracker import DipTracker
from shadowcam.io.frame_store import iter_frame_chunks, open_frames

log = logging.getLogger(__name__)


def add_parser(subparsers, name):
    """Register ``shadow-time-chunk`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="dip tracking of one time chunk of a sweep")
    parser.add_argument("--frames", required=True, help="frame store of the sweep")
    parser.add_argument("--owned", required=True, metavar="START:STOP",
                        help="frames whose dips and sums this chunk contributes (STOP may exceed the sweep)")
    parser.add_argument("--params", default="{}",
                        help="JSON as for shadow-time; only half_window is used here")
    parser.add_argument("--out", required=True, help="partial file (.npz)")
    return parser


def run(args):
    """Track frames around ``args.owned`` of ``args.frames``; save the partial to ``args.out``."""
    params = parse_params(args.params, allowed={"half_window", "method_params", "classify_params"})
    half_window = params.get("half_window", 4)
    frames = open_frames(args.frames)
    n_frames = frames.sizes["time"]
    start, stop = parse_frame_range(args.owned, n_frames, chunk_frames=1, option="--owned")
    out = Path(args.out)
    if out.suffix != ".npz":
        raise ValueError(f"--out must end with .npz; got {out}")
    tracker = DipTracker((frames.sizes["row"], frames.sizes["col"]), half_window=half_window, owned=(start, stop))
    pad = DipTracker.padding(half_window)
    for _, block in iter_frame_chunks(frames, start=max(0, start - pad), stop=stop + pad):
        tracker.update(block)
    out.parent.mkdir(parents=True, exist_ok=True)
    tracker.partial().save(out)
    log.info("frames %d:%d of %s (fed %d:%d) -> %s", start, stop, args.frames,
             max(0, start - pad), min(n_frames, stop + pad), out)
