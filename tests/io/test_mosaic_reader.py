"""The direct DNG read gives rawpy's mosaic exactly, and rawpy decides whenever a file differs."""


import numpy as np
import pytest

from shadowcam.io.raw_mosaic import read_mosaic
from shadowcam.io.mosaic_reader import MosaicReader
from shadowcam.io.raw_writer import write_dng



def _mosaic(seed, shape=(24, 40), top=16383):
    return np.random.default_rng(seed).integers(0, top + 1, shape).astype(np.uint16)


@pytest.mark.parametrize("bit_depth, compression", [(14, "none"), (12, "none"), (10, "none"),
                                                    (14, "ljpeg"), (12, "ljpeg")])
def test_dngs_are_read_directly_and_exactly_as_rawpy_reads_them(tmp_path, bit_depth, compression):
    """16-bit, bit-packed and lossless-JPEG DNGs."""
    paths = [write_dng(tmp_path / f"f{k}.dng", _mosaic(k, top=2**bit_depth - 1), bit_depth=bit_depth,
                       black_level=64, compression=compression) for k in range(3)]
    reader = MosaicReader(paths[0])
    assert reader.direct
    for path in paths:
        mosaic, levels = reader.read(path)
        reference, reference_levels = read_mosaic(path)
        np.testing.assert_array_equal(mosaic, reference, strict=True)
        np.testing.assert_array_equal(levels["black_sites"], reference_levels["black_sites"])
        np.testing.assert_array_equal(levels["white_sites"], reference_levels["white_sites"])


def test_a_frame_with_other_levels_is_read_with_rawpy(tmp_path):
    first = write_dng(tmp_path / "a.dng", _mosaic(0), bit_depth=14, black_level=512)
    other = write_dng(tmp_path / "b.dng", _mosaic(1), bit_depth=14, black_level=600)
    _, levels = MosaicReader(first).read(other)
    assert levels["black_sites"].tolist() == [[600.0, 600.0], [600.0, 600.0]]


def test_a_frame_compressed_otherwise_is_read_with_rawpy(tmp_path):
    first = write_dng(tmp_path / "a.dng", _mosaic(0), bit_depth=14, black_level=512)
    other = write_dng(tmp_path / "b.dng", _mosaic(1), bit_depth=14, black_level=512, compression="ljpeg")
    reader = MosaicReader(first)
    assert reader._direct(other)[0] != reader._layout
    np.testing.assert_array_equal(reader.read(other)[0], read_mosaic(other)[0])


def test_the_independent_renderers_dngs_are_read_as_rawpy_reads_them(shared_data):
    paths = sorted((shared_data / "lab-dev" / "dev_spheres_raw" / "frames_u").glob("*.dng"))[:2]
    reader = MosaicReader(paths[0])
    for path in paths:
        np.testing.assert_array_equal(reader.read(path)[0], read_mosaic(path)[0])


def test_frames_of_another_size_are_refused(tmp_path):
    first = write_dng(tmp_path / "a.dng", _mosaic(0), bit_depth=14, black_level=512)
    small = write_dng(tmp_path / "b.dng", _mosaic(1, shape=(24, 32)), bit_depth=14, black_level=512)
    with pytest.raises(ValueError, match="first frame"):
        MosaicReader(first).read(small)
    broken = tmp_path / "c.dng"
    broken.write_bytes(first.read_bytes()[:200])
    with pytest.raises(ValueError, match="c.dng"):
        MosaicReader(first).read(broken)


def test_decoding_a_sequence_reads_its_mosaics_directly_with_identical_frames(tmp_path):
    from shadowcam.io.decode import iter_frames, read_frame

    paths = [write_dng(tmp_path / f"f{k}.dng", _mosaic(k), bit_depth=14, black_level=512, compression="ljpeg")
             for k in range(3)]
    for path, image, info in iter_frames(paths):
        np.testing.assert_array_equal(image, read_frame(path), strict=True)  # read_frame alone: rawpy
        assert info["decoder"].startswith("tifffile")
    assert read_frame(paths[0], return_info=True)[1]["decoder"].startswith("rawpy")
