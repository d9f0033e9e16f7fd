# Job resources sized from the capture plan: memory (mem_mb, MB) and run time
# (runtime, minutes) of each job, from the frame size and the frames it handles.
# Every function takes (wildcards, attempt) and scales with `attempt`, so a job that a
# cluster stopped for lack of memory or time is retried with more (profiles set the
# retries). The per-pixel and per-megapixel constants below name where they come from.
import math
import sys

#: MB of a Python process with the shadowcam imports loaded, with margin
#: (benchmarks/<ds>/decode_<sweep>.tsv max_rss: a step holding almost no data)
BASE_MEM_MB = 500
#: seconds per pixel of decoding one frame, ~3x the measured cost of a 24 MP
#: lossless-JPEG DNG (docs/DESIGN.md "Facts measured"; rawpy + demosaic + zstd write)
DECODE_SECONDS_PER_PIXEL = 2e-7
#: seconds per pixel of streaming one frame through shadow time
#: (benchmarks/<ds>/shadow_time_<sweep>_part<part>.tsv s over pixel-frames, with margin)
SHADOW_TIME_SECONDS_PER_PIXEL = 5e-8
#: bytes per camera pixel held by shadow time per sweep: tracker window and sums,
#: result maps, classification temporaries (benchmarks/<ds>/shadow_time.tsv max_rss)
SHADOW_TIME_BYTES_PER_PIXEL = 600
#: bytes per camera pixel of a step on whole images (dual coordinates, dual view,
#: accuracy, figures) (benchmarks/<ds>/dual_view.tsv max_rss)
IMAGE_BYTES_PER_PIXEL = 2000
#: MB per megapixel of frame and fixed MB of the outdoor steps, with margin
#: (`make bench-outdoor-size`: benchmarks/bench<N>/<rule>.tsv max_rss at 24 MP; tracking
#: and per-pixel steps: tracemalloc peaks per pixel, docs/benchmarks.md "Outdoor arrival",
#: plus 30%; tracking also keeps each pixel's final descent, track_edges.descent_frames
#: float16 values of coverage and as many of luminance (128: 512 bytes per pixel), and
#: fits it in batches of 4096 pixels)
OUTDOOR_MEM_MB = {
    "normalise": (400, 85),
    "track": (500, 800),
    "track_strip": (500, 800),
    "per_pixel": (400, 110),
}
#: seconds per frame and megapixel of the outdoor steps on one core
#: (`make bench-outdoor-size`: benchmarks/bench<N>/<rule>.tsv s at 24 MP)
OUTDOOR_S_PER_MP_FRAME = {
    "normalise": 0.25,
    "track": 0.35,
    "track_strip": 0.35,
    "per_pixel": 0.05,
}
#: bytes per camera pixel of a light-field step on one frame's brackets or on per-pixel
#: maps (HDR merge: E uint16 brackets + float64 merge temporaries; shadow times: the
#: tracker's sums; rays, renders, accuracy, report: ray and render maps), with margin
#: (benchmarks/<ds>/lightfield_*.tsv max_rss, docs/benchmarks.md "Light field")
LIGHTFIELD_BYTES_PER_PIXEL = 3000
#: MB of the candela-table step beyond the base: its tangent-plane grid of directions
#: depends on the beam's width and the gamma step, not on the camera
#: (benchmarks/<ds>/lightfield_export.tsv max_rss at 1 degree, with margin)
LIGHTFIELD_FAR_FIELD_MB = 600
#: frames assumed for an outdoor job whose frame count is known only once rendered
OUTDOOR_UNKNOWN_FRAMES = 1000


def _frame_mb(ds):
    """MB of one float32 RGB frame of `ds`."""
    rows, cols = capture(ds).frame_shape
    return rows * cols * 3 * 4 / 2**20


def _pixels(ds):
    return math.prod(capture(ds).frame_shape)


def get_decode_mem_mb(wildcards, attempt):
    """decode_part: two copies of a time chunk and a few frames of decoder buffers."""
    chunk = decode_chunk_frames(wildcards.ds)
    return attempt * math.ceil(BASE_MEM_MB + (2 * chunk + 4) * _frame_mb(wildcards.ds))


def get_decode_runtime(wildcards, attempt):
    """decode_part: from its frame and pixel count."""
    start, stop = part_range(wildcards)
    seconds = (stop - start) * _pixels(wildcards.ds) * DECODE_SECONDS_PER_PIXEL
    return attempt * (5 + math.ceil(seconds / 60))


