"""Accuracy of outdoor arrival-time maps against ground truth, and the naive baseline.

Errors are in units of the median capture interval, over the non-sky pixels
the shadow reaches (ground-truth class 3), against one of the GT's
definitions (``arrival_time_s``: the pixel-centre point goes dark;
``arrival_time_half_coverage_s``: half of the footprint is dark). Targets
(issue 3): clean scenes median <= 0.25, p95 <= 1; with nuisances median
<= 0.5, p95 <= 2 and under 1% of pixels off by more than 5 intervals.

Offers
------
TARGETS : condition -> target figures.
arrival_errors : error statistics of an arrival map.
NaiveBaseline : streaming per-pixel "first frame below 50% of the recent maximum".
GT_DEFINITIONS : report name -> GT arrival variable.
check_targets : the targets of a condition against error statistics.
evaluate_arrivals : errors of several estimators against every GT definition, with targets.
false_arrivals : arrivals where the GT has none, per GT class.
edge_errors : tracked edge rows against the GT edge rows.
map_to_truth_camera : a map in the first frame's coordinates resampled into the GT camera's.
edges_to_truth_camera : per-column edge rows of the first frame's coordinates in the GT camera's.
registration_errors : estimated shifts (relative to frame 0) against the recorded shake.
pushbroom_errors : relative colour errors of a pushbroom image against the GT pushbroom.
accuracy_condition : the condition whose targets apply (explicit, else the manifest's GT noise).
outdoor_accuracy : the whole report of one capture: arrival maps, baseline, edges, pushbroom, registration.
GROUND_TRUTH_DEFINITION : what the ground truth is (shown with the table).
accuracy_table : the report as one row per quantity (value, unit, target, pass).
report_to_csv : the table as CSV text.
"""

import logging

import numpy as np

from shadowcam.io.frame_store import iter_store_frames
from shadowcam.io.frame_times import median_interval

log = logging.getLogger(__name__)
from shadowcam._shared.quantity_table import quantity_row, table_to_csv
from shadowcam._shared.validation import check_array, check_in, check_positive, check_same_shape
from shadowcam.outdoor.translation import translate

#: condition -> {statistic: bound} (errors in median capture intervals)
TARGETS = {
    "clean": {"median_abs": 0.25, "p95_abs": 1.0},
    "nuisances": {"median_abs": 0.5, "p95_abs": 2.0, "frac_over_5": 0.01},
}


def arrival_errors(estimate_s, truth_s, *, evaluate, interval_s):
    """Error statistics of an arrival-time map.

    Parameters
    ----------
    estimate_s, truth_s : (H, W) ndarray
        Arrival times in seconds (NaN = none).
    evaluate : (H, W) bool ndarray
        Pixels to evaluate (e.g. GT class 3).
    interval_s : float
        Unit of the errors (the median capture interval).

    Returns
    -------
    dict
        ``n_evaluated`` (pixels with a finite truth), ``coverage`` (share of
        them with an estimate), ``median_abs``, ``p95_abs``, ``max_abs``,
        ``frac_over_5``, ``frac_within_1``, ``median_signed`` (intervals;
        positive = late).
    """
    estimate = np.asarray(estimate_s, dtype=np.float64)
    truth = np.asarray(truth_s, dtype=np.float64)
    evaluate = np.asarray(evaluate, dtype=bool)
    check_same_shape({"estimate_s": estimate, "truth_s": truth, "evaluate": evaluate})
    check_positive(interval_s, "interval_s")
    pixels = evaluate & np.isfinite(truth)
    found = pixels & np.isfinite(estimate)
    error = (estimate[found] - truth[found]) / interval_s
    absolute = np.abs(error)
    n_eval = int(pixels.sum())

    def stat(fn):
        return float(fn(absolute)) if absolute.size else float("nan")

    return {
        "n_evaluated": n_eval,
        "coverage": float(found.sum() / n_eval) if n_eval else float("nan"),
        "median_abs": stat(np.median),
        "p95_abs": stat(lambda a: np.percentile(a, 95)),
        "max_abs": stat(np.max),
        "frac_over_5": stat(lambda a: np.mean(a > 5)),
        "frac_within_1": stat(lambda a: np.mean(a <= 1)),
        "median_signed": float(np.median(error)) if error.size else float("nan"),
    }


