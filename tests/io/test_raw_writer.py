"""Tests of shadowcam.io.raw_writer: DNG and TIFF files read back exactly."""

import datetime

import numpy as np
import pytest
import rawpy
import tifffile

from shadowcam.io.raw_writer import write_dng, write_tiff16


@pytest.mark.parametrize("bit_depth, compression", [(12, "none"), (14, "none"), (12, "ljpeg"), (14, "ljpeg")])
def test_dng_round_trips_through_rawpy(tmp_path, bit_depth, compression):
    rng = np.random.default_rng(bit_depth)
    raw = rng.integers(0, 2**bit_depth, size=(32, 48)).astype(np.uint16)
    path = write_dng(tmp_path / "f.dng", raw, bit_depth=bit_depth, black_level=256,
                     capture_time=datetime.datetime(2024, 5, 6, 7, 8, 9), compression=compression)
    assert tifffile.TiffFile(path).pages[0].compression == {"none": 1, "ljpeg": 7}[compression]
    with rawpy.imread(str(path)) as r:
        np.testing.assert_array_equal(r.raw_image_visible, raw)
        np.testing.assert_array_equal(r.raw_pattern, [[0, 1], [3, 2]])
        assert r.color_desc == b"RGBG"
        assert list(r.black_level_per_channel) == [256] * 4
        assert r.white_level == 2**bit_depth - 1
    tags = tifffile.TiffFile(path).pages[0].tags
    assert tags["DateTimeOriginal"].value == "2024:05:06 07:08:09"


def test_dng_rejects_bad_input(tmp_path):
    with pytest.raises(ValueError, match="raw"):
        write_dng(tmp_path / "a.dng", np.zeros((31, 32), np.uint16), bit_depth=12,
                  black_level=0)
    with pytest.raises(ValueError, match="raw"):
        write_dng(tmp_path / "a.dng", np.full((32, 32), 5000, np.uint16), bit_depth=12,
                  black_level=0)
    with pytest.raises(ValueError, match="bit_depth"):
        write_dng(tmp_path / "a.dng", np.zeros((32, 32), np.uint16), bit_depth=13,
                  black_level=0)
    with pytest.raises(ValueError, match="compression"):
        write_dng(tmp_path / "a.dng", np.zeros((32, 32), np.uint16), bit_depth=12,
                  black_level=0, compression="zip")


def test_tiff16_round_trips(tmp_path):
    img = np.random.default_rng(0).integers(0, 65536, size=(10, 12, 3)).astype(np.uint16)
    path = write_tiff16(tmp_path / "f.tiff", img)
    np.testing.assert_array_equal(tifffile.imread(path), img)
    with pytest.raises(ValueError, match="image"):
        write_tiff16(tmp_path / "g.tiff", img.astype(np.float32))


def test_dng_sub_second_capture_time_and_exposure_read_back(tmp_path):
    from shadowcam.io.decode import header_metadata

    raw = np.full((32, 48), 300, dtype=np.uint16)
    when = datetime.datetime(2025, 1, 21, 15, 12, 49, 123000)
    path = write_dng(tmp_path / "f.dng", raw, bit_depth=14, black_level=256,
                     capture_time=when, exposure_time=0.00635)
    meta = header_metadata(path)
    assert meta["capture_time"] == when.isoformat()
    assert meta["exposure_s"] == pytest.approx(0.00635, rel=1e-6)
    with pytest.raises(ValueError, match="exposure_time"):
        write_dng(tmp_path / "g.dng", raw, bit_depth=14, black_level=256, exposure_time=0.0)
