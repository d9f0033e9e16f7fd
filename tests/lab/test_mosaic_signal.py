"""The tracker's signal from the Bayer mosaic equals the channel sum of the demosaiced frame."""


import numpy as np
import pytest

from shadowcam.io.cfa import site_constants
from shadowcam.io.decode import read_frame
from shadowcam.io.raw_mosaic import read_mosaic
from shadowcam.lab.mosaic_signal import bilinear_channels, mosaic_signal
from shadowcam.lab.sweep_files import track_files

PATTERNS = ("RGGB", "BGGR", "GRBG", "GBRG")


def _noisy_mosaic(shape, seed, *, black=256, white=4095):
    rng = np.random.default_rng(seed)
    smooth = np.cumsum(np.cumsum(rng.normal(size=shape), axis=0), axis=1)
    smooth = (smooth - smooth.min()) / np.ptp(smooth)
    return (black + (white - black) * (0.05 + 0.9 * smooth) + rng.normal(0, 20, shape)).clip(0, white).astype(np.uint16)


def _normalised(mosaic, levels):
    black = site_constants(levels["black_sites"], mosaic.shape)
    return (mosaic - black) / (site_constants(levels["white_sites"], mosaic.shape) - black)


@pytest.mark.parametrize("pattern", PATTERNS)
def test_signal_and_channels_equal_the_demosaiced_frame(tmp_path, pattern, write_pidng):
    """Against OpenCV's bilinear demosaic in read_frame, every CFA phase, odd borders included."""
    path = write_pidng(tmp_path / "f.dng", _noisy_mosaic((30, 46), 1), pattern=pattern)
    rgb = read_frame(path).astype(np.float64)
    mosaic, levels = read_mosaic(path)
    assert levels["cfa_pattern"] == pattern
    signal, saturated = mosaic_signal(mosaic, pattern=pattern, black=levels["black_sites"],
                                      white=levels["white_sites"])
    assert signal.dtype == np.float32 and not saturated.any()
    # float32 rounding of values up to 3
    np.testing.assert_allclose(signal, rgb.sum(axis=2), rtol=0, atol=3e-7 * 3)
    np.testing.assert_allclose(bilinear_channels(_normalised(mosaic, levels), pattern=pattern), rgb,
                               rtol=0, atol=1e-7)


def test_signal_of_the_independent_renderers_dng(shared_data):
    path = shared_data / "lab-dev" / "dev_spheres_raw" / "frames_u" / "000000.dng"
    mosaic, levels = read_mosaic(path)
    signal, _ = mosaic_signal(mosaic, pattern=levels["cfa_pattern"], black=levels["black_sites"],
                              white=levels["white_sites"])
    np.testing.assert_allclose(signal, read_frame(path).sum(axis=2), rtol=0, atol=1e-6)


@pytest.mark.parametrize("pattern", ["RGGB", "GRBG"])
def test_a_clipped_site_flags_exactly_the_pixels_interpolated_from_it(pattern):
    mosaic = np.full((8, 10), 1000, np.uint16)
    mosaic[4, 5] = 4095
    _, saturated = mosaic_signal(mosaic, pattern=pattern, black=np.full((2, 2), 256), white=np.full((2, 2), 4095))
    green = site_constants(np.array([ch == "G" for ch in pattern]).reshape(2, 2), mosaic.shape) > 0
    rows, cols = np.indices(mosaic.shape)
    dr, dc = np.abs(rows - 4), np.abs(cols - 5)
    # a green site reads its 4 edge neighbours, a red or blue site all 8
    expected = (dr <= 1) & (dc <= 1) & ~(green & (dr == 1) & (dc == 1))
    np.testing.assert_array_equal(saturated, expected)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="pattern"):
        mosaic_signal(np.zeros((4, 4), np.uint16), pattern="RGBX", black=np.zeros((2, 2)), white=np.ones((2, 2)))
    with pytest.raises(ValueError, match="white"):
        mosaic_signal(np.zeros((4, 4), np.uint16), pattern="RGGB", black=np.ones((2, 2)), white=np.ones((2, 2)))
    with pytest.raises(ValueError, match="mosaic"):
        mosaic_signal(np.zeros((4, 4), np.float32), pattern="RGGB", black=np.zeros((2, 2)), white=np.ones((2, 2)))


def test_tracking_dng_files_from_the_mosaic_keeps_the_colour_sums(tmp_path, write_pidng):
    """Per-channel sums of a RAW sweep equal the sums of its demosaiced frames."""
    paths = [write_pidng(tmp_path / f"f{k:02d}.dng", _noisy_mosaic((24, 32), k), pattern="BGGR") for k in range(12)]
    summary = track_files(paths, workers=2, block_frames=5)
    frames = np.stack([read_frame(p) for p in paths]).astype(np.float64)
    np.testing.assert_allclose(summary.channel_sum, frames.sum(axis=0), rtol=0, atol=1e-6)
    np.testing.assert_allclose(summary.mean_level, frames.sum(axis=3).mean(axis=0), rtol=0, atol=1e-6)
    assert not summary.saturated.any()


def test_site_sums_accumulate_the_mosaic_exactly():
    frames = [_noisy_mosaic((10, 14), k) for k in range(3)]
    site_sum = np.zeros((10, 14), np.int64)
    for mosaic in frames:
        mosaic_signal(mosaic, pattern="RGGB", black=np.full((2, 2), 256), white=np.full((2, 2), 4095),
                      site_sum=site_sum)
    np.testing.assert_array_equal(site_sum, np.sum(frames, axis=0, dtype=np.int64))
    with pytest.raises(ValueError, match="site_sum"):
        mosaic_signal(frames[0], pattern="RGGB", black=np.zeros((2, 2)), white=np.full((2, 2), 4095),
                      site_sum=np.zeros((10, 14), np.int32))


def test_colour_sums_follow_each_frames_own_levels(tmp_path, write_pidng):
    """A camera may write another black level for some frames (rawpy reads those)."""
    paths = [write_pidng(tmp_path / f"f{k:02d}.dng", _noisy_mosaic((24, 32), k, black=black), black=black)
             for k, black in enumerate([256, 256, 300, 256, 300, 256, 256, 256, 256, 300, 256, 256, 256, 256])]
    summary = track_files(paths, workers=2, block_frames=4)
    frames = np.stack([read_frame(p) for p in paths]).astype(np.float64)
    np.testing.assert_allclose(summary.channel_sum, frames.sum(axis=0), rtol=0, atol=1e-6)
    # the sums are exact: the chunking does not change a bit
    np.testing.assert_array_equal(track_files(paths, workers=1).channel_sum, summary.channel_sum)