class NaiveBaseline:
    """Per-pixel threshold detector of ``shared/data/README.md`` section 2.8.

    Detected frame = first k with ``I_k < fraction * max(I_{k-window} .. I_{k-1})``,
    ``I`` = mean of R, G, B of the frame as delivered; its arrival time is
    ``time_s[k]``. State: a ring of `window` luminance images.

    Parameters
    ----------
    shape : tuple of int
        ``(H, W)``.
    window : int, optional
    fraction : float, optional
    """

    def __init__(self, shape, *, window=10, fraction=0.5):
        if window < 1 or not 0 < fraction < 1:
            raise ValueError(f"window must be >= 1 and fraction in (0, 1); got {window}, {fraction}")
        self.window, self.fraction = int(window), float(fraction)
        self.arrival_s = np.full(tuple(shape), np.nan)
        self._ring = []

    def update(self, frame, time_s):
        """Add the next frame ``(H, W, C)`` taken at `time_s` seconds."""
        luma = np.asarray(frame, dtype=np.float32).mean(axis=-1)
        if luma.shape != self.arrival_s.shape:
            raise ValueError(f"frame {np.shape(frame)} does not match shape {self.arrival_s.shape}")
        if self._ring:
            recent = np.max(self._ring, axis=0)
            hit = (luma < self.fraction * recent) & np.isnan(self.arrival_s)
            self.arrival_s[hit] = time_s
        self._ring = (self._ring + [luma])[-self.window:]


#: ground-truth definition variants: report name -> GT variable (seconds)
GT_DEFINITIONS = {
    "pixel_centre": "arrival_time_s",
    "half_coverage": "arrival_time_half_coverage_s",
}
#: the definition the targets are checked against (see docs/contracts.md)
PRIMARY_DEFINITION = "pixel_centre"


def check_targets(stats, *, condition, estimator="combined"):
    """Return the target checks of `condition` on `stats` (:func:`arrival_errors`).

    Returns
    -------
    list of dict
        ``{target, sweep, value, threshold, comparison, pass}`` (the layout of
        :func:`shadowcam.lab.accuracy.check_targets`; ``sweep`` names the estimator).
    """
    check_in(condition, "condition", TARGETS)
    return [
        {"target": name, "sweep": estimator, "value": stats[name], "threshold": bound, "comparison": "<=",
         "pass": bool(stats[name] <= bound)}
        for name, bound in TARGETS[condition].items()
    ]


def evaluate_arrivals(estimates, truth, *, interval_s, condition, primary="combined"):
    """Errors of several arrival maps against every GT definition, and the targets.

    Parameters
    ----------
    estimates : mapping of str to (H, W) ndarray
        Estimator name -> arrival seconds (e.g. combined, edge_crossing,
        coverage_crossing, naive_baseline).
    truth : xarray.Dataset
        Outdoor ground truth in standard form
        (:func:`shadowcam.io.ground_truth.load_ground_truth`).
    interval_s : float
        Median capture interval.
    condition : {"clean", "nuisances"}
    primary : str, optional
        Estimator whose errors against :data:`PRIMARY_DEFINITION` are checked.

    Returns
    -------
    dict
        ``errors[estimator][definition]`` statistics (:func:`arrival_errors`),
        ``targets`` (list), ``all_targets_pass``, ``condition``,
        ``primary_definition``, ``interval_s``, ``n_class3``.
    """
    evaluate = truth["shadow_class"].values == 3
    errors = {}
    for name, estimate in estimates.items():
        errors[name] = {
            definition: arrival_errors(estimate, truth[variable].values, evaluate=evaluate, interval_s=interval_s)
            for definition, variable in GT_DEFINITIONS.items() if variable in truth
        }
    targets = check_targets(errors[primary][PRIMARY_DEFINITION], condition=condition, estimator=primary)
    return {
        "errors": errors,
        "targets": targets,
        "all_targets_pass": all(t["pass"] for t in targets),
        "condition": condition,
        "primary_estimator": primary,
        "primary_definition": PRIMARY_DEFINITION,
        "interval_s": float(interval_s),
        "n_class3": int(evaluate.sum()),
    }


