# Helpers of the shadowcam workflow: the capture plan of each configured dataset and
# the input and params functions (get_*) of the stage files.
#
# Every fact about a capture (sweeps and their files, frame counts and shape, timing,
# reference, calibration, ground truth, outdoor or lab, the dual model, the strip halo)
# comes from shadowcam.io.capture_plan, the same code the `shadowcam` steps use. The
# manifests of the configured datasets are read and validated against the package's
# schema when the workflow is parsed, so a bad manifest stops `snakemake -n` with the
# step's own message.
#
# Offers
# ------
# capture(ds)                  CapturePlan of data_manifest/<ds>.yaml (cached)
# manifest_path(ds)            data_manifest/<ds>.yaml
# as_json(mapping)             compact JSON for params
# get_flag(flag, name)         params function: "FLAG PATHS" of an optional input, else ""
# get_*                        input / params functions of the rules
# Time parts and strips: workflow/rules/parts.smk; job resources: resources.smk;
# final targets: targets.smk.
import json
import os
import sys
from pathlib import Path

from shadowcam.io.capture_plan import SCENE_SWEEPS, capture_plan


wildcard_constraints:
    ds=r"[A-Za-z0-9][A-Za-z0-9_.-]*",
    # a sweep name (manifest schema), never the reference frame (rule decode_reference)
    sweep=r"(?!reference\b)[A-Za-z][A-Za-z0-9_]*",


_PLANS = {}


def manifest_path(ds):
    """Return the path of the data manifest of dataset `ds`."""
    return f"data_manifest/{ds}.yaml"


def capture(ds):
    """Return the CapturePlan of dataset `ds` (cached); raise ValueError naming the file and key."""
    if ds not in _PLANS:
        path = Path(manifest_path(ds))
        if not path.is_file():
            raise ValueError(
                f"dataset {ds!r} (config key 'datasets'): {path} does not exist; "
                f"write it (see README.md) or choose an existing dataset with "
                f"--config datasets=[NAME]"
            )
        plan = capture_plan(
            path,
            dual_model=config["dual_coords"]["model"],
            edge_margin=config["outdoor"]["track_edges"].get("margin"),
        )
        if plan.name != ds:
            raise ValueError(
                f"{path}: key 'name' is {plan.name!r} but must equal the file stem {ds!r}"
            )
        _PLANS[ds] = plan
    return _PLANS[ds]


def _plan_configured_datasets():
    """Read the manifest of every configured dataset; stop with its message if one is unusable."""
    for ds in config["datasets"]:
        try:
            capture(ds)
        except ValueError as exc:
            sys.exit(f"error: {exc}")


_plan_configured_datasets()


def relative(paths):
    """Return `paths` relative to the working directory (list of str)."""
    return [os.path.relpath(p) for p in paths]


def as_json(mapping):
    """Return `mapping` as a compact, key-sorted JSON string (for params)."""
    return json.dumps(mapping, sort_keys=True, separators=(",", ":"))


def get_flag(flag, name):
    """Return a params function giving ``FLAG PATH...`` when input `name` is not empty, else ""."""

    def get_option(wildcards, input):
        paths = input[name]
        paths = [paths] if isinstance(paths, str) else list(paths)
        return f"{flag} {' '.join(paths)}" if paths else ""

    get_option.__name__ = f"get_{name}_option"
    return get_option


def get_capture_input(wildcards):
    """Input that describes the capture: the manifest (user data) or the rendered capture directory."""
    if capture(wildcards.ds).rendered:
        return f"results/{wildcards.ds}/capture"
    return manifest_path(wildcards.ds)


def get_capture_manifest(wildcards):
    """Path given to ``--manifest``: data_manifest/<ds>.yaml, or capture.json of a rendered capture."""
    if capture(wildcards.ds).rendered:
        return f"results/{wildcards.ds}/capture/capture.json"
    return manifest_path(wildcards.ds)


def get_reference_files(wildcards):
    """Files decoding the reference frame reads: the rendered capture, or the manifest and the frame."""
    plan = capture(wildcards.ds)
    if plan.rendered:
        return [f"results/{wildcards.ds}/capture"]
    return [manifest_path(wildcards.ds)] + relative(plan.reference)


