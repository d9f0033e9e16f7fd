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
import math
import os
from functools import lru_cache
from pathlib import Path

import yaml

from shadowcam.io.decode import frame_info
from shadowcam.io.frame_store import default_chunk_frames
from shadowcam.io.manifest import natural_key

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
# frames, the second (edge tracking) as one job per column strip of config
# outdoor.edge_strips (merged exactly by track_edges); job memory and run time are sized from the frame size (header of the first
# frame) with per-megapixel figures measured by `make bench-outdoor-size`.

#: measured peak RSS per megapixel of frame (MB/MP) and fixed part (MB), with margin
OUTDOOR_MEM_MB = {"normalise": (400, 85), "track": (400, 100), "track_strip": (400, 100), "per_pixel": (400, 70)}
#: measured seconds per frame and megapixel on one core (x3 margin in outdoor_runtime)
OUTDOOR_S_PER_MP_FRAME = {"normalise": 0.25, "track": 0.35, "track_strip": 0.35, "per_pixel": 0.05}


def outdoor_frame_layout(ds):
    """Return ``(n_frames, megapixels)`` of the time-lapse of `ds` ((None, None) if rendered:
    the frames kept after dropped ones are known only once rendered)."""
    if is_synthetic(ds):
        return None, None
    sweep = outdoor_sweep(ds)
    rows, cols = frame_shape(ds, sweep)
    return sweep_frame_count(ds, sweep), rows * cols / 1e6


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


def edge_strip_count():
    """Column strips of the edge-tracking pass (config outdoor.edge_strips; 1 = one job)."""
    return int(config["outdoor"]["edge_strips"])


def get_edge_strips(wildcards):
    """Strip files of the edge-tracking pass merged by track_edges (none for one job)."""
    count = edge_strip_count()
    if count <= 1:
        return []
    return [f"results/{wildcards.ds}/outdoor/edges.strips/{index}.npz" for index in range(count)]


def get_edge_strips_option(wildcards, input):
    """``--strips FILES`` of track-edges when the pass ran in strips, else empty."""
    return "--strips " + " ".join(input.strips) if input.strips else ""


def get_edge_strip_arg(wildcards):
    """``--strip I/N`` value of strip job `wildcards.strip`."""
    return f"{wildcards.strip}/{edge_strip_count()}"


def _outdoor_megapixels(wildcards, stage):
    """Megapixels an outdoor job of `stage` reads per frame: a strip reads its columns plus
    a halo (~16 columns each side: shift + cubic taps + band widening + guard)."""
    megapixels = outdoor_frame_layout(wildcards.ds)[1] or 24.0
    if stage != "track_strip":
        return megapixels
    ds = wildcards.ds
    width = None if is_synthetic(ds) else frame_shape(ds, outdoor_sweep(ds))[1]
    halo_share = 2 * 16 / width if width else 0.1
    return megapixels * min(1.0, 1 / edge_strip_count() + halo_share)


def _outdoor_stage(stage):
    """The merge of strips (track_edges with edge_strips > 1) only handles (T, W) curves and maps."""
    return "per_pixel" if stage == "track" and edge_strip_count() > 1 else stage


def outdoor_mem_mb(stage):
    """Resource function: MB of memory of an outdoor job of `stage`, from the frame size."""

    def mem_mb(wildcards):
        fixed, per_mp = OUTDOOR_MEM_MB[_outdoor_stage(stage)]
        return int(fixed + per_mp * _outdoor_megapixels(wildcards, stage))

    return mem_mb


def outdoor_runtime(stage):
    """Resource function: minutes of an outdoor job of `stage` (3x the measured rate, >= 10)."""

    def runtime(wildcards):
        megapixels = _outdoor_megapixels(wildcards, stage)
        seconds = OUTDOOR_S_PER_MP_FRAME[_outdoor_stage(stage)] * megapixels * _outdoor_frames_in_job(wildcards, stage)
        return max(10, int(3 * seconds / 60) + 1)

    return runtime


# ---------------------------------------------------------------------------------------
# Time chunks and job resources (decode parts, resources sized from the input).
#
# A sweep of T frames is decoded by ceil(T / F) `decode_part` jobs of F = chunk_frames x
# decode.chunks_per_job frames each; `decode` joins them (hard links, no copy) into
# results/{ds}/frames/{sweep}.zarr. Memory of a job is bounded by one time chunk of
# chunk_frames frames, whatever T and F. The dips of the same time ranges are tracked
# by `shadow_time_chunk` jobs whose partials `shadow_time` merges.
#
# sweep_frame_count(ds, sweep)   frames of a sweep, known before anything runs
# frame_shape(ds, sweep)         (rows, cols) of its frames
# decode_chunk_frames(ds, sweep) store chunk: config decode.chunk_frames, or ~64 MiB (null)
# decode_part_ranges(ds, sweep)  [(start, stop), ...] frame range of each decode_part job
# get_decode_parts, get_part_files, get_part_range, get_chunk_frames   decode rules' inputs/params
# sweep_partials, get_partials, get_partials_option    shadow-time chunks (same ranges as the decode parts)
# get_decode_mem_mb, get_decode_runtime, get_shadow_time_mem_mb, get_shadow_time_chunk_mem_mb,
# get_shadow_time_chunk_runtime,
# get_image_mem_mb, get_stream_mem_mb, get_stream_runtime, get_render_mem_mb   resources (MB, minutes)


