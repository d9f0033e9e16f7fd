"""Time chunks: decode parts and shadow-time chunks merge into the single-job results.

Exact ground truth here is the single-job result itself (and the frames' own
pixel values): the merged store must hold the same values, coordinates and
attributes, and even the same compressed chunk files, for any part size; shadow
times merged from per-chunk dip-tracking partials must equal a single streaming
pass bit for bit (and the exact shadow passage of a synthetic sweep). Also
checked: the workflow splits each sweep into the expected jobs.
"""

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from shadowcam.cli import main
from shadowcam.io.frame_store import iter_frame_chunks, merge_frame_stores, open_frames, write_frames

FRAMES = 23  # not a multiple of any part size used below: the last part is short


def chunk_files(store):
    """{relative path: bytes} of every chunk file of a store."""
    store = Path(store)
    return {str(p.relative_to(store)): p.read_bytes() for p in store.rglob("*") if p.is_file() and "/c/" in f"/{p.relative_to(store)}"}


def decode_in_parts(paths, out, *, chunk_frames, frames_per_part, times):
    parts = []
    for start in range(0, len(paths), frames_per_part):
        stop = min(start + frames_per_part, len(paths))
        parts.append(write_frames(paths[start:stop], out.parent / f"part{start:04d}.zarr", times_s=times[start:stop],
                                  attrs={"sweep": "u"}, chunk_frames=chunk_frames, first_frame=start))
    return merge_frame_stores(parts, out)


@pytest.mark.parametrize("chunk_frames, frames_per_part", [(4, 4), (4, 12), (5, 10), (3, 24)])
def test_merged_parts_equal_single_job_bit_for_bit(tmp_path, chunk_frames, frames_per_part, make_frames):
    paths, expected = make_frames(tmp_path / "frames", FRAMES, seed=3)
    times = np.linspace(0.0, 2.2, FRAMES)
    single = write_frames(paths, tmp_path / "single" / "u.zarr", times_s=times, attrs={"sweep": "u"},
                          chunk_frames=chunk_frames)
    merged = decode_in_parts(paths, tmp_path / "merged" / "u.zarr", chunk_frames=chunk_frames,
                             frames_per_part=frames_per_part, times=times)
    a, b = open_frames(single).load(), open_frames(merged).load()
    xr.testing.assert_identical(a, b)
    np.testing.assert_array_equal(b["image"].values, expected)  # the frames' exact pixel values
    np.testing.assert_array_equal(b["time"].values, np.arange(FRAMES))
    assert b.attrs["n_frames"] == FRAMES
    assert chunk_files(single) == chunk_files(merged)  # same compressed bytes, same chunk keys
    starts = [s for s, _ in iter_frame_chunks(open_frames(merged))]
    assert starts == list(range(0, FRAMES, chunk_frames))


@pytest.mark.parametrize("group", [2, 3])
def test_nested_merges_equal_one_merge_bit_for_bit(tmp_path, group, make_frames):
    paths, _ = make_frames(tmp_path / "frames", FRAMES, seed=4)
    times = np.linspace(0.0, 2.2, FRAMES)
    single = decode_in_parts(paths, tmp_path / "single" / "u.zarr", chunk_frames=2, frames_per_part=4, times=times)
    parts = sorted((tmp_path / "single").glob("part*.zarr"))
    groups = [merge_frame_stores(parts[i:i + group], tmp_path / "groups" / f"g{i:04d}.zarr")
              for i in range(0, len(parts), group)]
    assert int(open_frames(groups[1])["time"][0]) == 4 * group  # a group is a part store
    nested = merge_frame_stores(groups, tmp_path / "nested" / "u.zarr")
    xr.testing.assert_identical(open_frames(single).load(), open_frames(nested).load())
    assert chunk_files(single) == chunk_files(nested)


def test_merge_links_instead_of_copying(tmp_path, make_frames):
    paths, _ = make_frames(tmp_path / "frames", 8)
    merged = decode_in_parts(paths, tmp_path / "u.zarr", chunk_frames=2, frames_per_part=4, times=np.arange(8.0))
    part_chunk = tmp_path / "part0004.zarr" / "image" / "c" / "0" / "0" / "0" / "0"
    assert part_chunk.stat().st_ino == (merged / "image" / "c" / "2" / "0" / "0" / "0").stat().st_ino


