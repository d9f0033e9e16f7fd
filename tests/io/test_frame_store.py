"""Tests of shadowcam.io.frame_store and the decode CLI: round trip, atomic writes, bounded memory."""

import json
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
import yaml

from shadowcam.cli import main
from shadowcam.io.frame_store import (
    CHUNK_BYTES,
    default_chunk_frames,
    iter_frame_chunks,
    merge_frame_stores,
    open_frames,
    write_frames,
    write_reference,
)
from shadowcam.io.manifest import checksums_for


def test_default_chunk_frames():
    assert default_chunk_frames((192, 192, 3)) == CHUNK_BYTES // (192 * 192 * 3 * 4) == 151
    assert default_chunk_frames((6000, 4000, 3)) == 1  # a 24 MP frame exceeds 64 MiB alone
    with pytest.raises(ValueError, match="frame_shape"):
        default_chunk_frames((0, 3, 3))


def test_round_trip_and_chunks(tmp_path, make_frames):
    paths, expected = make_frames(tmp_path / "in", 7, ExposureTime=0.004)
    times = np.array([0.0, 0.5, 1.1, 1.5, 2.0, 2.5, 3.0])
    out = write_frames(paths, tmp_path / "u.zarr", times_s=times, attrs={"input_checksums": {"a": "b"}, "sweep": "u"},
                       chunk_frames=3)
    ds = open_frames(out)
    image = ds["image"]
    assert image.dims == ("time", "row", "col", "channel") and image.dtype == np.float32
    assert image.encoding["chunks"] == (3, 12, 10, 3)
    assert "zstd" in repr(image.encoding["compressors"]).lower()
    np.testing.assert_array_equal(image.values, expected)
    np.testing.assert_array_equal(ds["time"].values, np.arange(7.0))
    assert ds["time"].dtype == np.float64 and ds["time"].attrs["units"] == "frame"
    np.testing.assert_array_equal(ds["time_s"].values, times)
    np.testing.assert_allclose(ds["exposure_s"].values, 0.004)  # from the TIFF headers
    assert list(ds["channel"].values) == ["R", "G", "B"]
    assert ds.attrs["sweep"] == "u" and json.loads(ds.attrs["input_checksums"]) == {"a": "b"}
    assert ds.attrs["decoder"].startswith("OpenImageIO") and ds.attrs["white_level"] == 65535.0
    blocks = list(iter_frame_chunks(ds))
    assert [(start, block.shape[0]) for start, block in blocks] == [(0, 3), (3, 3), (6, 1)]
    assert all(block.dtype == np.float32 for _, block in blocks)
    np.testing.assert_array_equal(np.concatenate([b for _, b in blocks]), expected)
    assert [s for s, _ in iter_frame_chunks(ds, chunk_frames=5)] == [0, 5]
    assert not list(tmp_path.glob(".u.zarr.*"))


def test_reference_store_is_mean_of_frames(tmp_path, make_frames):
    paths, expected = make_frames(tmp_path / "ref", 2)
    ds = open_frames(write_reference(paths, tmp_path / "reference.zarr", attrs={"sweep": "reference"}))
    assert ds["image"].dims == ("row", "col", "channel")
    np.testing.assert_allclose(ds["image"].values, expected.mean(axis=0), rtol=1e-6)
    assert ds.attrs["n_frames_averaged"] == 2


def test_failed_write_leaves_no_store_and_keeps_old(tmp_path, write_image, make_frames):
    paths, _ = make_frames(tmp_path / "in", 4)
    out = write_frames(paths[:2], tmp_path / "u.zarr", times_s=[0, 1])
    odd = write_image(tmp_path / "in" / "odd.tif", np.zeros((12, 11, 3), np.uint16))
    with pytest.raises(ValueError, match=r"odd\.tif.*12x11.*0000\.tif.*12x10"):
        write_frames(paths + [odd], out, times_s=np.arange(5.0), chunk_frames=2)
    assert not list(tmp_path.glob(".u.zarr.*"))
    assert open_frames(out).sizes["time"] == 2  # previous complete store untouched
    with pytest.raises(ValueError, match="does not exist"):
        open_frames(tmp_path / "v.zarr")


