"""Tests of shadowcam.io.decode: linear RAW / PNG / TIFF decoding to float32 RGB."""

import json

import numpy as np
import OpenImageIO as oiio
import pytest

from shadowcam.io.cfa import bayer_pattern, demosaic_bilinear, opencv_bayer_code
from shadowcam.io.decode import frame_info, iter_frames, read_frame


PATTERNS = ("RGGB", "BGGR", "GRBG", "GBRG")


# --------------------------------------------------------------------------- helpers


def mosaic_of(rgb, pattern):
    """Bayer mosaic (H, W) of an (H, W, 3) image: each site keeps its own channel."""
    channels = np.array(["RGB".index(c) for c in pattern]).reshape(2, 2)
    rows, cols = np.indices(rgb.shape[:2])
    site_channel = channels[rows % 2, cols % 2]
    return np.take_along_axis(rgb, site_channel[..., None], axis=2)[..., 0], site_channel


# --------------------------------------------------------------------------- Bayer maths


def test_bayer_pattern_from_rawpy_description():
    # the dev DNGs: raw_pattern [[0,1],[3,2]], color_desc RGBG (README 1.2)
    assert bayer_pattern([[0, 1], [3, 2]], b"RGBG") == "RGGB"
    assert bayer_pattern([[2, 3], [1, 0]], b"RGBG") == "BGGR"
    assert bayer_pattern([[3, 2], [0, 1]], "RGBG") == "GBRG"
    with pytest.raises(ValueError, match="2x2"):
        bayer_pattern(np.zeros((6, 6), int), b"RGBG")  # X-Trans
    with pytest.raises(ValueError, match="not a Bayer"):
        bayer_pattern([[0, 1], [1, 1]], b"RGBG")


@pytest.mark.parametrize("pattern", PATTERNS)
def test_opencv_code_demosaics_synthetic_mosaic_to_right_channels(pattern):
    """A smooth colour image -> mosaic -> demosaic gives it back (no R/B swap).

    Each channel is a different affine function of (row, col); bilinear
    interpolation reproduces affine functions exactly, so every interior pixel
    of every channel must come back exactly (values are multiples of 1/16 DN).
    """
    rows, cols = np.indices((24, 30), dtype=np.float64)
    rgb = np.stack([400 + 20 * rows + 8 * cols, 1500 + 4 * rows - 10 * cols + 300, 3500 - 30 * rows + 12 * cols], -1)
    mosaic, site_channel = mosaic_of(rgb.astype(np.uint16), pattern)
    out = demosaic_bilinear(mosaic, pattern=pattern, max_value=4095)
    assert out.dtype == np.float32 and out.shape == (24, 30, 3)
    np.testing.assert_array_equal(out[2:-2, 2:-2], rgb[2:-2, 2:-2])
    # own channel at every CFA site (borders included) is the raw value exactly
    own = np.take_along_axis(out, site_channel[..., None], axis=2)[..., 0]
    np.testing.assert_array_equal(own, mosaic)
    # constant colour: exact everywhere, borders included (mirror padding keeps the phase)
    flat, _ = mosaic_of(np.broadcast_to(np.array([700, 2100, 3300], np.uint16), (10, 12, 3)), pattern)
    np.testing.assert_array_equal(demosaic_bilinear(flat, pattern=pattern, max_value=4095), np.broadcast_to([700, 2100, 3300], (10, 12, 3)))


def test_opencv_bayer_code_rejects_unknown_pattern():
    with pytest.raises(ValueError, match="pattern"):
        opencv_bayer_code("RGBG")


def test_demosaic_validates_inputs():
    with pytest.raises(ValueError, match="mosaic"):
        demosaic_bilinear(np.zeros((4, 4), np.float32), pattern="RGGB", max_value=1)
    with pytest.raises(ValueError, match="max_value"):
        demosaic_bilinear(np.zeros((4, 4), np.uint16), pattern="RGGB", max_value=70000)


# --------------------------------------------------------------------------- RAW


@pytest.mark.parametrize("pattern", ["RGGB", "GBRG"])
def test_dng_decodes_linearly_exact_at_cfa_sites(tmp_path, pattern, write_pidng):
    rng = np.random.default_rng(11)
    raw = rng.integers(0, 4096, size=(32, 48)).astype(np.uint16)  # includes values below black
    path = write_pidng(tmp_path / "frame.dng", raw, pattern=pattern, exposure=[1, 250], stamp="2024:05:01 18:00:07")
    image, info = read_frame(path, return_info=True)
    assert image.dtype == np.float32 and image.shape == (32, 48, 3)
    _, site_channel = mosaic_of(np.zeros((32, 48, 3)), pattern)
    own = np.take_along_axis(image, site_channel[..., None], axis=2)[..., 0]
    expected = (raw.astype(np.float32) - np.float32(256)) / np.float32(4095 - 256)
    np.testing.assert_array_equal(own, expected)  # exact, negative values kept
    assert info["cfa_pattern"] == pattern
    assert info["black_level"] == [256.0, 256.0, 256.0] and info["white_level"] == 4095.0
    assert info["bit_depth"] == 12
    assert info["white_balance"] == pytest.approx([2.0, 1.0, 4.0])  # reported, not applied
    assert info["exposure_s"] == pytest.approx(1 / 250, rel=1e-6)
    assert info["capture_time"] == "2024-05-01T18:00:07"
    assert frame_info(path) == info


