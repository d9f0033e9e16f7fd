# Jobs of one step over parts of a dataset, merged exactly afterwards.
#
# Wildcards
# ---------
# part    decode part of a sweep, 0000, 0001, ..., 9999, 10000, ... (no limit): frames [i F, (i + 1) F) with
#         F = chunk_frames x decode.chunks_per_job; `decode` joins the part stores
#         (hard links, no copy) into results/{ds}/frames/{sweep}.zarr, and the
#         shadow_time_chunk jobs track the dips of the same frame ranges
# group   group of PARTS_PER_GROUP consecutive parts of a sweep with more parts than
#         that, 0000, 0001, ...: decode_group joins them (hard links) into
#         results/{ds}/frames/{sweep}.groups/{group}.zarr and `decode` joins the groups,
#         so no job lists more than PARTS_PER_GROUP inputs (Snakemake checks each
#         consumer of the sweep store against its producer's inputs: a sweep store
#         made of every part directly makes planning quadratic in the part count)
# span    time span of the first outdoor pass, START-STOP (frames; `0-end` when the
#         frame count is known only once the capture is rendered): config
#         outdoor.part_frames frames per job, merged into photometry.nc
# strip   column strip of the outdoor edge tracking, 0 .. edge_strips - 1, merged by
#         track_edges (config outdoor.edge_strips; 1 = one job, no strips)
#
# Memory of a job is bounded by one time chunk of chunk_frames frames, whatever the
# frames per job. The part ranges and part file names of a sweep are computed once
# per run (cached per dataset and sweep): an input function of one part looks its
# range up, so planning stays linear in the number of parts.
#
# The frames of a user capture are not inputs of decode_part (a sweep has hundreds and
# `snakemake -n` would print them all on one line): the manifest is, with their sha256
# sums, and `decode` has a param digesting every frame's path, size and modification
# time, so a changed frame decodes its sweep again.
import hashlib

from shadowcam.io.frame_store import default_chunk_frames


wildcard_constraints:
    part=r"\d\d\d\d+",
    group=r"\d\d\d\d+",
    span=r"\d+-(\d+|end)",
    strip=r"\d+",


#: parts joined by one decode_group job (sweeps with more parts are joined in two levels)
PARTS_PER_GROUP = 100

_PART_RANGES = {}
_PART_NAMES = {}


def decode_chunk_frames(ds):
    """Frames per store chunk: config decode.chunk_frames, or ~64 MiB of float32 RGB if null.

    Never more than the longest sweep of `ds`: a chunk longer than the sweep would only
    size the jobs' memory for frames that do not exist.
    """
    plan = capture(ds)
    longest = max([plan.n_frames(s) for s in plan.sweeps] + [1])
    configured = config["decode"]["chunk_frames"]
    if configured:
        return min(int(configured), longest)
    return min(default_chunk_frames(plan.frame_shape + (3,)), longest)


def decode_part_ranges(ds, sweep):
    """Frame ranges [(start, stop), ...] of the decode_part jobs of a sweep (cached)."""
    key = (ds, sweep)
    if key not in _PART_RANGES:
        total = capture(ds).n_frames(sweep)
        step = decode_chunk_frames(ds) * int(config["decode"]["chunks_per_job"])
        _PART_RANGES[key] = tuple(
            (start, min(start + step, total)) for start in range(0, total, step)
        )
    return _PART_RANGES[key]


def part_range(wildcards):
    """``(start, stop)`` frames of decode part `wildcards.part` of `wildcards.sweep`."""
    ranges = decode_part_ranges(wildcards.ds, wildcards.sweep)
    index = int(wildcards.part)
    if index >= len(ranges):
        raise ValueError(
            f"{wildcards.ds} sweep {wildcards.sweep} has {len(ranges)} parts, no part {index}"
        )
    return ranges[index]


def part_names(ds, sweep):
    """Names of the decode parts of a sweep in time order: 0000, 0001, ... (cached)."""
    key = (ds, sweep)
    if key not in _PART_NAMES:
        count = len(decode_part_ranges(ds, sweep))
        _PART_NAMES[key] = tuple(f"{i:04d}" for i in range(count))
    return _PART_NAMES[key]


def sweep_parts(ds, sweep, template):
    """`template` (with {ds}, {sweep}, {part}) of every decode part of a sweep, in time order."""
    return [
        template.format(ds=ds, sweep=sweep, part=part) for part in part_names(ds, sweep)
    ]