def test_input_validation(tmp_path, make_frames):
    paths, _ = make_frames(tmp_path / "in", 2)
    with pytest.raises(ValueError, match="times_s"):
        write_frames(paths, tmp_path / "u.zarr", times_s=[0.0])
    with pytest.raises(ValueError, match="chunk_frames"):
        write_frames(paths, tmp_path / "u.zarr", times_s=[0.0, 1.0], chunk_frames=0)
    with pytest.raises(ValueError, match=".zarr"):
        write_frames(paths, tmp_path / "u.nc", times_s=[0.0, 1.0])


def _peak_bytes(paths, out):
    tracemalloc.start()
    try:
        write_frames(paths, out, times_s=np.arange(len(paths), dtype=float), chunk_frames=10)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_memory_bounded_by_chunk_not_frame_count(tmp_path, make_frames):
    shape = (64, 64, 3)
    frame_bytes = int(np.prod(shape)) * 4
    paths, _ = make_frames(tmp_path / "in", 200, shape=shape)
    _peak_bytes(paths[:10], tmp_path / "warm.zarr")  # import / codec set-up outside the measurement
    peak_50 = _peak_bytes(paths[:50], tmp_path / "a.zarr")
    peak_200 = _peak_bytes(paths, tmp_path / "b.zarr")
    # holding all frames would need 200 frames (9.8 MB); one chunk is 10 frames
    assert peak_200 < 50 * frame_bytes
    # 150 more frames add (much) less than 15 frames of memory: no accumulation
    assert peak_200 - peak_50 < 15 * frame_bytes
    # reading back streams too: one 10-frame chunk at a time
    ds = open_frames(tmp_path / "b.zarr")
    tracemalloc.start()
    try:
        total = sum(float(block[..., 0].sum()) for _, block in iter_frame_chunks(ds))
        peak_read = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak_read < 50 * frame_bytes
    assert total > 0 and ds.sizes["time"] == 200


def test_decode_cli_verifies_then_writes(tmp_path, write_image, make_frames):
    paths, expected = make_frames(tmp_path / "data" / "u", 5)
    write_image(tmp_path / "data" / "ref.tif", np.full((12, 10, 3), 32768, np.uint16))
    doc = {"name": "cap", "kind": "lab", "light": "point", "root": "data",
           "sweeps": {"u": {"files": "u/*.tif", "axis": "u"}}, "reference": "ref.tif",
           "timing": {"source": "rate", "rate_hz": 10.0}}
    manifest = tmp_path / "cap.yaml"
    manifest.write_text(yaml.safe_dump(doc))
    doc["checksums"] = checksums_for(manifest)
    manifest.write_text(yaml.safe_dump(doc))

    assert main(["decode", "--manifest", str(manifest), "--sweep", "u", "--out", str(tmp_path / "f/u.zarr"),
                 "--chunk-frames", "2"]) == 0
    ds = open_frames(tmp_path / "f/u.zarr")
    np.testing.assert_array_equal(ds["image"].values, expected)
    np.testing.assert_allclose(ds["time_s"].values, np.arange(5) / 10.0)
    assert ds.attrs["step"] == "decode" and ds.attrs["axis"] == "u"
    assert json.loads(ds.attrs["input_checksums"]) == {f"u/{Path(p).name}": doc["checksums"][f"u/{Path(p).name}"] for p in paths}

    assert main(["decode", "--manifest", str(manifest), "--sweep", "reference", "--out", str(tmp_path / "f/reference.zarr")]) == 0
    np.testing.assert_array_equal(open_frames(tmp_path / "f/reference.zarr")["image"].values, np.float32(32768 / 65535))

    paths[3].write_bytes(paths[3].read_bytes() + b"\0")  # corrupt one frame
    assert main(["decode", "--manifest", str(manifest), "--sweep", "u", "--out", str(tmp_path / "f/u2.zarr")]) == 2
    assert not (tmp_path / "f/u2.zarr").exists() and not (tmp_path / "f/u2.zarr.tmp").exists()


