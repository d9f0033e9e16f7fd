"""``shadowcam track-edges``: the shadow edge of every frame, with keyframe interpolation.

Second streaming pass (:mod:`shadowcam.outdoor.tracking`): coverage, frame
differencing, sub-pixel column edges with confidence, and the per-pixel
coverage crossing; then keyframes and interpolation in seconds of the edges
of unreliable frames (:mod:`shadowcam.outdoor.keyframes`). Writes
``results/<ds>/outdoor/edges.nc``. With ``--strips`` the pass is not run here:
the column strips of ``shadowcam track-edges-strip`` jobs are merged
(:func:`shadowcam.outdoor.strips.merge_strips`, equal to one job bit for bit).

Offers
------
add_parser : register the step and its options.
run : track and write the dataset.
"""

import json

from shadowcam.cli.options import parse_params
from shadowcam.cli.outdoor_io import input_checksums, iter_frames, open_dataset, write_dataset
from shadowcam.io.frame_store import open_frames
from shadowcam.io.frame_times import find_gaps, median_interval
from shadowcam.outdoor.keyframes import interpolate_edges, select_keyframes
from shadowcam.outdoor.datasets import edges_dataset, photometry_arrays
from shadowcam.outdoor.strips import merge_strips
from shadowcam.outdoor.tracking import track_frames

TRACK_OPTIONS = {"half_window", "min_drop", "margin", "max_step", "lit_update", "update_distance"}
KEYFRAME_OPTIONS = {"min_confidence", "min_found_fraction"}


def add_parser(subparsers, name):
    """Register ``track-edges`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="track the shadow edge per frame; keyframe interpolation",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--frames", required=True, help="frame store of the time-lapse sweep")
    parser.add_argument("--photometry", required=True, help="results/<ds>/outdoor/photometry.nc")
    parser.add_argument("--params", default="{}",
                        help=f"JSON: {', '.join(sorted(TRACK_OPTIONS | KEYFRAME_OPTIONS))}")
    parser.add_argument("--strips", nargs="+", metavar="NPZ",
                        help="column strips of track-edges-strip to merge instead of tracking here")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/outdoor/edges.nc")
    return parser


def run(args):
    """Track the edges and write the edges dataset."""
    params = parse_params(args.params, allowed=TRACK_OPTIONS | KEYFRAME_OPTIONS)
    frames = open_frames(args.frames)
    photometry = open_dataset(args.photometry)
    arrays = photometry_arrays(photometry)
    time_s = frames["time_s"].values
    if args.strips:
        from shadowcam.cli.track_edges_strip import load_strip  # (imports this module)

        tracked = merge_strips([load_strip(path) for path in args.strips])
        if tracked["edge_row"].shape != (time_s.size, frames.sizes["col"]):
            raise ValueError(f"--strips {args.strips[0]} ...: shape {tracked['edge_row'].shape} does not "
                             f"match the frames {args.frames}; rerun track-edges-strip")
    else:
        tracked = track_frames(iter_frames(frames), arrays, time_s,
                               **{k: v for k, v in params.items() if k in TRACK_OPTIONS})
    key_options = {k: v for k, v in params.items() if k in KEYFRAME_OPTIONS}
    is_keyframe = select_keyframes(tracked["confidence"], tracked["edge_row"], **key_options)
    edge_row, interpolated = interpolate_edges(
        tracked["edge_row"], tracked["confidence"], time_s, is_keyframe=is_keyframe,
        min_confidence=key_options.get("min_confidence", 0.6))
    dataset = edges_dataset(tracked, arrays, time_s, edge_row=edge_row, is_keyframe=is_keyframe,
                            interpolated=interpolated)
    dataset.attrs.update(median_interval_s=median_interval(time_s), gaps=json.dumps(find_gaps(time_s)))
    write_dataset(dataset, args.out, config=params, checksums=input_checksums(frames, photometry),
                  step="track-edges")
