"""``shadowcam bench``: speed of the shadow-time pipeline against its floors (``make bench``).

Renders its own DNG sweep (reused on later runs), then prints end-to-end
throughput against the decode floor, the shadow-time stage against one numpy
pass, peak memory for a short and a long sequence, and the default
configuration's accuracy. Not part of the test suite.

Example::

    shadowcam bench --compression none --frames 96 --json results/bench/figures-none.json

Offers
------
add_parser : register the step and its options.
run : run the benchmark and print the figures.
"""

import json
from pathlib import Path

from shadowcam.evaluate.speed_benchmark import WireScene, format_report, run_benchmark


def add_parser(subparsers, name):
    """Register ``bench`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="speed benchmark (make bench)")
    parser.add_argument("--dir", help="where the DNG sweep is rendered (default results/bench/dng-<compression>)")
    parser.add_argument("--compression", choices=("ljpeg", "none"), default="ljpeg",
                        help="DNG compression: lossless JPEG as cameras write (default), or none")
    parser.add_argument("--frames", type=int, default=1000, help="frames of the long sequence")
    parser.add_argument("--short", type=int, default=100, help="frames of the short sequence")
    parser.add_argument("--height", type=int, default=1200, help="frame rows, pixels")
    parser.add_argument("--width", type=int, default=1600, help="frame cols, pixels")
    parser.add_argument("--workers", type=int, default=2, help="processes (cores)")
    parser.add_argument("--json", help="also write the figures to this JSON file")
    return parser


def run(args):
    """Run the benchmark and print its report."""
    if not 0 < args.short < args.frames:
        raise ValueError(f"--short must be in (0, --frames), got {args.short} and {args.frames}")
    # keep the shadow crossing the whole image during the long sequence
    span = args.width + 0.3 * args.height
    scene = WireScene(height=args.height, width_px=args.width, n_frames=args.frames,
                      px_per_frame=span / max(args.frames - 20, 1))
    directory = args.dir or f"results/bench/dng-{args.compression}"
    figures = run_benchmark(directory, scene=scene, short=args.short, workers=args.workers,
                            stage_frames=min(240, args.frames), compression=args.compression,
                            log=lambda m: print(m, flush=True))
    print()
    print(format_report(figures))
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(figures, indent=2))