def get_shadow_time_mem_mb(wildcards, attempt):
    """shadow_time: the merged summaries and per-sweep maps of every sweep."""
    maps = (
        len(get_sweeps(wildcards)) * _pixels(wildcards.ds) * SHADOW_TIME_BYTES_PER_PIXEL
    )
    return attempt * math.ceil(BASE_MEM_MB + maps / 2**20)


def get_shadow_time_chunk_mem_mb(wildcards, attempt):
    """shadow_time_chunk: a tracker's per-pixel state and three copies of a read chunk."""
    chunk = decode_chunk_frames(wildcards.ds) * _frame_mb(wildcards.ds)
    state = _pixels(wildcards.ds) * SHADOW_TIME_BYTES_PER_PIXEL / 2**20
    return attempt * math.ceil(BASE_MEM_MB + 3 * chunk + state)


def get_shadow_time_chunk_runtime(wildcards, attempt):
    """shadow_time_chunk: from the pixel-frames it streams."""
    start, stop = part_range(wildcards)
    seconds = (stop - start) * _pixels(wildcards.ds) * SHADOW_TIME_SECONDS_PER_PIXEL
    return attempt * (5 + math.ceil(seconds / 60))


def get_image_mem_mb(wildcards, attempt):
    """A per-dataset step on whole images: image-sized maps."""
    maps = _pixels(wildcards.ds) * IMAGE_BYTES_PER_PIXEL / 2**20
    return attempt * math.ceil(BASE_MEM_MB + maps)


def get_render_mem_mb(wildcards, attempt):
    """render: one sweep's float32 RGB frames (plus scene maps)."""
    plan = capture(wildcards.ds)
    frames = plan.n_frames(plan.outdoor_sweep if plan.is_outdoor else "u")
    sweep = 3 * frames * _frame_mb(wildcards.ds)
    return get_image_mem_mb(wildcards, attempt) + attempt * math.ceil(sweep)


def _outdoor_stage(stage):
    """The merge of strips (track_edges with edge_strips > 1) only handles (T, W) curves and maps."""
    return "per_pixel" if stage == "track" and edge_strip_count() > 1 else stage


def _outdoor_megapixels(wildcards, stage):
    """Megapixels an outdoor job reads per frame: a strip its columns plus the halo each side."""
    plan = capture(wildcards.ds)
    if stage != "track_strip":
        return plan.megapixels
    halo_share = 2 * plan.strip_halo / plan.frame_shape[1]
    return plan.megapixels * min(1.0, 1 / edge_strip_count() + halo_share)


def _outdoor_frames(wildcards, stage):
    """Frames an outdoor job of `stage` handles (a first-pass span: warm-up and reference too)."""
    n_frames = outdoor_frame_count(wildcards.ds)
    if (
        stage == "normalise"
        and n_frames is not None
        and not wildcards.span.endswith("end")
    ):
        start, stop = (int(v) for v in wildcards.span.split("-"))
        return stop - start + 3
    return n_frames or OUTDOOR_UNKNOWN_FRAMES


def _outdoor_mem_mb(wildcards, attempt, stage):
    fixed, per_mp = OUTDOOR_MEM_MB[_outdoor_stage(stage)]
    return attempt * int(fixed + per_mp * _outdoor_megapixels(wildcards, stage))


def _outdoor_runtime(wildcards, attempt, stage):
    """3x the measured rate, at least 10 minutes."""
    rate = OUTDOOR_S_PER_MP_FRAME[_outdoor_stage(stage)]
    seconds = (
        rate * _outdoor_megapixels(wildcards, stage) * _outdoor_frames(wildcards, stage)
    )
    return attempt * max(10, int(3 * seconds / 60) + 1)


def get_normalise_mem_mb(wildcards, attempt):
    """outdoor_normalise_part: registration and gains of one time span."""
    return _outdoor_mem_mb(wildcards, attempt, "normalise")


def get_normalise_runtime(wildcards, attempt):
    """outdoor_normalise_part: from the frames of its span."""
    return _outdoor_runtime(wildcards, attempt, "normalise")


def get_track_strip_mem_mb(wildcards, attempt):
    """track_edges_strip: the edge tracking of one column strip and its halo."""
    return _outdoor_mem_mb(wildcards, attempt, "track_strip")


def get_track_strip_runtime(wildcards, attempt):
    """track_edges_strip: every frame over the strip's columns."""
    return _outdoor_runtime(wildcards, attempt, "track_strip")


def get_track_edges_mem_mb(wildcards, attempt):
    """track_edges: the whole edge tracking, or the merge of its strips."""
    return _outdoor_mem_mb(wildcards, attempt, "track")