def get_decode_parts(wildcards):
    """Part stores of a sweep, or its group stores if it has more parts than PARTS_PER_GROUP (inputs of `decode`)."""
    parts = sweep_parts(
        wildcards.ds, wildcards.sweep, "results/{ds}/frames/{sweep}.parts/{part}.zarr"
    )
    if len(parts) <= PARTS_PER_GROUP:
        return parts
    count = -(-len(parts) // PARTS_PER_GROUP)
    return [
        f"results/{wildcards.ds}/frames/{wildcards.sweep}.groups/{i:04d}.zarr"
        for i in range(count)
    ]


def get_group_parts(wildcards):
    """Part stores of group `wildcards.group` of a sweep, in time order (inputs of `decode_group`)."""
    names = part_names(wildcards.ds, wildcards.sweep)
    first = int(wildcards.group) * PARTS_PER_GROUP
    if len(names) <= PARTS_PER_GROUP or first >= len(names):
        raise ValueError(
            f"{wildcards.ds} sweep {wildcards.sweep} has {len(names)} parts, no group {wildcards.group}"
        )
    return [
        f"results/{wildcards.ds}/frames/{wildcards.sweep}.parts/{name}.zarr"
        for name in names[first : first + PARTS_PER_GROUP]
    ]


def get_part_files(wildcards):
    """Inputs of one decode_part job: the rendered capture, or the manifest (and missing frames).

    A frame missing on disk stays an input, so that the dry run stops naming it.
    """
    plan = capture(wildcards.ds)
    if plan.rendered:
        return [f"results/{wildcards.ds}/capture"]
    start, stop = part_range(wildcards)
    files = relative(plan.sweep(wildcards.sweep).files[start:stop])
    return [manifest_path(wildcards.ds)] + [f for f in files if not os.path.exists(f)]


def get_sweep_stamp(wildcards):
    """Digest of path, size and modification time of every frame of a user sweep ("" if rendered)."""
    plan = capture(wildcards.ds)
    if plan.rendered:
        return ""
    digest = hashlib.sha256()
    for path in relative(plan.sweep(wildcards.sweep).files):
        try:
            stat = os.stat(path)
            digest.update(f"{path}\0{stat.st_size}\0{stat.st_mtime_ns}\n".encode())
        except FileNotFoundError:
            digest.update(f"{path}\0missing\n".encode())
    return digest.hexdigest()[:16]


def get_part_range(wildcards):
    """``START:STOP`` of ``shadowcam decode --frames`` (and ``--owned``) for one part."""
    start, stop = part_range(wildcards)
    return f"{start}:{stop}"


def get_chunk_frames(wildcards):
    """``--chunk-frames`` of a sweep (the same for all its parts)."""
    return decode_chunk_frames(wildcards.ds)


def get_partials(wildcards):
    """Dip-tracking partials of every sweep of `get_sweeps` (inputs of `shadow_time`)."""
    template = "results/{ds}/shadow_time/{sweep}.parts/{part}.npz"
    return [
        p for s in get_sweeps(wildcards) for p in sweep_parts(wildcards.ds, s, template)
    ]


def get_partials_option(wildcards, input):
    """``--partials SWEEP FILE... --partials ...`` of ``shadowcam shadow-time``."""
    template = "results/{ds}/shadow_time/{sweep}.parts/{part}.npz"
    return " ".join(
        f"--partials {s} " + " ".join(sweep_parts(wildcards.ds, s, template))
        for s in get_sweeps(wildcards)
    )


def outdoor_frame_count(ds):
    """Frames of the time-lapse of `ds`, or None if known only once rendered (dropped frames)."""
    plan = capture(ds)
    return None if plan.rendered else plan.n_frames(plan.outdoor_sweep)


def outdoor_spans(ds):
    """Time spans of the first outdoor pass of `ds`: ``START-STOP`` names (one ``0-end`` if unknown)."""
    n_frames = outdoor_frame_count(ds)
    size = int(config["outdoor"]["part_frames"])
    if n_frames is None or size <= 0:
        return ["0-end"]
    return [
        f"{start}-{min(start + size, n_frames)}" for start in range(0, n_frames, size)
    ]


def get_outdoor_photometry_parts(wildcards):
    """Span datasets of the first outdoor pass, merged into photometry.nc."""
    return [
        f"results/{wildcards.ds}/outdoor/photometry.parts/{span}.nc"
        for span in outdoor_spans(wildcards.ds)
    ]


def get_outdoor_span_range(wildcards):
    """``--part START:STOP`` value of a span ``START-STOP`` (``end`` = to the last frame)."""
    start, stop = wildcards.span.split("-")
    return f"{start}:{'' if stop == 'end' else stop}"


def edge_strip_count():
    """Column strips of the edge-tracking pass (config outdoor.edge_strips; 1 = one job)."""
    return int(config["outdoor"]["edge_strips"])


def get_edge_strips(wildcards):
    """Strip files of the edge-tracking pass merged by track_edges (none for one job)."""
    count = edge_strip_count()
    if count <= 1:
        return []
    return [
        f"results/{wildcards.ds}/outdoor/edges.strips/{index}.npz"
        for index in range(count)
    ]


def get_edge_strip_arg(wildcards):
    """``--strip I/N`` value of strip job `wildcards.strip`."""
    return f"{wildcards.strip}/{edge_strip_count()}"
