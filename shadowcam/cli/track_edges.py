"""``shadowcam track-edges``: the shadow edge of every frame, with keyframe interpolation.

Second streaming pass (:func:`shadowcam.outdoor.edges.track_edges`): coverage, frame
differencing, sub-pixel column edges with confidence, and the per-pixel
coverage crossing; then keyframes and interpolation in seconds of the edges
of unreliable frames. Writes ``results/<ds>/outdoor/edges.nc``. With ``--strips`` the
pass is not run here: the column strips of ``shadowcam track-edges-strip`` jobs are
merged (:func:`shadowcam.outdoor.edges.edges_from_strips`, equal to one job bit for bit).

Example::

    shadowcam track-edges --frames results/dev_ridge/frames/timelapse.zarr \\
        --photometry results/dev_ridge/outdoor/photometry.nc --out results/dev_ridge/outdoor/edges.nc

Offers
------
add_parser : register the step and its options.
run : track and write the dataset.
"""

from shadowcam.cli.options import parse_params
from shadowcam.io.datasets import open_dataset, write_dataset
from shadowcam.io.frame_store import open_frames
from shadowcam.outdoor.edges import KEYFRAME_OPTIONS, TRACK_OPTIONS, edges_from_strips, track_edges
from shadowcam.outdoor.strips import load_strip


def add_parser(subparsers, name):
    """Register ``track-edges`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="track the shadow edge per frame; keyframe interpolation")
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
    if args.strips:
        dataset = edges_from_strips([load_strip(path) for path in args.strips], photometry,
                                    frames["time_s"].values, width=frames.sizes["col"], **params)
    else:
        dataset = track_edges(frames, photometry, **params)
    write_dataset(dataset, args.out, config=params, inputs=(frames, photometry), step="track-edges")