def test_merge_rejects_gaps_order_and_mixed_chunks(tmp_path, make_frames):
    paths, _ = make_frames(tmp_path / "frames", 8)
    times = np.arange(8.0)
    a = write_frames(paths[:4], tmp_path / "a.zarr", times_s=times[:4], chunk_frames=2)
    b = write_frames(paths[4:], tmp_path / "b.zarr", times_s=times[4:], chunk_frames=2, first_frame=4)
    c = write_frames(paths[4:], tmp_path / "c.zarr", times_s=times[4:], chunk_frames=4, first_frame=4)
    with pytest.raises(ValueError, match="starts at frame 0, expected 8"):
        merge_frame_stores([b, a], tmp_path / "out.zarr")
    with pytest.raises(ValueError, match="same --chunk-frames"):
        merge_frame_stores([a, c], tmp_path / "out.zarr")
    with pytest.raises(ValueError, match="parts"):
        merge_frame_stores([], tmp_path / "out.zarr")
    assert not (tmp_path / "out.zarr").exists() and not list(tmp_path.glob(".out.zarr.*"))
    with pytest.raises(ValueError, match="first_frame"):
        write_frames(paths[3:], tmp_path / "d.zarr", times_s=times[3:], chunk_frames=2, first_frame=3)


def test_decode_cli_parts_equal_whole_sweep_with_provenance(tmp_path, make_frames, sweep_manifest):
    paths, expected = make_frames(tmp_path / "data" / "u", 7, seed=5)
    manifest = sweep_manifest(tmp_path, rate_hz=4.0)
    common = ["--manifest", str(manifest), "--sweep", "u", "--chunk-frames", "2"]
    assert main(["decode", *common, "--out", str(tmp_path / "whole.zarr")]) == 0
    parts = []
    for start, stop in [(0, 4), (4, 8)]:  # the workflow gives the last part its nominal stop
        parts.append(str(tmp_path / f"p{start}.zarr"))
        assert main(["decode", *common, "--frames", f"{start}:{stop}", "--out", parts[-1]]) == 0
    # each part verified and recorded only the files it read
    assert len(json.loads(open_frames(parts[1]).attrs["input_checksums"])) == 3
    assert main(["merge-frames", "--parts", *parts, "--out", str(tmp_path / "merged.zarr")]) == 0
    whole, merged = open_frames(tmp_path / "whole.zarr").load(), open_frames(tmp_path / "merged.zarr").load()
    xr.testing.assert_identical(whole, merged)  # values, time_s, provenance attrs
    np.testing.assert_array_equal(merged["image"].values, expected)

    # a corrupt frame fails only the part that reads it
    paths[5].write_bytes(paths[5].read_bytes() + b"\0")
    assert main(["decode", *common, "--frames", "0:4", "--out", str(tmp_path / "q0.zarr")]) == 0
    assert main(["decode", *common, "--frames", "4:8", "--out", str(tmp_path / "q1.zarr")]) == 2
    assert not (tmp_path / "q1.zarr").exists()
    for bad in ("3:6", "8:9", "x"):
        assert main(["decode", *common, "--frames", bad, "--out", str(tmp_path / "bad.zarr")]) == 2


def test_workflow_splits_sweeps_into_decode_jobs(tmp_path, workflow_copy, snakemake):
    """Dry run: ceil(frames / (chunk_frames x chunks_per_job)) decode_part and shadow_time_chunk
    jobs per sweep."""
    workdir = workflow_copy(tmp_path)
    frames = yaml.safe_load((workdir / "data_manifest" / "synthetic_tiny.yaml").read_text())["synthetic"]["frames"]
    sweeps = 4  # u, v, cal_u, cal_v
    for chunk_frames, per_job in [(4, 2), (5, 1), (16, 4)]:
        (workdir / "parts.yaml").write_text(yaml.safe_dump(
            {"decode": {"chunk_frames": chunk_frames, "chunks_per_job": per_job}}))
        result = snakemake(["-n", "--cores", "1", "--configfile", "config/config.yaml", "parts.yaml",
                            "--config", "datasets=[synthetic_tiny]"], workdir)
        assert result.returncode == 0, result.stdout[-3000:]
        stats = result.stdout.split("Job stats:")[1]
        counts = {m[1]: int(m[2]) for m in re.finditer(r"^(\w+)\s+(\d+)\s*$", stats, re.M)}
        parts = sweeps * math.ceil(frames / (chunk_frames * per_job))
        assert counts["decode_part"] == counts["shadow_time_chunk"] == parts
        assert counts["decode"] == sweeps and counts["shadow_time"] == 1