def get_sweeps(wildcards):
    """Sweeps whose shadow times are estimated: u, v, and cal_u, cal_v when the calibration model runs."""
    return list(capture(wildcards.ds).timed_sweeps)


def get_frames(wildcards):
    """Decoded frame stores of the sweeps of `get_sweeps`, in the same order."""
    return [f"results/{wildcards.ds}/frames/{s}.zarr" for s in get_sweeps(wildcards)]


def get_reference(wildcards):
    """Decoded reference frame store, or an empty list if the capture has none."""
    if capture(wildcards.ds).has_reference:
        return [f"results/{wildcards.ds}/frames/reference.zarr"]
    return []


def get_dual_model(wildcards):
    """Model passed to ``shadowcam dual-coords --model``: the one the capture plan chose."""
    return capture(wildcards.ds).dual_model


FIGURE_ORDER = (
    "primal",
    "shadow_time_u",
    "shadow_time_v",
    "shadow_time_cal_u",
    "shadow_time_cal_v",
    "dual_view",
    "viewpoints",
    "keyframes",
    "edge_over_time",
    "arrival_map",
    "transient_events",
    "pushbroom",
    "accuracy",
    "error_histogram",
)


def get_figure_labels(wildcards):
    """Report labels of a figure: the dataset, and the figure's place in reading order (the report sorts
    a dataset's results by label) and name."""
    order = (
        FIGURE_ORDER.index(wildcards.figure)
        if wildcards.figure in FIGURE_ORDER
        else len(FIGURE_ORDER)
    )
    return {
        "dataset": wildcards.ds,
        "figure": f"{order + 1:02d} {wildcards.figure.replace('_', ' ')}",
    }


def get_accuracy(wildcards):
    """Accuracy table of the dataset, or an empty list if it has no ground truth."""
    if capture(wildcards.ds).has_ground_truth:
        return [f"results/{wildcards.ds}/accuracy.csv"]
    return []


def get_dual_coords_params(wildcards):
    """JSON ``--params`` of ``shadowcam dual-coords``: model options and the dual grid size.

    The dual grid size is set in config section ``dual_view`` (width, height; null = the
    manifest's ``dual`` block, else frames per sweep) and fixed when the dual coordinates
    are computed, so a change reruns dual_coords and everything after it.
    """
    options = dict(config["dual_coords"]["params"], min_coverage=config["min_coverage"])
    for key in ("width", "height"):
        if config["dual_view"][key] is not None:
            options[f"dual_{key}"] = config["dual_view"][key]
    return as_json(options)


def get_dual_view_params(wildcards):
    """JSON ``--params`` of ``shadowcam dual-view``: config section ``dual_view.params``
    (the mesh carries the camera-pixel density unless ``density: false``)."""
    return as_json(
        dict(config["dual_view"]["params"], min_coverage=config["min_coverage"])
    )


def get_evaluate_params(wildcards):
    """JSON ``--params`` of ``shadowcam evaluate``: config section ``evaluate``."""
    return as_json(config["evaluate"])


def get_outdoor_frames(wildcards):
    """Decoded frame store of the time-lapse sweep of an outdoor dataset."""
    return f"results/{wildcards.ds}/frames/{capture(wildcards.ds).outdoor_sweep}.zarr"


def get_outdoor_accuracy(wildcards):
    """Outdoor accuracy report of the dataset, or an empty list if it has no ground truth."""
    if capture(wildcards.ds).has_ground_truth:
        return [f"results/{wildcards.ds}/outdoor/accuracy.json"]
    return []


def get_scene_sweeps(wildcards):
    """Scene sweep names (u v) of the dataset, for ``--sweeps``."""
    return list(SCENE_SWEEPS)


def get_scene_frames(wildcards):
    """Decoded frame stores of the scene sweeps (u, v), in `get_scene_sweeps` order."""
    return [
        f"results/{wildcards.ds}/frames/{s}.zarr" for s in get_scene_sweeps(wildcards)
    ]


def get_methods_params(wildcards):
    """JSON ``--params`` of ``shadowcam methods-comparison``: the shadow-time half window."""
    options = config["shadow_time"]["params"]
    return as_json({k: options[k] for k in ("half_window",) if k in options})
