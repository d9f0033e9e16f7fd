# Helpers of the shadowcam workflow: dataset manifests, which stages and sweeps
# each dataset needs, and the input functions (get_*) used by the stage files.
#
# Offers
# ------
# load_dataset_manifest(ds)   parsed data_manifest/<ds>.yaml (cached), with a clear error
# is_synthetic(ds)            manifest has a `synthetic:` block (rendered by the workflow)
# has_ground_truth(ds)        synthetic, or a `ground_truth:` entry -> accuracy is run
# has_reference(ds)           capture has an unshadowed reference frame
# uses_calibration(ds)        calibration sweeps exist and the configured model may use them
# scene_sweeps(ds)            names of the scene sweeps (u, v)
# is_outdoor(ds)              manifest kind is outdoor (time-lapse pipeline, workflow/rules/outdoor.smk)
# outdoor_sweep(ds)           name of the time-lapse sweep of an outdoor dataset
# get_*                       input / params functions of the rules
import glob
import json
import os
from pathlib import Path

import yaml

SCENE_SWEEPS = ("u", "v")
CALIBRATION_SWEEPS = ("cal_u", "cal_v")
_MANIFEST_CACHE = {}


wildcard_constraints:
    ds=r"[A-Za-z0-9][A-Za-z0-9_.-]*",
    sweep=r"[A-Za-z0-9_]+",


def as_json(mapping):
    """Return `mapping` as a compact, key-sorted JSON string (for params)."""
    return json.dumps(mapping, sort_keys=True, separators=(",", ":"))


def manifest_path(ds):
    """Return the path of the data manifest of dataset `ds`."""
    return f"data_manifest/{ds}.yaml"


def load_dataset_manifest(ds):
    """Return the parsed data manifest of dataset `ds` (a dict); raise ValueError if unusable."""
    if ds not in _MANIFEST_CACHE:
        path = Path(manifest_path(ds))
        if not path.is_file():
            raise ValueError(
                f"dataset {ds!r} (config key 'datasets'): {path} does not exist; "
                f"write it (see README.md) or choose an existing dataset with "
                f"--config datasets=[NAME]"
            )
        with open(path) as handle:
            manifest = yaml.safe_load(handle)
        if not isinstance(manifest, dict):
            raise ValueError(f"{path}: expected a YAML mapping at top level")
        if manifest.get("name", ds) != ds:
            raise ValueError(
                f"{path}: key 'name' is {manifest['name']!r} but must equal the file stem {ds!r}"
            )
        _MANIFEST_CACHE[ds] = manifest
    return _MANIFEST_CACHE[ds]


def is_synthetic(ds):
    """Return True if dataset `ds` is rendered by the workflow (`synthetic:` block)."""
    return "synthetic" in load_dataset_manifest(ds)


def has_ground_truth(ds):
    """Return True if dataset `ds` has ground truth (synthetic, or a `ground_truth:` entry)."""
    return is_synthetic(ds) or "ground_truth" in load_dataset_manifest(ds)


def has_reference(ds):
    """Return True if the capture of `ds` has an unshadowed reference frame.

    Rendered captures always include one (``shadowcam render`` writes it).
    """
    return is_synthetic(ds) or bool(load_dataset_manifest(ds).get("reference"))


def has_calibration_sweeps(ds):
    """Return True if `ds` has both calibration-plane sweeps and their plane description."""
    manifest = load_dataset_manifest(ds)
    if is_synthetic(ds):
        return bool(manifest["synthetic"].get("calibration", False))
    sweeps = manifest.get("sweeps") or {}
    return all(s in sweeps for s in CALIBRATION_SWEEPS) and "calibration_plane" in manifest


def scene_sweeps(ds):
    """Return the scene sweep names of `ds` (tuple of str); raise ValueError if u or v is missing."""
    manifest = load_dataset_manifest(ds)
    if is_synthetic(ds):
        return SCENE_SWEEPS
    sweeps = manifest.get("sweeps") or {}
    missing = [s for s in SCENE_SWEEPS if s not in sweeps]
    if missing:
        raise ValueError(
            f"{manifest_path(ds)}: key 'sweeps' lacks {', '.join(missing)}; "
            f"the lab dual view needs the two perpendicular sweeps u and v"
        )
    return SCENE_SWEEPS