@pytest.fixture
def sweep_store(wire_sweep, write_image):
    """``sweep_store(folder, ...)``: a TIFF sweep and its frame store, whose shadow (2 frames wide)
    darkens column c in frames c and c + 1 (centre c + 0.5), lit 0.6, shadowed 0.05."""
    def make(folder, *, frames=23, shape=(6, 20), chunk_frames=4, seed=0):
        images, _ = wire_sweep(n_frames=frames, shape=shape, t0=0.0, px_per_frame=1.0, tilt=0.0, width=2.0,
                               supersample=1, albedo=np.full(shape + (3,), 0.6), depth=1 - 0.05 / 0.6,
                               noise=0.002, seed=seed, dtype=np.float64)
        folder.mkdir(parents=True)
        paths = [write_image(folder / f"{t:04d}.tif", np.round(image * 65535).astype(np.uint16))
                 for t, image in enumerate(images)]
        return write_frames(paths, folder.parent / f"{folder.name}.zarr", times_s=np.arange(float(frames)),
                            chunk_frames=chunk_frames)
    return make


@pytest.mark.parametrize("owned", [[(0, 23)], [(0, 8), (8, 16), (16, 24)], [(0, 5), (5, 23)]])
def test_shadow_time_from_chunk_partials_equals_single_pass(tmp_path, owned, sweep_store):
    stores = [sweep_store(tmp_path / sweep, seed=k) for k, sweep in enumerate(("u", "v"))]
    common = ["--frames", *map(str, stores), "--sweeps", "u", "v", "--method", "dip_centroid"]
    assert main(["shadow-time", *common, "--out", str(tmp_path / "single.nc")]) == 0
    partials = {}
    for store, sweep in zip(stores, ("u", "v")):
        for start, stop in owned:
            partials.setdefault(sweep, []).append(str(tmp_path / f"{sweep}.{start}.npz"))
            assert main(["shadow-time-chunk", "--frames", str(store), "--owned", f"{start}:{stop}",
                         "--out", partials[sweep][-1]]) == 0
    assert main(["shadow-time", *common, "--partials", "u", *partials["u"], "--partials", "v", *partials["v"],
                 "--out", str(tmp_path / "merged.nc")]) == 0
    with xr.open_dataset(tmp_path / "single.nc", engine="h5netcdf") as a, \
            xr.open_dataset(tmp_path / "merged.nc", engine="h5netcdf") as b:
        single, merged = a.load(), b.load()
    xr.testing.assert_identical(single, merged)  # bit for bit, attrs included
    # and physically right: the shadow centre passes column c at frame c + 0.5
    inside = np.arange(2, 19)
    times = merged["shadow_time"].sel(sweep="u").transpose("row", "col").values[:, inside]
    np.testing.assert_allclose(times, np.broadcast_to(inside + 0.5, times.shape), atol=0.1)


def test_shadow_time_partials_must_cover_every_sweep(tmp_path, sweep_store):
    store = sweep_store(tmp_path / "u")
    part = tmp_path / "u.npz"
    assert main(["shadow-time-chunk", "--frames", str(store), "--owned", "0:23", "--out", str(part)]) == 0
    base = ["shadow-time", "--frames", str(store), str(store), "--sweeps", "u", "v", "--out", str(tmp_path / "x.nc")]
    assert main([*base, "--partials", "u", str(part)]) == 2
    assert main([*base, "--partials", "u", str(part), "--partials", "v"]) == 2
    assert main(["shadow-time-chunk", "--frames", str(store), "--owned", "5:3", "--out", str(part)]) == 2
    assert not (tmp_path / "x.nc").exists()