def false_arrivals(estimate_s, truth):
    """Pixels with an arrival although the GT says never shadowed / shadowed at start / sky (dict of int)."""
    found = np.isfinite(np.asarray(estimate_s))
    cls = truth["shadow_class"].values
    return {name: int((found & (cls == code)).sum())
            for name, code in (("sky", 0), ("never_shadowed", 1), ("shadowed_at_start", 2))}


def edge_errors(edge_row, truth_edge_row, *, unambiguous=None):
    """Median and p95 absolute edge-row error (pixels) where both exist (and the GT column is unambiguous)."""
    edge = np.asarray(edge_row, dtype=np.float64)
    gt = np.asarray(truth_edge_row, dtype=np.float64)
    check_same_shape({"edge_row": edge, "truth_edge_row": gt})
    use = np.isfinite(edge) & np.isfinite(gt)
    if unambiguous is not None:
        use &= np.asarray(unambiguous, dtype=bool)
    diff = np.abs(edge[use] - gt[use])
    return {"n": int(use.sum()),
            "median_abs_px": float(np.median(diff)) if diff.size else float("nan"),
            "p95_abs_px": float(np.percentile(diff, 95)) if diff.size else float("nan"),
            "found_fraction": float(use.sum() / max(np.isfinite(gt).sum(), 1))}


def map_to_truth_camera(values, *, shift_row, shift_col):
    """Resample a per-pixel map from the first frame's coordinates into the GT camera's.

    The pipeline registers every frame to the first one, so its maps are in
    that frame's pixel grid; synthetic ground truth is in the unshaken camera,
    and the first frame shows it moved by its own shake (``frame_0(r, c) =
    truth(r - shift_row, c - shift_col)``). The map is sampled at ``(r +
    shift_row, c + shift_col)``, bilinear; NaN where a neighbour is NaN or
    outside the image.

    Parameters
    ----------
    values : (H, W) ndarray
        Map in the first frame's coordinates (NaN = none).
    shift_row, shift_col : float
        Shake of the first frame (pixels, content moved by +shift).

    Returns
    -------
    (H, W) float64 ndarray
    """
    values = np.asarray(values, dtype=np.float64)
    check_array(values, "values", ndim=2)
    return translate(values, (shift_row, shift_col), method="linear_nan")


def edges_to_truth_camera(edge_row, *, shift_row, shift_col):
    """Per-column edge rows ``(T, W)`` of the first frame's coordinates in the GT camera's.

    The GT column ``c`` is the first frame's column ``c + shift_col``
    (linear between columns, NaN past the image); its row moves by ``-shift_row``.
    """
    edge = np.asarray(edge_row, dtype=np.float64)
    check_array(edge, "edge_row", ndim=2)
    width = edge.shape[1]
    if width < 2:
        raise ValueError(f"edge_row needs at least 2 columns, got {width}")
    cols = np.arange(width) + shift_col
    left = np.clip(np.floor(cols).astype(int), 0, width - 2)
    frac = cols - left
    lo, hi = edge[:, left], edge[:, left + 1]
    with np.errstate(invalid="ignore"):
        out = np.where(frac == 0, lo, np.where(frac == 1, hi, (1 - frac) * lo + frac * hi))
    out[:, (cols < 0) | (cols > width - 1)] = np.nan
    return out - shift_row


