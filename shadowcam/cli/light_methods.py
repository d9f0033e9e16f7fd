"""``shadowcam light-methods``: speed against error of the timing methods of several minima.

Finds, times and assigns every pixel's minima to the lights of a several-lights capture
with each timing method the minima accept, measures wall time, throughput, peak memory
and per-light error against the capture's ground truth
(:func:`shadowcam.evaluate.methods_comparison.compare_light_set_methods`), and writes the
table (netCDF and CSV) and the speed-versus-error chart with the Pareto front.

Example::

    shadowcam light-methods --manifest results/synthetic_lights/lights/capture/capture.json \\
        --dataset synthetic_lights \\
        --out results/synthetic_lights/lights/methods/methods.nc \\
        --csv results/synthetic_lights/lights/methods/methods.csv \\
        --figure results/synthetic_lights/lights/methods/speed_vs_error.png

Offers
------
add_parser : register the step and its options.
run : measure and write the comparison.
"""

from shadowcam.cli.methods_comparison import write_comparison
from shadowcam.io.capture_plan import capture_plan


def add_parser(subparsers, name):
    """Register ``light-methods`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="speed against error of the several-minima methods")
    parser.add_argument("--manifest", required=True,
                        help="several-lights manifest with ground_truth: a rendered capture.json or data_manifest/<ds>.yaml")
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
    from shadowcam.lab.light_files import light_set_capture_of_plan

    capture = light_set_capture_of_plan(capture_plan(args.manifest))
    dataset = compare_light_set_methods(capture, half_window=args.half_window)
    write_comparison(dataset, args, name=args.dataset,
                     config={"half_window": args.half_window}, step="light-methods")