def dual_model(ds):
    """Return the dual-coordinate model to run for `ds` (config `dual_coords.model`)."""
    model = config["dual_coords"]["model"]
    if model == "calibration" and not has_calibration_sweeps(ds):
        raise ValueError(
            f"config dual_coords.model is 'calibration' but {manifest_path(ds)} has no "
            f"calibration sweeps (cal_u, cal_v and calibration_plane); use model 'auto' or 'uniform'"
        )
    return model


def uses_calibration(ds):
    """Return True if the calibration sweeps of `ds` are decoded and timed."""
    return has_calibration_sweeps(ds) and dual_model(ds) in ("auto", "calibration")


def is_outdoor(ds):
    """Return True if dataset `ds` is an outdoor time-lapse (manifest ``kind: outdoor``)."""
    return load_dataset_manifest(ds).get("kind") == "outdoor"


def outdoor_sweep(ds):
    """Return the time-lapse sweep of outdoor dataset `ds`: ``timelapse``, or its only sweep."""
    if is_synthetic(ds):
        return "timelapse"
    sweeps = list(load_dataset_manifest(ds).get("sweeps") or {})
    if "timelapse" in sweeps or len(sweeps) == 1:
        return "timelapse" if "timelapse" in sweeps else sweeps[0]
    raise ValueError(
        f"{manifest_path(ds)}: an outdoor dataset needs one sweep (preferably named 'timelapse'); "
        f"found {sweeps or 'none'}"
    )


def outdoor_targets(ds):
    """Return the final output files of outdoor dataset `ds` (list of str)."""
    targets = [
        f"results/{ds}/outdoor/arrival.nc",
        f"results/{ds}/outdoor/pushbroom.nc",
        f"results/{ds}/outdoor/figures",
    ]
    if has_ground_truth(ds):
        targets += [f"results/{ds}/outdoor/accuracy.json", f"results/{ds}/outdoor/accuracy.csv"]
    return targets


def dataset_targets(ds):
    """Return the final output files of dataset `ds` (list of str)."""
    if is_outdoor(ds):
        return outdoor_targets(ds)
    targets = [
        f"results/{ds}/shadow_time.nc",
        f"results/{ds}/dual_coords.nc",
        f"results/{ds}/dual_view.nc",
        f"results/{ds}/figures",
    ]
    if has_ground_truth(ds):
        targets += [f"results/{ds}/accuracy.json", f"results/{ds}/accuracy.csv"]
    return targets


def get_final_targets(wildcards):
    """Input function of `all`: the outputs of every configured dataset."""
    return [t for ds in config["datasets"] for t in dataset_targets(ds)]


def get_capture_input(wildcards):
    """Input that describes the capture: the manifest (user data) or the rendered capture directory."""
    if is_synthetic(wildcards.ds):
        return f"results/{wildcards.ds}/capture"
    return manifest_path(wildcards.ds)


def get_capture_manifest(wildcards):
    """Path given to ``--manifest``: data_manifest/<ds>.yaml, or capture.json of a rendered capture."""
    if is_synthetic(wildcards.ds):
        return f"results/{wildcards.ds}/capture/capture.json"
    return manifest_path(wildcards.ds)


def capture_files(ds, group):
    """Files `decode` reads for `group` (a sweep name or "reference"): the rendered capture
    directory, or the manifest plus the frames its pattern matches."""
    if is_synthetic(ds):
        return [f"results/{ds}/capture"]
    manifest = load_dataset_manifest(ds)
    root = Path(manifest_path(ds)).parent / manifest.get("root", ".")
    if group == "reference":
        pattern = manifest.get("reference")
    else:
        pattern = (manifest.get("sweeps") or {}).get(group, {}).get("files")
    if not pattern:
        raise ValueError(f"{manifest_path(ds)}: no files declared for sweep {group!r}")
    files = sorted(os.path.normpath(f) for f in glob.glob(str(root / pattern)))
    if not files:
        raise ValueError(
            f"{manifest_path(ds)}: pattern {pattern!r} of sweep {group!r} matches no "
            f"file under {root}; check 'root' and the pattern"
        )
    return [manifest_path(ds)] + files