wildcard_constraints:
    # decode_part / shadow_time_chunk parts (0000, 0001, ...); the outdoor first-pass
    # time parts (START-STOP) set their own constraint in outdoor.smk
    part=r"\d{4}",

#: per-pixel seconds of decoding one frame (rawpy + demosaic + zstd write, ~3x the
#: measured 24 MP lossless-JPEG DNG cost), used to size `runtime`
DECODE_SECONDS_PER_PIXEL = 2e-7
#: per-pixel seconds of streaming one frame through shadow time (zarr read + tracker)
SHADOW_TIME_SECONDS_PER_PIXEL = 5e-8
#: bytes per camera pixel held by the shadow-time step per sweep (tracker window and
#: sums, per-sweep result maps, classification temporaries)
SHADOW_TIME_BYTES_PER_PIXEL = 600
#: memory of a Python process with the shadowcam imports loaded
BASE_MEM_MB = 500


def sweep_files(ds, sweep):
    """Frame files of a sweep of user data in frame order (natural sort, as the manifest)."""
    return sorted(capture_files(ds, sweep)[1:], key=natural_key)


def sweep_frame_count(ds, sweep):
    """Number of frames of `sweep` of `ds` (int), known when the DAG is built."""
    if is_synthetic(ds):
        return int(load_dataset_manifest(ds)["synthetic"]["frames"])
    return len(sweep_files(ds, sweep))


@lru_cache(maxsize=None)
def frame_shape(ds, sweep):
    """(rows, cols) of the frames of `sweep` (the manifest, or the first file's header)."""
    if is_synthetic(ds):
        synthetic = load_dataset_manifest(ds)["synthetic"]
        return int(synthetic["height"]), int(synthetic["width"])
    info = frame_info(sweep_files(ds, sweep)[0])
    return int(info["height"]), int(info["width"])


def decode_chunk_frames(ds, sweep):
    """Frames per store chunk: config decode.chunk_frames, or ~64 MiB of float32 RGB if null."""
    configured = config["decode"]["chunk_frames"]
    return int(configured) if configured else default_chunk_frames(frame_shape(ds, sweep) + (3,))


def decode_part_ranges(ds, sweep):
    """Frame ranges [(start, stop), ...] of the decode_part jobs of a sweep."""
    total = sweep_frame_count(ds, sweep)
    step = decode_chunk_frames(ds, sweep) * int(config["decode"]["chunks_per_job"])
    return [(start, min(start + step, total)) for start in range(0, total, step)]


def _part_range(wildcards):
    ranges = decode_part_ranges(wildcards.ds, wildcards.sweep)
    index = int(wildcards.part)
    if index >= len(ranges):
        raise ValueError(f"{wildcards.ds} sweep {wildcards.sweep} has {len(ranges)} parts, no part {index}")
    return ranges[index]


def get_decode_parts(wildcards):
    """Part stores of a sweep, in time order (inputs of `decode`)."""
    count = len(decode_part_ranges(wildcards.ds, wildcards.sweep))
    return [f"results/{wildcards.ds}/frames/{wildcards.sweep}.parts/{i:04d}.zarr" for i in range(count)]


def get_part_files(wildcards):
    """Files one decode_part job reads: the rendered capture, or the manifest and its frames."""
    if is_synthetic(wildcards.ds):
        return capture_files(wildcards.ds, wildcards.sweep)
    start, stop = _part_range(wildcards)
    return [manifest_path(wildcards.ds)] + sweep_files(wildcards.ds, wildcards.sweep)[start:stop]


def get_part_range(wildcards):
    """``START:STOP`` of ``shadowcam decode --frames`` for one part."""
    start, stop = _part_range(wildcards)
    return f"{start}:{stop}"


def sweep_partials(ds, sweep):
    """Dip-tracking partials of a sweep, one per decode part (time chunk), in time order."""
    count = len(decode_part_ranges(ds, sweep))
    return [f"results/{ds}/shadow_time/{sweep}.parts/{i:04d}.npz" for i in range(count)]


def get_partials(wildcards):
    """Partials of every sweep of `get_sweeps` (inputs of `shadow_time`)."""
    return [p for s in get_sweeps(wildcards) for p in sweep_partials(wildcards.ds, s)]


