"""The simulation study end to end: settings from a parameter mapping, tables and figures.

Offers
------
STUDY_OPTIONS : options of :func:`shadowcam.evaluate.simulation_study.simulate_setting`.
TABLE_COLUMNS : metric -> header of the printed table.
study_from_params : run the study described by a ``levels`` / ``baseline`` / options mapping.
format_table : the study's numbers as plain-text tables, one per factor.
write_study_figures : one ``study_<factor>.png`` per factor into a directory (all or nothing).
"""

import logging
import time
from dataclasses import replace

from shadowcam._shared.atomic import atomic_directory
from shadowcam.evaluate.simulation_study import BASELINE, FACTORS, run_study
from shadowcam.report.figures import save_png, study_factor_figure

log = logging.getLogger(__name__)

STUDY_OPTIONS = ("scene", "size", "supersample", "seed", "method", "half_window", "dual_view_method")
#: columns of the printed table: metric -> header
TABLE_COLUMNS = {"rel_rmse_whole": "err_whole", "rel_rmse_masked": "err_mask",
                 "dual_coord_rmse": "uv_rmse", "dual_coord_coverage": "uv_cover",
                 "shadow_time_p95": "t_p95", "dual_coverage": "dual_cov", "runtime": "sec"}


def _progress(factor, value, metrics):
    log.info("%s = %g: whole %.3f, mask %.3f, uv rmse %.3f (%.1f s)", factor, value,
             metrics["rel_rmse_whole"], metrics["rel_rmse_masked"],
             metrics["dual_coord_rmse"], metrics["runtime"])


def study_from_params(params):
    """Run the simulation study described by `params`.

    Parameters
    ----------
    params : mapping
        ``levels`` (factor -> values), ``baseline`` (factor -> value) and any of
        :data:`STUDY_OPTIONS`.

    Returns
    -------
    xarray.Dataset
        :func:`shadowcam.evaluate.simulation_study.run_study` result with attr ``total_runtime_s``.
    """
    unknown = set(params) - {"levels", "baseline", *STUDY_OPTIONS}
    if unknown:
        raise ValueError(f"params: unknown keys {sorted(unknown)}")
    levels = params.get("levels") or {}
    baseline = params.get("baseline") or {}
    unknown = set(baseline) - set(FACTORS)
    if unknown:
        raise ValueError(f"params baseline: unknown factors {sorted(unknown)}; choose from {list(FACTORS)}")
    options = {k: params[k] for k in STUDY_OPTIONS if k in params}
    started = time.perf_counter()
    study = run_study(levels, baseline=replace(BASELINE, **baseline), progress=_progress, **options)
    study.attrs["total_runtime_s"] = time.perf_counter() - started
    return study


def format_table(study):
    """Plain-text tables of a study dataset, one block per factor.

    Parameters
    ----------
    study : xarray.Dataset
        As returned by :func:`shadowcam.evaluate.simulation_study.run_study`.

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


def write_study_figures(study, outdir):
    """Write one ``study_<factor>.png`` per factor of `study` into `outdir` (replaced whole)."""
    with atomic_directory(outdir) as tmp:
        for factor in study["factor"].values:
            sub = study.sel(factor=factor)
            figure = study_factor_figure(
                sub["value"].values, whole=sub["rel_rmse_whole"].values,
                masked=sub["rel_rmse_masked"].values, coord_error=sub["dual_coord_rmse"].values,
                factor=str(factor), unit=str(sub["factor_units"].values))
            save_png(figure, tmp / f"study_{factor}.png")
