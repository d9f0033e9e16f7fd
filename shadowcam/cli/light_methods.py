"""``shadowcam light-methods``: speed against error of the timing methods of several minima.

Finds, times and assigns every pixel's minima to the lights of a several-lights capture
with each timing method the minima accept, measures wall time, throughput, peak memory
and per-light error against the renderer's times
(:func:`shadowcam.evaluate.methods_comparison.compare_light_set_methods`), and writes the
table (netCDF and CSV) and the speed-versus-error chart with the Pareto front.

Example::

    shadowcam light-methods --capture results/synthetic_lights/lights/capture.nc --dataset synthetic_lights \\
        --out results/synthetic_lights/lights/methods/methods.nc \\
        --csv results/synthetic_lights/lights/methods/methods.csv \\
        --figure results/synthetic_lights/lights/methods/speed_vs_error.png

Offers
------
add_parser : register the step and its options.
run : measure and write the comparison.
"""

import xarray as xr

from shadowcam.cli.methods_comparison import write_comparison


def add_parser(subparsers, name):
    """Register ``light-methods`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="speed against error of the several-minima methods")
    parser.add_argument("--capture", required=True, help="capture.nc written by render-lights")
    parser.add_argument("--half-window", type=int, default=4,
                        help="frames: at least half the widest dip, as for light-views; default 4")
    parser.add_argument("--dataset", default="capture", help="dataset name for the chart's title and provenance")
    parser.add_argument("--out", required=True, help="results/<ds>/lights/methods/methods.nc")
    parser.add_argument("--csv", required=True, help="results/<ds>/lights/methods/methods.csv")
    parser.add_argument("--figure", required=True, help="results/<ds>/lights/methods/speed_vs_error.png")
    return parser


def run(args):
    """Measure every several-minima method against the renderer and write table and chart."""
    from shadowcam.evaluate.methods_comparison import compare_light_set_methods

    with xr.open_dataset(args.capture) as opened:
        capture = opened.load()
    dataset = compare_light_set_methods(capture, half_window=args.half_window)
    write_comparison(dataset, args, name=args.dataset,
                     config={"half_window": args.half_window}, step="light-methods")