def get_partials_option(wildcards, input):
    """``--partials SWEEP FILE... --partials ...`` of ``shadowcam shadow-time``."""
    return " ".join(f"--partials {s} " + " ".join(sweep_partials(wildcards.ds, s)) for s in get_sweeps(wildcards))


def get_chunk_frames(wildcards):
    """``--chunk-frames`` of a sweep (the same for all its parts)."""
    return decode_chunk_frames(wildcards.ds, wildcards.sweep)


def _frame_mb(ds, sweep):
    rows, cols = frame_shape(ds, sweep)
    return rows * cols * 3 * 4 / 2**20


def get_decode_mem_mb(wildcards, attempt):
    """Memory of a decode_part job: two copies of a time chunk and a few frames of decoder
    buffers (float32 RGB), doubled on a retry."""
    frame = _frame_mb(wildcards.ds, wildcards.sweep)
    chunk = decode_chunk_frames(wildcards.ds, wildcards.sweep)
    return attempt * math.ceil(BASE_MEM_MB + (2 * chunk + 4) * frame)


def get_decode_runtime(wildcards, attempt):
    """Minutes of a decode_part job, from its frame and pixel count."""
    start, stop = _part_range(wildcards)
    rows, cols = frame_shape(wildcards.ds, wildcards.sweep)
    return attempt * (5 + math.ceil((stop - start) * rows * cols * DECODE_SECONDS_PER_PIXEL / 60))


def get_shadow_time_mem_mb(wildcards, attempt):
    """Memory of shadow_time: the merged summaries and per-sweep maps of every sweep."""
    sweeps = get_sweeps(wildcards)
    rows, cols = frame_shape(wildcards.ds, sweeps[0])
    maps = len(sweeps) * rows * cols * SHADOW_TIME_BYTES_PER_PIXEL / 2**20
    return attempt * math.ceil(BASE_MEM_MB + maps)


def get_shadow_time_chunk_mem_mb(wildcards, attempt):
    """Memory of shadow_time_chunk: a tracker's per-pixel state and three copies of a read chunk."""
    rows, cols = frame_shape(wildcards.ds, wildcards.sweep)
    chunk = decode_chunk_frames(wildcards.ds, wildcards.sweep) * _frame_mb(wildcards.ds, wildcards.sweep)
    return attempt * math.ceil(BASE_MEM_MB + 3 * chunk + rows * cols * SHADOW_TIME_BYTES_PER_PIXEL / 2**20)


def get_shadow_time_chunk_runtime(wildcards, attempt):
    """Minutes of shadow_time_chunk, from the pixel-frames it streams."""
    start, stop = _part_range(wildcards)
    work = (stop - start) * math.prod(frame_shape(wildcards.ds, wildcards.sweep))
    return attempt * (5 + math.ceil(work * SHADOW_TIME_SECONDS_PER_PIXEL / 60))


def first_sweep(ds):
    """A sweep whose frame size is the dataset's: the time-lapse (outdoor) or u (lab)."""
    return outdoor_sweep(ds) if is_outdoor(ds) else SCENE_SWEEPS[0]


def get_image_mem_mb(wildcards, attempt):
    """Memory of a per-dataset step on whole images (dual coordinates, dual view, accuracy,
    figures, outdoor arrival/pushbroom): ~2 kB per camera pixel of image-sized maps."""
    rows, cols = frame_shape(wildcards.ds, first_sweep(wildcards.ds))
    return attempt * math.ceil(BASE_MEM_MB + rows * cols * 2000 / 2**20)


def get_stream_mem_mb(wildcards, attempt):
    """Memory of a step streaming a sweep (outdoor passes): image maps plus three read chunks."""
    sweep = first_sweep(wildcards.ds)
    chunk = decode_chunk_frames(wildcards.ds, sweep) * _frame_mb(wildcards.ds, sweep)
    return get_image_mem_mb(wildcards, attempt) + attempt * math.ceil(3 * chunk)


def get_stream_runtime(wildcards, attempt):
    """Minutes of a step streaming a sweep once (outdoor passes), from its pixel-frames."""
    sweep = first_sweep(wildcards.ds)
    work = sweep_frame_count(wildcards.ds, sweep) * math.prod(frame_shape(wildcards.ds, sweep))
    return attempt * (5 + math.ceil(work * SHADOW_TIME_SECONDS_PER_PIXEL / 60))


def get_render_mem_mb(wildcards, attempt):
    """Memory of render: the renderer holds one sweep's float32 RGB frames (plus scene maps)."""
    frames = sweep_frame_count(wildcards.ds, SCENE_SWEEPS[0])
    return attempt * math.ceil(get_image_mem_mb(wildcards, 1) + 3 * frames * _frame_mb(wildcards.ds, SCENE_SWEEPS[0]))