def get_raw_files(wildcards):
    """Input files of decoding one sweep (see `capture_files`)."""
    return capture_files(wildcards.ds, wildcards.sweep)


def get_reference_files(wildcards):
    """Input files of decoding the reference frame (see `capture_files`)."""
    return capture_files(wildcards.ds, "reference")


def get_sweeps(wildcards):
    """Sweeps whose shadow times are estimated: u, v, and cal_u, cal_v when used."""
    sweeps = list(scene_sweeps(wildcards.ds))
    if uses_calibration(wildcards.ds):
        sweeps += list(CALIBRATION_SWEEPS)
    return sweeps


def get_frames(wildcards):
    """Decoded frame stores of the sweeps of `get_sweeps`, in the same order."""
    return [f"results/{wildcards.ds}/frames/{s}.zarr" for s in get_sweeps(wildcards)]


def get_reference(wildcards):
    """Decoded reference frame store, or an empty list if the capture has none."""
    if has_reference(wildcards.ds):
        return [f"results/{wildcards.ds}/frames/reference.zarr"]
    return []


def get_reference_option(wildcards, input):
    """``--reference PATH`` if the dual view has a reference frame, else an empty string."""
    return f"--reference {input.reference}" if input.reference else ""


def get_dual_model(wildcards):
    """Model name passed to ``shadowcam dual-coords --model``."""
    return dual_model(wildcards.ds)


def get_accuracy(wildcards):
    """Accuracy table of the dataset, or an empty list if it has no ground truth."""
    if has_ground_truth(wildcards.ds):
        return [f"results/{wildcards.ds}/accuracy.csv"]
    return []


def get_accuracy_option(wildcards, input):
    """``--accuracy PATH`` for report figures when accuracy was computed, else empty."""
    return f"--accuracy {input.accuracy}" if input.accuracy else ""


def get_dual_coords_params(wildcards):
    """JSON ``--params`` of ``shadowcam dual-coords``: model options and the dual grid size.

    The dual grid size is set in config section ``dual_view`` (width, height; null = the
    manifest's ``dual`` block, else frames per sweep) and fixed when the dual coordinates
    are computed, so a change reruns dual_coords and everything after it.
    """
    options = dict(config["dual_coords"]["params"])
    for key in ("width", "height"):
        if config["dual_view"][key] is not None:
            options[f"dual_{key}"] = config["dual_view"][key]
    return as_json(options)


def get_evaluate_params(wildcards):
    """JSON ``--params`` of ``shadowcam evaluate``: config section ``evaluate``."""
    return as_json(config["evaluate"])

def get_outdoor_frames(wildcards):
    """Decoded frame store of the time-lapse sweep of an outdoor dataset."""
    return f"results/{wildcards.ds}/frames/{outdoor_sweep(wildcards.ds)}.zarr"


def get_outdoor_accuracy(wildcards):
    """Outdoor accuracy report of the dataset, or an empty list if it has no ground truth."""
    if has_ground_truth(wildcards.ds):
        return [f"results/{wildcards.ds}/outdoor/accuracy.json"]
    return []


def get_outdoor_accuracy_option(wildcards, input):
    """``--accuracy PATH`` for the outdoor figures when accuracy was computed, else empty."""
    return f"--accuracy {input.accuracy}" if input.accuracy else ""


def get_scene_sweeps(wildcards):
    """Scene sweep names (u v) of the dataset, for ``--sweeps``."""
    return list(scene_sweeps(wildcards.ds))


def get_scene_frames(wildcards):
    """Decoded frame stores of the scene sweeps (u, v), in `get_scene_sweeps` order."""
    return [f"results/{wildcards.ds}/frames/{s}.zarr" for s in scene_sweeps(wildcards.ds)]