def registration_errors(shift_row, shift_col, *, shake_dy, shake_dx):
    """Error statistics of the estimated shifts against the recorded camera shake.

    Parameters
    ----------
    shift_row, shift_col : (T,) ndarray
        Estimated content shift of each frame relative to frame 0, pixels.
    shake_dy, shake_dx : (T,) ndarray
        Recorded shake (content moves by ``+dx`` cols, ``+dy`` rows) relative to
        the unshaken camera; frame 0's is subtracted.

    Returns
    -------
    dict
        ``rms_row_px``, ``rms_col_px``, ``rms_px`` (both axes), ``max_abs_px``, and
        ``true_max_px`` (largest true shake relative to frame 0, for scale).
    """
    arrays = [np.asarray(a, dtype=np.float64) for a in (shift_row, shift_col, shake_dy, shake_dx)]
    if len({a.shape for a in arrays}) != 1 or arrays[0].ndim != 1:
        raise ValueError(f"shift_row, shift_col, shake_dy and shake_dx must be (T,) of one length; got "
                         f"{[a.shape for a in arrays]}")
    true_row, true_col = arrays[2] - arrays[2][0], arrays[3] - arrays[3][0]
    d_row, d_col = arrays[0] - true_row, arrays[1] - true_col
    return {"rms_row_px": float(np.sqrt(np.mean(d_row**2))),
            "rms_col_px": float(np.sqrt(np.mean(d_col**2))),
            "rms_px": float(np.sqrt(np.mean(d_row**2 + d_col**2))),
            "max_abs_px": float(np.max(np.abs(np.r_[d_row, d_col]))),
            "true_max_px": float(np.max(np.hypot(true_row, true_col)))}


def pushbroom_errors(pushbroom, truth):
    """Relative colour errors of a pushbroom image against the GT pushbroom.

    The estimate is scaled to the GT by the median ratio of channel sums (the
    pipeline's colours are in camera units); the error of a pixel is the L1
    colour difference over the GT's channel sum.

    Parameters
    ----------
    pushbroom, truth : (T, W, C) ndarray
        Estimated and GT pushbroom images (NaN = none); same shape.

    Returns
    -------
    dict
        ``n`` (pixels compared), ``scale_to_gt``, ``median_rel_error``, ``p95_rel_error``.
    """
    pushbroom, truth = np.asarray(pushbroom), np.asarray(truth)
    if pushbroom.shape != truth.shape or pushbroom.ndim != 3:
        raise ValueError(f"pushbroom: shape {pushbroom.shape} must equal the truth's {truth.shape} (T, W, C)")
    both = np.isfinite(pushbroom).all(-1) & np.isfinite(truth).all(-1) & (truth.sum(-1) > 0)
    scale = float(np.median(pushbroom[both].sum(-1) / truth[both].sum(-1))) if both.any() else float("nan")
    rel = np.abs(pushbroom[both] / scale - truth[both]).sum(-1) / truth[both].sum(-1)
    return {"n": int(both.sum()), "scale_to_gt": scale,
            "median_rel_error": float(np.median(rel)) if rel.size else float("nan"),
            "p95_rel_error": float(np.percentile(rel, 95)) if rel.size else float("nan")}


def accuracy_condition(manifest, condition=None):
    """The condition whose targets apply: `condition`, else the manifest's ``ground_truth.noise``
    if it names one of :data:`TARGETS`, else ``nuisances``."""
    if condition is not None:
        if condition not in TARGETS:
            raise ValueError(f"condition: must be one of {sorted(TARGETS)}; got {condition!r}")
        return condition
    noise = manifest.get("ground_truth", {}).get("noise")
    return noise if noise in TARGETS else "nuisances"


