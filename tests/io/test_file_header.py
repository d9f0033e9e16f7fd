"""Tests of shadowcam.io.file_header: capture facts from headers OpenImageIO cannot open."""

import datetime
import struct

import numpy as np
import pytest

from shadowcam.io.file_header import header_metadata
from shadowcam.io.raw_writer import write_dng

WHEN = datetime.datetime(2026, 6, 1, 20, 15, 3, 250000)


@pytest.mark.parametrize("compression", ["none", "ljpeg"])
def test_camera_dng_capture_time_exposure_and_bit_depth(tmp_path, compression):
    # cameras write lossless-JPEG DNGs, which OpenImageIO cannot open: the facts come from
    # the TIFF structure, the same as an uncompressed DNG's
    raw = np.random.default_rng(0).integers(64, 4000, (32, 48)).astype(np.uint16)
    path = write_dng(tmp_path / f"{compression}.dng", raw, bit_depth=12, black_level=64,
                     capture_time=WHEN, exposure_time=1 / 250, compression=compression)
    meta = header_metadata(path)
    assert meta == {"exposure_s": pytest.approx(0.004, rel=1e-6), "capture_time": WHEN.isoformat(),
                    "bits_per_sample": 12}


def _tiff_with_exif_ifd(path, *, exposure, original, subsec):
    """A little-endian 8x8 grey TIFF whose EXIF facts live in an EXIF IFD (tag 34665),
    where cameras put them, not in IFD 0."""
    def entry(code, kind, count, value):
        return struct.pack("<HHI", code, kind, count) + value

    original = original.encode() + b"\0"
    subsec = subsec.encode() + b"\0"
    image_at = 8
    ifd0_at = image_at + 64
    ifd0 = [entry(256, 3, 1, struct.pack("<HH", 8, 0)), entry(257, 3, 1, struct.pack("<HH", 8, 0)),
            entry(258, 3, 1, struct.pack("<HH", 8, 0)), entry(259, 3, 1, struct.pack("<HH", 1, 0)),
            entry(262, 3, 1, struct.pack("<HH", 1, 0)), entry(273, 4, 1, struct.pack("<I", image_at)),
            entry(277, 3, 1, struct.pack("<HH", 1, 0)), entry(278, 3, 1, struct.pack("<HH", 8, 0)),
            entry(279, 4, 1, struct.pack("<I", 64))]
    exif_at = ifd0_at + 2 + 12 * (len(ifd0) + 1) + 4
    ifd0.append(entry(34665, 4, 1, struct.pack("<I", exif_at)))
    data_at = exif_at + 2 + 12 * 3 + 4
    exif = [entry(33434, 5, 1, struct.pack("<I", data_at)),
            entry(36867, 2, len(original), struct.pack("<I", data_at + 8)),
            entry(37521, 2, len(subsec), subsec.ljust(4, b"\0"))]
    blob = (b"II*\0" + struct.pack("<I", ifd0_at) + bytes(64)
            + struct.pack("<H", len(ifd0)) + b"".join(ifd0) + struct.pack("<I", 0)
            + struct.pack("<H", len(exif)) + b"".join(exif) + struct.pack("<I", 0)
            + struct.pack("<II", *exposure) + original)
    path.write_bytes(blob)
    return path


def test_facts_in_the_exif_ifd_are_read(tmp_path):
    path = _tiff_with_exif_ifd(tmp_path / "exif.tif", exposure=(1, 125), original="2026:06:01 20:15:03",
                               subsec="25")
    meta = header_metadata(path)
    assert meta["exposure_s"] == pytest.approx(0.008)
    assert meta["capture_time"] == WHEN.isoformat()
    assert meta["bits_per_sample"] == 8


def test_a_file_neither_reader_opens_gives_no_facts(tmp_path):
    path = tmp_path / "broken.dng"
    path.write_bytes(b"not an image at all" * 10)
    assert header_metadata(path) == {"exposure_s": None, "capture_time": None, "bits_per_sample": None}
