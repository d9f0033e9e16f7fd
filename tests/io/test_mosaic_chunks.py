"""Tests of shadowcam.io.mosaic_chunks: a mosaic store's chunks read straight from their files equal zarr's read."""

import numpy as np
import pytest
import zarr
from zarr.codecs import BloscCodec, ZstdCodec

import shadowcam.io.frame_store as frame_store
from shadowcam.io.frame_store import iter_store_luminance, open_frames, write_frames
from shadowcam.io.luminance import channel_mean
from shadowcam.io.mosaic_chunks import MosaicChunks


@pytest.fixture
def raw_paths(tmp_path, write_pidng):
    """Five 12-bit RGGB DNGs of 38x30 pixels and their float decodes."""
    from shadowcam.io.decode import read_frame

    rng = np.random.default_rng(11)
    paths = [write_pidng(tmp_path / f"f{k}.dng", rng.integers(200, 4096, size=(38, 30)), pattern="RGGB", black=256)
             for k in range(5)]
    return paths, np.stack([read_frame(p) for p in paths])


def _store(paths, path, compressors, monkeypatch):
    """A mosaic store of `paths` (chunks of 2 frames) written with the mosaic `compressors`."""
    monkeypatch.setattr(frame_store, "_MOSAIC_COMPRESSORS", compressors)
    return write_frames(paths, path, times_s=np.arange(float(len(paths))), chunk_frames=2)


@pytest.mark.parametrize("compressors, direct", [
    ((BloscCodec(cname="lz4", clevel=9, shuffle="bitshuffle", typesize=2),), True),  # this version's stores
    ((BloscCodec(cname="zstd", clevel=1, shuffle="bitshuffle", typesize=2),), True),  # earlier stores
    ((BloscCodec(cname="blosclz", clevel=5, shuffle="shuffle", typesize=2),), True),
    ((ZstdCodec(level=1),), False),  # not Blosc: zarr reads it
])
def test_windows_equal_zarrs_read_whatever_the_stores_codec(raw_paths, tmp_path, monkeypatch, compressors, direct):
    paths, decoded = raw_paths
    store = _store(paths, tmp_path / "sweep.zarr", compressors, monkeypatch)
    chunks = MosaicChunks(store / "mosaic")
    stored = zarr.open_array(store / "mosaic", mode="r")[...]
    for t0, t1, r0, r1, c0, c1 in [(0, 2, 0, 38, 0, 30), (2, 3, 4, 10, 2, 17), (4, 5, 0, 38, 0, 30), (1, 2, 0, 5, 3, 4)]:
        got = chunks.window(t0, t1, r0, r1, c0, c1)
        if not direct:
            assert got is None
            continue
        assert not got.flags.writeable
        np.testing.assert_array_equal(got, stored[t0:t1, r0:r1, c0:c1])
    assert chunks.window(1, 3, 0, 38, 0, 30) is None  # two chunks: zarr reads it
    # either way the store reads as the frames' decode, bit for bit, in colour and as luminance
    frames = open_frames(store)
    np.testing.assert_array_equal(frames["image"].values, decoded)
    np.testing.assert_array_equal(frames["image"][1:4, 3:9].values, decoded[1:4, 3:9])
    np.testing.assert_array_equal(np.stack(list(iter_store_luminance(frames.isel(time=slice(1, 5))))),
                                  channel_mean(decoded[1:5]))


def test_a_missing_chunk_file_is_left_to_zarr(raw_paths, tmp_path, monkeypatch):
    paths, _ = raw_paths
    store = _store(paths, tmp_path / "sweep.zarr", frame_store._MOSAIC_COMPRESSORS, monkeypatch)
    (store / "mosaic" / "c" / "1" / "0" / "0").unlink()
    chunks = MosaicChunks(store / "mosaic")
    assert chunks.window(2, 3, 0, 38, 0, 30) is None
    assert chunks.window(0, 1, 0, 38, 0, 30) is not None


def test_the_chunk_held_is_reused_and_replaced(raw_paths, tmp_path, monkeypatch):
    import pickle

    paths, _ = raw_paths
    store = _store(paths, tmp_path / "sweep.zarr", frame_store._MOSAIC_COMPRESSORS, monkeypatch)
    stored = zarr.open_array(store / "mosaic", mode="r")[...]
    chunks = MosaicChunks(store / "mosaic")
    np.testing.assert_array_equal(chunks.window(0, 1, 0, 38, 0, 30), stored[0:1])
    second = chunks.window(1, 2, 0, 38, 0, 30)  # the chunk held: frames 0 and 1
    np.testing.assert_array_equal(second, stored[1:2])
    np.testing.assert_array_equal(chunks.window(3, 4, 0, 38, 0, 30), stored[3:4])
    np.testing.assert_array_equal(second, stored[3:4])  # the next chunk (frames 2, 3) in the same buffer
    copy = pickle.loads(pickle.dumps(chunks))  # without its buffer, with a lock of its own
    np.testing.assert_array_equal(copy.window(4, 5, 0, 38, 0, 30), stored[4:5])