def get_methods_params(wildcards):
    """JSON ``--params`` of ``shadowcam methods-comparison``: the shadow-time half window."""
    options = config["shadow_time"]["params"]
    return as_json({k: options[k] for k in ("half_window",) if k in options})


# --- Outdoor time parts and job sizes (rules in workflow/rules/outdoor.smk) ---
# The first outdoor pass runs as one job per time part of config outdoor.part_frames
# frames; job memory and run time are sized from the frame size (header of the first
# frame) with per-megapixel figures measured by `make bench-outdoor-size`.

_OUTDOOR_FRAME_CACHE = {}
#: measured peak RSS per megapixel of frame (MB/MP) and fixed part (MB), with margin
OUTDOOR_MEM_MB = {"normalise": (400, 85), "track": (400, 100), "per_pixel": (400, 70)}
#: measured seconds per frame and megapixel on one core (x3 margin in outdoor_runtime)
OUTDOOR_S_PER_MP_FRAME = {"normalise": 0.25, "track": 0.35, "per_pixel": 0.05}


def outdoor_frame_layout(ds):
    """Return ``(n_frames, megapixels)`` of the time-lapse of `ds` ((None, None) if rendered)."""
    if ds not in _OUTDOOR_FRAME_CACHE:
        if is_synthetic(ds):
            _OUTDOOR_FRAME_CACHE[ds] = (None, None)
        else:
            from shadowcam.decode import frame_info

            files = capture_files(ds, outdoor_sweep(ds))[1:]
            info = frame_info(files[0])
            _OUTDOOR_FRAME_CACHE[ds] = (len(files), info["height"] * info["width"] / 1e6)
    return _OUTDOOR_FRAME_CACHE[ds]


def outdoor_parts(ds):
    """Time parts of the first outdoor pass of `ds`: ``START-STOP`` names (one ``0-end`` if unknown)."""
    n_frames, _ = outdoor_frame_layout(ds)
    size = int(config["outdoor"]["part_frames"])
    if n_frames is None or size <= 0:
        return ["0-end"]
    return [f"{start}-{min(start + size, n_frames)}" for start in range(0, n_frames, size)]


def get_outdoor_photometry_parts(wildcards):
    """Part datasets of the first outdoor pass, merged into photometry.nc."""
    return [f"results/{wildcards.ds}/outdoor/photometry.parts/{part}.nc" for part in outdoor_parts(wildcards.ds)]


def get_outdoor_part_range(wildcards):
    """``--part START:STOP`` value of a part name ``START-STOP`` (``end`` = to the last frame)."""
    start, stop = wildcards.part.split("-")
    return f"{start}:{'' if stop == 'end' else stop}"


def _outdoor_frames_in_job(wildcards, stage):
    n_frames, _ = outdoor_frame_layout(wildcards.ds)
    if stage == "normalise" and n_frames is not None and not wildcards.part.endswith("end"):
        start, stop = (int(v) for v in wildcards.part.split("-"))
        return stop - start + 3  # warm-up frames and the reference
    return n_frames or 1000


def outdoor_mem_mb(stage):
    """Resource function: MB of memory of an outdoor job of `stage`, from the frame size."""

    def mem_mb(wildcards):
        megapixels = outdoor_frame_layout(wildcards.ds)[1] or 24.0
        fixed, per_mp = OUTDOOR_MEM_MB[stage]
        return int(fixed + per_mp * megapixels)

    return mem_mb


def outdoor_runtime(stage):
    """Resource function: minutes of an outdoor job of `stage` (3x the measured rate, >= 10)."""

    def runtime(wildcards):
        megapixels = outdoor_frame_layout(wildcards.ds)[1] or 24.0
        seconds = OUTDOOR_S_PER_MP_FRAME[stage] * megapixels * _outdoor_frames_in_job(wildcards, stage)
        return max(10, int(3 * seconds / 60) + 1)

    return runtime
