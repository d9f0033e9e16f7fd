"""Command line interface: ``shadowcam <step> ...``.

Each step lives in its own module of this package and exposes
``add_parser(subparsers, name)`` (which registers the step and its options) and
``run(args)``; its ``--help`` text and example come from the module docstring
(:mod:`shadowcam.cli.help_text`). Snakemake rules call exactly one step each.
"""

import argparse
import importlib
import logging
import sys

from shadowcam import __version__
from shadowcam.cli.help_text import DESCRIPTION, step_texts

#: step name -> module (inside ``shadowcam.cli``) that implements it
STEPS = {
    "render": "render",
    "checksum": "checksum",
    "decode": "decode",
    "merge-frames": "merge_frames",
    "shadow-time": "shadow_time", "shadow-time-chunk": "shadow_time_chunk", "viewpoint": "viewpoint",
    "render-array": "render_array", "camera-array": "camera_array", "array-accuracy": "array_accuracy",
    "render-lights": "render_lights", "light-views": "light_views", "light-accuracy": "light_accuracy",
    "dual-coords": "dual_coords", "dual-view": "dual_view",
    "accuracy": "accuracy",
    "report-figures": "report_figures",
    "evaluate": "evaluate",
    "plan": "plan",
    "outdoor-normalise": "outdoor_normalise", "outdoor-sky-mask": "outdoor_sky_mask",
    "outdoor-merge-photometry": "outdoor_merge_photometry",
    "track-edges": "track_edges",
    "track-edges-strip": "track_edges_strip",
    "arrival": "arrival",
    "pushbroom": "pushbroom", "lab-pushbroom": "lab_pushbroom",  # ridge (outdoor), single-sweep lab
    "outdoor-accuracy": "outdoor_accuracy",
    "outdoor-figures": "outdoor_figures",
    "bench": "bench",
    "methods-comparison": "methods_comparison", "light-methods": "light_methods",
    "outdoor-sample": "outdoor_sample",
    "bench-report": "bench_report", "render-lightfield": "render_lightfield",  # light field: and lightfield-<stage>
    **{f"lightfield-{s}": f"lightfield_{s.replace('-', '_')}" for s in "hdr shadow-times rays render export truth accuracy report".split()}}


def build_parser(steps=None):
    """Return the top-level argument parser with every available step (or only `steps`).

    A job runs one step, so :func:`main` registers only that one: importing every
    step's libraries (plotting, compiled kernels, ...) would add seconds to each job.
    """
    parser = argparse.ArgumentParser(prog="shadowcam", description=DESCRIPTION,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=__version__)
    parser.add_argument("-v", "--verbose", action="store_true", help="debug logging")
    subparsers = parser.add_subparsers(dest="step", required=True, metavar="STEP")
    for name, module_name in STEPS.items():
        if steps is not None and name not in steps:
            continue
        try:
            module = importlib.import_module(f"shadowcam.cli.{module_name}")
        except ModuleNotFoundError as exc:
            if exc.name == f"shadowcam.cli.{module_name}":
                continue  # step not part of this installation
            raise
        sub = module.add_parser(subparsers, name)
        sub.description, sub.epilog = step_texts(module.__doc__)
        sub.formatter_class = argparse.RawDescriptionHelpFormatter
        sub.set_defaults(run=module.run)
    return parser


def main(argv=None):
    """Entry point of the ``shadowcam`` command."""
    argv = sys.argv[1:] if argv is None else list(argv)
    positional = [a for a in argv if not a.startswith("-")][:1]
    parser = build_parser(positional if positional and positional[0] in STEPS else None)
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.DEBUG if args.verbose else logging.INFO,
        format="%(asctime)s %(levelname)s %(name)s: %(message)s",
    )
    try:
        args.run(args)
    except (ValueError, FileNotFoundError) as exc:
        # user-facing errors: say what is wrong, no traceback
        print(f"shadowcam {args.step}: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