def outdoor_accuracy(truth, frames, photometry, edges, arrival, pushbroom, *, condition):
    """Evaluate one outdoor capture's products against its ground truth.

    Parameters
    ----------
    truth : xarray.Dataset
        Outdoor ground truth (:func:`shadowcam.io.ground_truth.load_ground_truth`).
    frames : xarray.Dataset
        Frame store of the time-lapse (streamed for the naive baseline).
    photometry, edges, arrival, pushbroom : xarray.Dataset
        The pipeline's outdoor datasets.
    condition : {"clean", "nuisances"}
        Targets that apply.

    Returns
    -------
    dict
        :func:`evaluate_arrivals` report plus ``false_arrivals``, ``first_frame_shake_px``
        and, where the GT has them, ``edge_row``, ``pushbroom``, ``registration``.
    """
    if condition not in TARGETS:
        raise ValueError(f"condition: must be one of {sorted(TARGETS)}; got {condition!r}")
    time_s = frames["time_s"].values
    if "times_s" in truth and truth["times_s"].size == time_s.size:
        log.info("frame times vs GT: max |difference| %.3g s", float(np.max(np.abs(truth["times_s"].values - time_s))))
    baseline = NaiveBaseline((frames.sizes["row"], frames.sizes["col"]))
    for frame, t in zip(iter_store_frames(frames, what="naive baseline"), time_s):
        baseline.update(frame, t)
    # the maps are in the first frame's pixel grid; synthetic GT is in the unshaken camera
    shift = {"shift_row": 0.0, "shift_col": 0.0}
    has_shake = "shake_dy_px" in truth and truth["shake_dy_px"].size == time_s.size
    if has_shake:
        shift = {"shift_row": float(truth["shake_dy_px"].values[0]),
                 "shift_col": float(truth["shake_dx_px"].values[0])}
        log.info("first frame's shake (GT): row %+.3f px, col %+.3f px; maps resampled into the GT camera",
                 shift["shift_row"], shift["shift_col"])
    estimates = {
        name: map_to_truth_camera(arrival[variable].values, **shift)
        for name, variable in (("combined", "arrival_time_s"), ("edge_crossing", "edge_arrival_s"),
                               ("coverage_crossing", "coverage_arrival_s"))
    }
    # the baseline works on the frames as delivered (no registration)
    estimates["naive_baseline"] = baseline.arrival_s
    report = evaluate_arrivals(estimates, truth, interval_s=median_interval(time_s), condition=condition)
    report["false_arrivals"] = {name: false_arrivals(est, truth) for name, est in estimates.items()}
    report["first_frame_shake_px"] = shift
    if "pb_edge_y" in truth and truth["pb_edge_y"].shape == edges["edge_row"].shape:
        unambiguous = truth["pb_n_transitions"].values == 1 if "pb_n_transitions" in truth else None
        report["edge_row"] = edge_errors(edges_to_truth_camera(edges["edge_row"].values, **shift),
                                         truth["pb_edge_y"].values, unambiguous=unambiguous)
    if "pb_front" in truth and truth["pb_front"].shape == pushbroom["pushbroom"].shape:
        report["pushbroom"] = pushbroom_errors(pushbroom["pushbroom"].values, truth["pb_front"].values)
    if has_shake:
        report["registration"] = registration_errors(photometry["shift_row"].values, photometry["shift_col"].values,
                                                     shake_dy=truth["shake_dy_px"].values,
                                                     shake_dx=truth["shake_dx_px"].values)
    return report


