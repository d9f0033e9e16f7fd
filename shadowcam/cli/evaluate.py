"""``shadowcam evaluate``: the simulation study (paper II-C, Fig. 5), reproduced and extended.

Example::

    shadowcam evaluate --params '{"levels": {"frames": [96, 48, 12]}, "size": 64}' \\
        --out results/evaluate/study.nc --figures results/evaluate/figures

``--params`` (JSON): ``levels`` (factor -> values, factors of
``shadowcam.evaluate.simulation_study.FACTORS``), ``baseline`` (factor -> value), and the options
``scene``, ``size``, ``supersample``, ``seed``, ``method``, ``half_window``,
``dual_view_method`` of ``simulate_setting`` (:mod:`shadowcam.evaluate.study_report`). Writes the
study dataset (dims ``factor, level``) and one figure ``study_<factor>.png`` per factor, and
prints a table per factor. Outputs appear only when complete.

Offers
------
add_parser : register the step and its options.
run : run the study and write its dataset and figures.
"""

from shadowcam.cli.options import parse_params
from shadowcam.evaluate.study_report import STUDY_OPTIONS, format_table, study_from_params, write_study_figures
from shadowcam.io.datasets import write_dataset


def add_parser(subparsers, name):
    """Register ``evaluate`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="simulation study of the dual pipeline (Fig. 5)")
    parser.add_argument("--params", default="{}",
                        help="JSON: levels, baseline, scene, size, supersample, seed, method, "
                             "half_window, dual_view_method")
    parser.add_argument("--out", required=True, help="study dataset, results/evaluate/study.nc")
    parser.add_argument("--figures", default=None, help="directory of the figures")
    return parser


def run(args):
    """Run the study, write the dataset (and figures), print the tables."""
    params = parse_params(args.params, allowed={"levels", "baseline", *STUDY_OPTIONS})
    study = write_dataset(study_from_params(params), args.out, config=params, step="evaluate")
    if args.figures:
        write_study_figures(study, args.figures)
    print(format_table(study))
    print(f"study: {study.sizes['factor']} factors, "
          f"{int(study['value'].notnull().sum())} settings in {study.attrs['total_runtime_s']:.1f} s")
