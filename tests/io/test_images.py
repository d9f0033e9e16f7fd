"""Tests of shadowcam.io.images: EXR round trip, previews, atomic writes."""

import numpy as np
import pytest

from shadowcam.io.images import (
    HOLE_COLOUR,
    colormap_rgb8,
    white_point,
    preview_rgb8,
    read_image,
    srgb_encode,
    write_exr,
    write_png_preview,
    write_scalar_preview,
)


def test_exr_round_trip_is_exact_and_keeps_nan(tmp_path):
    rng = np.random.default_rng(1)
    img = rng.uniform(0, 3, (7, 9, 3)).astype(np.float32)
    img[2, 3] = np.nan
    write_exr(tmp_path / "a.exr", img)
    back = read_image(tmp_path / "a.exr")
    assert back.shape == img.shape and back.dtype == np.float32
    np.testing.assert_array_equal(back, img)  # NaN positions compare equal too
    assert list(tmp_path.iterdir()) == [tmp_path / "a.exr"]  # no temporary left


def test_srgb_encode_reference_values():
    np.testing.assert_allclose(srgb_encode([0.0, 0.0031308, 0.18, 1.0, 2.0]),
                               [0.0, 0.04045, 0.46135612, 1.0, 1.0], atol=1e-5)


def test_preview_exposure_and_holes(tmp_path):
    img = np.full((20, 20, 3), 0.2, np.float32)
    img[0, 0] = 50.0  # one hot pixel (0.25% of the image) must not set the exposure
    img[5, 5] = np.nan
    assert white_point(img, percentile=99.0) == pytest.approx(0.2)
    out = preview_rgb8(img)
    assert out.dtype == np.uint8 and out.shape == (20, 20, 3)
    assert (out[1, 1] == 255).all()  # the bulk at the percentile maps to white
    assert (out[5, 5] == np.round(np.array(HOLE_COLOUR) * 255)).all()
    half = preview_rgb8(img, scale=0.4)
    assert half[1, 1, 0] == round(255 * float(srgb_encode(0.5)))
    write_png_preview(tmp_path / "p.png", img)
    back = read_image(tmp_path / "p.png")
    np.testing.assert_allclose(back * 255, out, atol=0.01)


def test_colormap_preview_nan_grey(tmp_path):
    t = np.tile(np.linspace(0, 95, 16), (4, 1))
    t[0, 0] = np.nan
    out = colormap_rgb8(t, vmin=0, vmax=95)
    assert (out[0, 0] == 128).all()
    assert not (out[1, 0] == out[1, -1]).all()  # the two ends get different colours
    write_scalar_preview(tmp_path / "t.png", t)
    assert (tmp_path / "t.png").stat().st_size > 0
    with pytest.raises(ValueError, match="values"):
        colormap_rgb8(np.zeros((2, 2, 2)))