@pytest.fixture
def raw_sweep(tmp_path, write_pidng):
    """Five 12-bit GRBG DNGs of 38x30 pixels, their float decodes, and their mosaic store (chunks of 2 frames)."""
    from shadowcam.io.decode import read_frame

    folder = tmp_path / "raw_sweep"
    folder.mkdir()
    rng = np.random.default_rng(5)
    paths = [write_pidng(folder / f"f{k}.dng", rng.integers(200, 4096, size=(38, 30)), pattern="GRBG", black=256)
             for k in range(5)]
    decoded = np.stack([read_frame(p) for p in paths])
    store = write_frames(paths, folder / "sweep.zarr", times_s=np.arange(5.0), chunk_frames=2)
    return paths, decoded, store


def test_raw_sweep_is_stored_as_mosaics_that_read_as_the_float_decode(raw_sweep, tmp_path):
    paths, decoded, store = raw_sweep
    assert (store / "mosaic").is_dir() and not (store / "image").exists()
    frames = open_frames(store)
    assert frames["image"].dims == ("time", "row", "col", "channel") and frames["image"].dtype == np.float32
    np.testing.assert_array_equal(frames["image"].values, decoded)  # bit for bit, whole sweep
    blocks = list(iter_frame_chunks(frames))
    assert [start for start, _ in blocks] == [0, 2, 4]
    np.testing.assert_array_equal(np.concatenate([b for _, b in blocks]), decoded)
    # a column strip reads like the strip of the whole decode (edges of the window exact)
    np.testing.assert_array_equal(frames.isel(col=slice(7, 19))["image"].values, decoded[:, :, 7:19])
    parts = [write_frames(paths[a:b], tmp_path / f"p{a}.zarr", times_s=np.arange(a, b, dtype=float),
                          chunk_frames=2, first_frame=a) for a, b in ((0, 2), (2, 5))]
    merged = open_frames(merge_frame_stores(parts, tmp_path / "merged.zarr"))
    np.testing.assert_array_equal(merged["image"].values, decoded)
    np.testing.assert_array_equal(merged["time"].values, np.arange(5.0))


def test_any_window_of_a_mosaic_store_is_the_window_of_the_whole_decode(raw_sweep):
    from hypothesis import given, settings
    from hypothesis import strategies as st

    _, decoded, store = raw_sweep
    image = open_frames(store)["image"]

    def axis(n):
        index = st.integers(0, n - 1)
        # (xarray itself fails on empty reversed slices: those are left out)
        ranges = st.tuples(st.integers(0, n), st.integers(0, n), st.sampled_from([1, 2, 3, -1])).filter(
            lambda r: r[2] > 0 or r[1] > r[0])
        return st.one_of(index, ranges.map(
            lambda r: slice(r[0], r[1], r[2]) if r[2] > 0 else slice(r[1] - 1, r[0] - 1 if r[0] else None, -1)))

    @settings(max_examples=120, deadline=None)
    @given(axis(5), axis(38), axis(30), axis(3))
    def check(t, r, c, ch):
        key = (t, r, c, ch)
        got = image[key].values
        assert got.shape == decoded[key].shape
        np.testing.assert_array_equal(got, decoded[key])

    check()


def test_luminance_of_a_mosaic_store_is_the_channel_mean_of_its_frames(raw_sweep, make_frames, tmp_path):
    from shadowcam.io.frame_store import iter_store_frames, iter_store_luminance
    from shadowcam.io.luminance import channel_mean

    _, decoded, store = raw_sweep
    frames = open_frames(store)
    want = channel_mean(decoded)
    assert frames["luminance"].dims == ("time", "row", "col")
    np.testing.assert_array_equal(np.stack(list(iter_store_luminance(frames))), want)  # chunks of 2
    np.testing.assert_array_equal(np.stack(list(iter_store_luminance(frames.isel(time=slice(1, 4))))), want[1:4])
    np.testing.assert_array_equal(frames["luminance"][2:4, 5:17, 3:9].values, want[2:4, 5:17, 3:9])
    np.testing.assert_array_equal(frames["luminance"][1, 7, ::3].values, want[1, 7, ::3])
    # a float store has no luminance variable: the frames are averaged as they are read
    paths, _ = make_frames(tmp_path / "float", 3)
    floats = open_frames(write_frames(paths, tmp_path / "float.zarr", times_s=np.arange(3.0)))
    assert "luminance" not in floats
    np.testing.assert_array_equal(np.stack(list(iter_store_luminance(floats))),
                                  np.stack([channel_mean(f) for f in iter_store_frames(floats)]))
