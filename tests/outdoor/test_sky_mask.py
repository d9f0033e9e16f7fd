"""Sky masks: automatic (bluish, smooth, from the top border), polygon, mask image."""

import numpy as np
import pytest

from shadowcam.outdoor.sky_mask import auto_sky_mask, mask_from_image, polygon_mask


def test_auto_sky_mask_finds_the_sky_and_not_blue_shadows():
    rng = np.random.default_rng(0)
    height, width = 40, 60
    image = np.empty((height, width, 3), np.float32)
    skyline = 12 + (np.arange(width) // 10)  # a stepped ridge line
    rows = np.arange(height)[:, None]
    sky = rows < skyline[None, :]
    gradient = 0.3 + 0.002 * rows
    image[...] = (np.array([0.25, 0.3, 0.45]) * gradient[..., None] / 0.3)[:, :1, :]
    terrain = (0.5 + 0.2 * rng.random((height, width, 1))) * np.array([0.8, 0.7, 0.5])
    shadow = terrain * 0.1 * np.array([0.6, 0.8, 1.4])  # sky-lit: bluish but dark
    ground = np.where(rows[..., None] > 30, shadow, terrain)
    image = np.where(sky[..., None], image, ground).astype(np.float32)
    found = auto_sky_mask(image)
    assert np.array_equal(found, sky)


def test_polygon_mask_uses_pixel_centres():
    mask = polygon_mask([(0, 0), (0, 4), (2, 4), (2, 0)], (5, 6))
    expected = np.zeros((5, 6), bool)
    expected[:2, :4] = True
    assert np.array_equal(mask, expected)
    with pytest.raises(ValueError, match="polygon"):
        polygon_mask([(0, 0), (1, 1)], (5, 6))


def test_mask_from_image_checks_the_size():
    image = np.zeros((4, 5, 3))
    image[0, 1, 2] = 1
    mask = mask_from_image(image, (4, 5))
    assert mask.sum() == 1 and mask[0, 1]
    with pytest.raises(ValueError, match="size of the frames"):
        mask_from_image(image, (5, 5))