#: what the ground truth is (shown with the table)
GROUND_TRUTH_DEFINITION = (
    "Ground truth: per-pixel shadow arrival time of the renderer (pixel_centre: the pixel-centre point "
    "goes dark, bisected in time; half_coverage: half of the pixel footprint is dark), evaluated over the "
    "non-sky pixels the shadow reaches (class 3); errors in median capture intervals "
    "(docs/architecture.md, 'Datasets between stages', outdoor ground truth; shared data README 2.6)."
)
#: arrival statistics shown per estimator (primary GT definition): key -> (quantity, unit, scale)
_ARRIVAL_ROWS = {
    "median_abs": ("arrival |error| median", "interval", 1.0),
    "p95_abs": ("arrival |error| p95", "interval", 1.0),
    "frac_over_5": ("arrival |error| > 5 intervals", "%", 100.0),
    "coverage": ("arrival coverage", "%", 100.0),
}
#: further statistics of the primary estimator
_PRIMARY_ROWS = {
    "frac_within_1": ("arrival |error| <= 1 interval", "%", 100.0),
    "median_signed": ("arrival median signed error", "interval", 1.0),
    "max_abs": ("arrival |error| max", "interval", 1.0),
    "n_evaluated": ("pixels evaluated (shadow arrives)", "pixel", 1.0),
}
_SECTION_ROWS = {
    "edge_row": {"median_abs_px": ("edge row |error| median", "pixel", 1.0),
                 "p95_abs_px": ("edge row |error| p95", "pixel", 1.0),
                 "found_fraction": ("edge found", "%", 100.0)},
    "pushbroom": {"median_rel_error": ("pushbroom relative error median", "%", 100.0),
                  "p95_rel_error": ("pushbroom relative error p95", "%", 100.0),
                  "scale_to_gt": ("pushbroom scale to GT", "1", 1.0)},
    "registration": {"rms_px": ("registration RMS error", "pixel", 1.0),
                     "max_abs_px": ("registration |error| max", "pixel", 1.0),
                     "true_max_px": ("true shake, max", "pixel", 1.0)},
}


def accuracy_table(report):
    """The report as a table a reader scans: one row per quantity, targets on their quantity's row.

    Every estimator gets its arrival errors against the primary GT definition; the primary
    estimator also its remaining statistics and its errors against the other definitions;
    then false arrivals, edge rows, pushbroom and registration where present.

    Parameters
    ----------
    report : dict
        From :func:`outdoor_accuracy` (``dataset`` optional).

    Returns
    -------
    list of dict
        Rows of :func:`shadowcam._shared.quantity_table.quantity_row`.
    """
    primary, definition = report["primary_estimator"], report["primary_definition"]
    targets = {(t["target"], t["sweep"]): t for t in report.get("targets", [])}
    rows = []
    for name, by_definition in report["errors"].items():
        stats = by_definition.get(definition, {})
        spec = {**_ARRIVAL_ROWS, **_PRIMARY_ROWS} if name == primary else _ARRIVAL_ROWS
        rows += [quantity_row(f"{quantity}, {name}", stats[key], unit, scale=scale, target=targets.get((key, name)))
                 for key, (quantity, unit, scale) in spec.items() if key in stats]
    for other, stats in report["errors"].get(primary, {}).items():
        if other != definition:
            rows += [quantity_row(f"{quantity}, {primary}, GT {other}", stats[key], unit, scale=scale)
                     for key, (quantity, unit, scale) in _ARRIVAL_ROWS.items() if key in stats and key != "coverage"]
    for cls, count in report.get("false_arrivals", {}).get(primary, {}).items():
        rows.append(quantity_row(f"false arrivals, {primary}, GT {cls.replace('_', ' ')}", count, "pixel"))
    for section, spec in _SECTION_ROWS.items():
        stats = report.get(section) or {}
        rows += [quantity_row(quantity, stats[key], unit, scale=scale)
                 for key, (quantity, unit, scale) in spec.items() if key in stats]
    rows.append(quantity_row("median capture interval", report["interval_s"], "s"))
    rows.append(quantity_row("GT definition of the targets", definition))
    rows.append(quantity_row("condition (targets that apply)", report["condition"]))
    rows.append(quantity_row("all targets pass", report["all_targets_pass"]))
    if "dataset" in report:
        rows.append(quantity_row("dataset", report["dataset"]))
    return rows


def report_to_csv(report):
    """The report's :func:`accuracy_table` as CSV text (``quantity,value,unit,target,pass``)."""
    return table_to_csv(accuracy_table(report))