# --------------------------------------------------------------------------- PNG / TIFF


def test_png16_scaled_by_65535_exactly(tmp_path, write_image):
    rng = np.random.default_rng(3)
    pixels = rng.integers(0, 65536, size=(20, 16, 3)).astype(np.uint16)
    path = write_image(tmp_path / "f.png", pixels)
    image = read_frame(path)
    assert image.dtype == np.float32
    np.testing.assert_array_equal(image, pixels.astype(np.float32) / np.float32(65535))
    info = frame_info(path)
    assert (info["height"], info["width"], info["bit_depth"], info["white_level"]) == (20, 16, 16, 65535.0)


def test_grey_8bit_and_float_tiff(tmp_path, write_image):
    grey = np.arange(12, dtype=np.uint8).reshape(3, 4, 1) * 20
    image = read_frame(write_image(tmp_path / "g.png", grey))
    np.testing.assert_array_equal(image, np.repeat(grey / np.float32(255), 3, axis=2).astype(np.float32))
    rgba = np.random.default_rng(4).random((5, 6, 4), dtype=np.float32) * 3  # HDR, above 1 kept
    image = read_frame(write_image(tmp_path / "f.tif", rgba, ExposureTime=0.5))
    np.testing.assert_array_equal(image, rgba[..., :3])
    assert frame_info(tmp_path / "f.tif")["exposure_s"] == 0.5


def test_missing_file_names_it(tmp_path):
    with pytest.raises(ValueError, match="nothere.png"):
        read_frame(tmp_path / "nothere.png")


def test_frames_of_different_size_raise_naming_both(tmp_path, write_image):
    a = write_image(tmp_path / "a.png", np.zeros((8, 8, 3), np.uint16))
    b = write_image(tmp_path / "b.png", np.zeros((8, 10, 3), np.uint16))
    frames = iter_frames([a, a, b])
    next(frames), next(frames)
    with pytest.raises(ValueError, match=r"b\.png.*8x10.*a\.png.*8x8"):
        next(frames)


# --------------------------------------------------------------------------- shared dev data

def _shadow_free(gt):
    """Pixels the wire cannot touch in u frame 0: shadow time > 3 frames away (dip ~2 frames)."""
    return np.abs(gt["t_u_all"]) > 3


def test_shared_png_frame0_matches_reference_linear(shared_data):
    gt = np.load(shared_data / "lab-dev" / "dev_spheres/gt.npz")
    scale = json.loads((shared_data / "lab-dev" / "dev_spheres/meta.json").read_text())["encoding"]["png_scale"]
    image = read_frame(shared_data / "lab-dev" / "dev_spheres/frames_u/000000.png").astype(np.float64)
    mask = _shadow_free(gt)
    assert mask.mean() > 0.9
    # value = round(radiance * png_scale); value/65535 decoded: error <= 0.5 DN
    # plus float32 representation of value/65535 (< 0.005 DN)
    err_dn = np.abs(image * 65535 - gt["reference_linear"].astype(np.float64) * scale)[mask]
    assert err_dn.max() <= 0.505
    # and the reference frame itself everywhere
    ref = read_frame(shared_data / "lab-dev" / "dev_spheres/reference.png").astype(np.float64)
    assert np.abs(ref * 65535 - gt["reference_linear"] * scale).max() <= 0.505


def test_shared_dng_frame0_matches_reference_linear_within_noise(shared_data):
    """Own-channel values follow the README noise model around k_e * radiance."""
    gt = np.load(shared_data / "lab-dev" / "dev_spheres_raw/gt.npz")
    noise = json.loads((shared_data / "lab-dev" / "dev_spheres_raw/meta.json").read_text())["noise_model"]
    image = read_frame(shared_data / "lab-dev" / "dev_spheres_raw/frames_u/000000.dng")
    _, site_channel = mosaic_of(np.zeros((192, 192, 3)), "RGGB")
    own = np.take_along_axis(image, site_channel[..., None], axis=2)[..., 0].astype(np.float64)
    radiance = np.take_along_axis(gt["reference_linear"], site_channel[..., None], axis=2)[..., 0]
    electrons = noise["electrons_per_unit_radiance"] * radiance.astype(np.float64)
    span = noise["white_level"] - noise["black_level"]
    # DN above black = Poisson(e) + N(0, 6^2) + rounding (var 1/12)
    z = (own * span - electrons) / np.sqrt(electrons + noise["read_noise_dn"] ** 2 + 1 / 12)
    z = z[_shadow_free(gt)]
    n = z.size
    assert abs(z.mean()) < 5 / np.sqrt(n)  # unbiased: black 256 subtracted, scale 1/(4095-256)
    assert abs(z.std() - 1) < 5 / np.sqrt(2 * n)
