"""Light-field stage front functions: the streamed HDR merge of RAW files, its reason codes,
bracket errors, and rays through saturated pixels; against exact values of the sensor model."""

import numpy as np
import pytest

from shadowcam.io.raw_writer import write_dng
from shadowcam.lightfield import rays
from shadowcam.lightfield.stages import bracket_files, merge_sweep, render_grid

SENSOR = {"black_level": 256, "white_level": 4095, "gain": 1.0, "read_noise": 2.0, "responsivity": 1000.0}
TIMES = (4e-3, 5e-4)
SHAPE = (24, 24)  # LibRaw refuses mosaics narrower than ~22 pixels


def _sweep(folder, irradiance, n_frames):
    """Noise-free DNG brackets of a static scene: DN = black + responsivity * t * E (clipped)."""
    paths = []
    for t in range(n_frames):
        for e, time in enumerate(TIMES):
            dn = np.clip(np.rint(SENSOR["black_level"] + SENSOR["responsivity"] * time * irradiance), 0, 4095)
            path = folder / f"frame{t:04d}_b{e}.dng"
            write_dng(path, dn.astype(np.uint16), bit_depth=12, black_level=256, exposure_time=time)
            paths.append(path)
    return paths


def test_merge_sweep_recovers_irradiance_and_flags_every_bracket_saturated(tmp_path):
    irradiance = np.full(SHAPE, 500.0)
    irradiance[3, 5] = 1.0e4   # 4e-3 s: 40000 e- (saturated); 5e-4 s: 5000 e- (saturated): both brackets
    irradiance[7, 7] = 3.0e3   # long bracket saturated, short one (1500 DN) merges alone
    out = tmp_path / "hdr.npy"
    result = merge_sweep(_sweep(tmp_path, irradiance, 3), out, exposure_times=TIMES, sensor=SENSOR)
    stack = np.load(out)
    assert result == {"n_frames": 3, "all_saturated": 1}
    assert stack.shape == (3,) + SHAPE and stack.dtype == np.float32
    assert np.isnan(stack[:, 3, 5]).all()
    finite = np.isfinite(stack)
    assert finite.sum() == stack.size - 3
    # rounding to whole DN: at most 0.5 DN / (responsivity * t) off
    assert np.allclose(stack[:, 7, 7], 3.0e3, atol=0.5 / (1000.0 * 5e-4))
    assert np.allclose(stack[finite], np.broadcast_to(irradiance, stack.shape)[finite], rtol=1e-3)


def test_brackets_of_different_sizes_are_refused_before_reading(tmp_path):
    paths = [tmp_path / f"f{i}.dng" for i in range(5)]
    with pytest.raises(ValueError, match="brackets of 2 files; got 5 files"):
        next(bracket_files(paths, brackets=2))
    out = tmp_path / "hdr.npy"
    with pytest.raises(ValueError, match="brackets of different sizes"):
        merge_sweep(paths, out, exposure_times=TIMES, sensor=SENSOR)
    assert not out.exists() and list(tmp_path.iterdir()) == []


def _screen(z, irradiance):
    """A screen whose pixel (r, c) sees mask point (c - 4, r - 4) mm, 1 mm pixels magnified with z."""
    r, c = np.mgrid[0:9, 0:9].astype(float)
    mask = np.stack([c - 4, r - 4], -1)
    xy = mask * z / 50.0
    found = {"position": mask[..., 0], "position_std": np.full((9, 9), 0.01), "lit_level": irradiance}
    other = {"position": mask[..., 1], "position_std": np.full((9, 9), 0.01), "lit_level": irradiance}
    return rays.screen_mask_map(found, other, xy=xy, area=np.ones((9, 9)), position_mm=z)


def test_a_pixel_saturated_in_every_bracket_gets_the_saturated_reason_not_a_guessed_flux():
    near_e = np.full((9, 9), 100.0)
    near_e[4, 6] = np.nan  # every bracket saturated in the HDR merge
    ray_set = rays.rays_dataset(_screen(250.0, near_e), _screen(450.0, np.full((9, 9), 30.0)), anchor="near")
    assert ray_set["flag"].values[4, 6] == rays.SATURATED
    assert rays.REASONS[rays.SATURATED] == "saturated"
    assert np.isnan(ray_set["flux"].values[4, 6]) and ray_set["confidence"].values[4, 6] == 0
    ok = ray_set["flag"].values == rays.OK
    assert ok.sum() == 80
    # the rays pass through the source side's mask point: direction = xy / z of the mask point
    d = ray_set["direction"].values
    assert np.allclose(d[ok][:, :2], (ray_set["origin"].values[ok][:, :2] / 250.0), atol=1e-9)


def test_render_grid_magnifies_the_near_pitch_with_distance():
    description = {"screens": [{"position_mm": 250.0, "homography": np.diag([0.0, 0.0, 1.0])
                                + np.array([[0, 2.0, 0], [2.0, 0, 0], [0, 0, 0]])}]}
    shape, pitch = render_grid(description, (96, 96), 500.0, pitch_factor=2.0)
    assert shape == (48, 48) and pitch == pytest.approx(2.0 * 2.0 * 2.0)
    with pytest.raises(ValueError, match="pitch_factor"):
        render_grid(description, (96, 96), 500.0, pitch_factor=0.0)
