"""``shadowcam evaluate``: the simulation study (paper II-C, Fig. 5), reproduced and extended.

Usage::

    shadowcam evaluate --params '{"levels": {"frames": [96, 48, 12]}, "size": 64}' \\
        --out results/evaluate/study.nc --figures results/evaluate/figures

``--params`` (JSON): ``levels`` (factor -> values, factors of
``shadowcam.evaluate.simulation_study.FACTORS``), ``baseline`` (factor -> value), and the options
``scene``, ``size``, ``supersample``, ``seed``, ``method``, ``half_window``,
``dual_view_method`` of ``simulate_setting``. Writes the study dataset (dims
``factor, level``) and one figure ``study_<factor>.png`` per factor, and prints a table
per factor. Outputs appear only when complete.

Offers
------
add_parser : register the step and its options.
run : run the study and write its dataset and figures.
format_table : the study's numbers as plain-text tables, one per factor.
"""

import logging
import os
import shutil
import time
from pathlib import Path

from shadowcam.cli.options import parse_params

log = logging.getLogger(__name__)

OPTIONS = ("scene", "size", "supersample", "seed", "method", "half_window", "dual_view_method")
#: columns of the printed table: metric -> header
TABLE_COLUMNS = {"rel_rmse_whole": "err_whole", "rel_rmse_masked": "err_mask",
                 "dual_coord_rmse": "uv_rmse", "dual_coord_coverage": "uv_cover",
                 "shadow_time_p95": "t_p95", "dual_coverage": "dual_cov", "runtime": "sec"}


def add_parser(subparsers, name):
    """Register ``evaluate`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="simulation study of the dual pipeline (Fig. 5)",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--params", default="{}",
                        help="JSON: levels, baseline, scene, size, supersample, seed, method, "
                             "half_window, dual_view_method")
    parser.add_argument("--out", required=True, help="study dataset, results/evaluate/study.nc")
    parser.add_argument("--figures", default=None, help="directory of the figures")
    return parser


def format_table(study):
    """Plain-text tables of a study dataset, one block per factor.

    Parameters
    ----------
    study : xarray.Dataset
        As returned by ``shadowcam.evaluate.simulation_study.run_study``.

    Returns
    -------
    str
    """
    lines = []
    for factor in study["factor"].values:
        sub = study.sel(factor=factor)
        unit = str(sub["factor_units"].values)
        lines.append(f"{factor} ({unit})")
        lines.append(f"{'value':>8} " + " ".join(f"{h:>9}" for h in TABLE_COLUMNS.values()))
        for level in sub["level"].values:
            value = float(sub["value"].sel(level=level))
            if value != value:  # NaN: this factor has fewer levels
                continue
            cells = " ".join(f"{float(sub[m].sel(level=level)):9.3f}" for m in TABLE_COLUMNS)
            lines.append(f"{value:8.3g} {cells}")
        lines.append("")
    return "\n".join(lines)


def _write_figures(study, outdir):
    from shadowcam.report.figures import save_png, study_factor_figure

    outdir = Path(outdir)
    tmp = outdir.parent / f".{outdir.name}.tmp-{os.getpid()}"
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    try:
        for factor in study["factor"].values:
            sub = study.sel(factor=factor)
            figure = study_factor_figure(
                sub["value"].values, whole=sub["rel_rmse_whole"].values,
                masked=sub["rel_rmse_masked"].values, coord_error=sub["dual_coord_rmse"].values,
                factor=str(factor), unit=str(sub["factor_units"].values))
            save_png(figure, tmp / f"study_{factor}.png")
        shutil.rmtree(outdir, ignore_errors=True)
        tmp.rename(outdir)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def run(args):
    """Run the study, write the dataset (and figures), print the tables."""
    from dataclasses import replace

    from shadowcam._shared.atomic import atomic_path
    from shadowcam.io.provenance import attach_provenance
    from shadowcam.evaluate.simulation_study import BASELINE, FACTORS, run_study

    params = parse_params(args.params, allowed={"levels", "baseline", *OPTIONS})
    levels = params.get("levels") or {}
    baseline = params.get("baseline") or {}
    unknown = set(baseline) - set(FACTORS)
    if unknown:
        raise ValueError(f"--params baseline: unknown factors {sorted(unknown)}; "
                         f"choose from {list(FACTORS)}")
    options = {k: params[k] for k in OPTIONS if k in params}
    started = time.perf_counter()

    def progress(factor, value, metrics):
        log.info("%s = %g: whole %.3f, mask %.3f, uv rmse %.3f (%.1f s)", factor, value,
                 metrics["rel_rmse_whole"], metrics["rel_rmse_masked"],
                 metrics["dual_coord_rmse"], metrics["runtime"])

    study = run_study(levels, baseline=replace(BASELINE, **baseline), progress=progress,
                      **options)
    elapsed = time.perf_counter() - started
    study.attrs["total_runtime_s"] = elapsed
    study = attach_provenance(study, config=params, step="evaluate")
    with atomic_path(args.out) as tmp:
        study.to_netcdf(tmp, engine="h5netcdf")
    if args.figures:
        _write_figures(study, args.figures)
    print(format_table(study))
    print(f"study: {study.sizes['factor']} factors, "
          f"{int(study['value'].notnull().sum())} settings in {elapsed:.1f} s")