def get_track_edges_runtime(wildcards, attempt):
    """track_edges: every frame, or the merge of its strips."""
    return _outdoor_runtime(wildcards, attempt, "track")


def get_per_pixel_mem_mb(wildcards, attempt):
    """Outdoor steps on per-pixel maps and (T, W) curves (merge, arrival, pushbroom, ...)."""
    return _outdoor_mem_mb(wildcards, attempt, "per_pixel")


def get_per_pixel_runtime(wildcards, attempt):
    """Outdoor steps on per-pixel maps and (T, W) curves."""
    return _outdoor_runtime(wildcards, attempt, "per_pixel")


class _PlanningWildcards(dict):
    """Wildcards of a dataset's first job of each kind, for sizing before the DAG is built."""

    __getattr__ = dict.__getitem__


def get_lightfield_mem_mb(wildcards, attempt):
    """A light-field step on one frame or per-pixel maps (memory independent of the frames)."""
    maps = _pixels(wildcards.ds) * LIGHTFIELD_BYTES_PER_PIXEL / 2**20
    return attempt * math.ceil(BASE_MEM_MB + maps)


def get_lightfield_export_mem_mb(wildcards, attempt):
    """lightfield_export: the rays and the far-field direction grid."""
    return get_lightfield_mem_mb(wildcards, attempt) + attempt * LIGHTFIELD_FAR_FIELD_MB


def get_array_mem_mb(wildcards, attempt):
    """A camera-array step: both experiments' float32 RGB frames and the crossing images."""
    images = capture(wildcards.ds).camera_array["images"]
    return get_image_mem_mb(wildcards, attempt) + attempt * math.ceil(
        3 * images * _frame_mb(wildcards.ds)
    )


def get_light_set_mem_mb(wildcards, attempt):
    """A several-lights step: the u and v sweeps' float32 RGB frames."""
    frames = capture(wildcards.ds).light_set["frames"]
    return get_image_mem_mb(wildcards, attempt) + attempt * math.ceil(
        3 * 2 * frames * _frame_mb(wildcards.ds)
    )


def planned_mem_mb(ds):
    """Memory (MB, first attempt) of the largest job of each kind of dataset `ds`."""
    plan = capture(ds)
    if plan.camera_array is not None:
        return {"camera-array steps": get_array_mem_mb(_PlanningWildcards(ds=ds), 1)}
    if plan.light_set is not None:
        return {
            "several-lights steps": get_light_set_mem_mb(_PlanningWildcards(ds=ds), 1)
        }
    if plan.is_lightfield:
        wildcards = _PlanningWildcards(ds=ds)
        return {
            "lightfield steps": get_lightfield_mem_mb(wildcards, 1),
            "lightfield_export": get_lightfield_export_mem_mb(wildcards, 1),
        }
    sweep = plan.outdoor_sweep if plan.is_outdoor else plan.timed_sweeps[0]
    wildcards = _PlanningWildcards(
        ds=ds, sweep=sweep, part="0000", span="0-end", strip="0"
    )
    sizes = {
        "decode_part": get_decode_mem_mb(wildcards, 1),
        "decode_reference and the image steps": get_image_mem_mb(wildcards, 1),
    }
    if plan.rendered:
        sizes["render"] = get_render_mem_mb(wildcards, 1)
    if plan.is_outdoor:
        sizes["outdoor_normalise_part"] = get_normalise_mem_mb(wildcards, 1)
        sizes["track_edges"] = get_track_edges_mem_mb(wildcards, 1)
        sizes["outdoor per-pixel steps"] = get_per_pixel_mem_mb(wildcards, 1)
    else:
        sizes["shadow_time_chunk"] = get_shadow_time_chunk_mem_mb(wildcards, 1)
        sizes["shadow_time"] = get_shadow_time_mem_mb(wildcards, 1)
    return sizes


def _check_job_sizes():
    """Stop the plan when a configured dataset needs a job larger than config max_job_mem_mb."""
    ceiling = int(config["max_job_mem_mb"])
    for ds in config["datasets"]:
        job, size = max(planned_mem_mb(ds).items(), key=lambda item: item[1])
        if size > ceiling:
            rows, cols = capture(ds).frame_shape
            sys.exit(
                f"error: dataset {ds!r} ({manifest_path(ds)}): frames of {rows} x {cols} pixels "
                f"({rows * cols / 1e6:.3g} MP) need {size:,} MB of memory in job {job}, above "
                f"max_job_mem_mb {ceiling:,} MB (config). Crop or bin the frames, lower "
                f"decode.chunk_frames if decode_part is the largest job, or raise "
                f"max_job_mem_mb if your machines have that much memory."
            )


_check_job_sizes()
