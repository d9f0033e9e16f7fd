"""Real-size outdoor sample: the source shake is undone, the sample's own shake is applied as recorded.

* Steadying a frame shaken by a known offset (the renderer's cubic spline) gives the unshaken
  frame back (interior, to the spline's round-trip error).
* The sample shake is seeded, within its bound and on OpenCV's 1/32 px grid.
* A real-size mosaic made with a shake ``(dx, dy)`` shows the content moved by exactly that
  much: registration of two noisy mosaics recovers the difference of their shakes.
"""

import cv2
import numpy as np
import pytest

from shadowcam.synthetic.outdoor.nuisance import apply_shake
from shadowcam.synthetic.outdoor.sample import SHAKE_STEP_PX, sample_mosaic, sample_shake, steady_frame
from shadowcam.outdoor.registration import shift_lucas_kanade_LucasKanade1981
from shadowcam.synthetic.sensor import SensorModel


def _scene(shape=(48, 64), seed=0):
    rng = np.random.default_rng(seed)
    grey = cv2.GaussianBlur(rng.random(shape).astype(np.float32), (0, 0), 1.2)
    grey = 0.2 + 0.6 * (grey - grey.min()) / np.ptp(grey)
    return np.stack([grey, 0.9 * grey, 0.7 * grey], axis=-1)


def test_steady_frame_undoes_the_recorded_shake():
    image = _scene()
    shaken = apply_shake(image, 0.63, -0.41)
    assert np.abs(shaken - image)[4:-4, 4:-4].max() > 0.05  # the shake is visible
    steady = steady_frame(shaken, dx=0.63, dy=-0.41)
    np.testing.assert_allclose(steady[4:-4, 4:-4], image[4:-4, 4:-4], atol=0.01)
    with pytest.raises(ValueError, match="image"):
        steady_frame(image[..., 0], dx=0, dy=0)


def test_sample_shake_is_seeded_bounded_and_on_the_warp_grid():
    dx, dy = sample_shake(200, seed=3, max_px=2.0)
    again = sample_shake(200, seed=3, max_px=2.0)
    np.testing.assert_array_equal(dx, again[0])
    assert np.hypot(dx, dy).max() <= 2.0 + SHAKE_STEP_PX  # bound, up to the grid rounding
    assert np.hypot(dx, dy).max() > 1.0 and np.sqrt(np.mean(dx**2 + dy**2)) < 1.0  # sub-pixel, gusts to 2 px
    np.testing.assert_array_equal(np.round(dx / SHAKE_STEP_PX) * SHAKE_STEP_PX, dx)
    assert not np.array_equal(dx, sample_shake(200, seed=4)[0])


def test_mosaic_content_moves_by_the_recorded_shake():
    image = _scene((120, 160), seed=1)  # colour = grey x (1, 0.9, 0.7)
    sensor = SensorModel(bit_depth=14, black_level=512, gain=1.0, read_noise=3.0)
    size = dict(rows=480, cols=640, sensor=sensor, scale=20000.0)
    shakes = [(0.0, 0.0), (1.25, -0.6875)]  # (dx, dy), pixels of the sample
    mosaics = [sample_mosaic(image, seed=[0, k], shake=s, **size) for k, s in enumerate(shakes)]
    # dividing each RGGB site by its channel's colour gives the grey scene at full resolution
    colour = np.array([[1.0, 0.9], [0.9, 0.7]], np.float32)
    greys = [(m.astype(np.float32) - sensor.black_level) / np.tile(colour, (240, 320)) for m in mosaics]
    estimate, _ = shift_lucas_kanade_LucasKanade1981(greys[1], greys[0])
    true = np.array([shakes[1][1] - shakes[0][1], shakes[1][0] - shakes[0][0]])  # (row, col)
    np.testing.assert_allclose(estimate, true, atol=0.02)  # pixels of the sample


def test_write_sample_writes_checksummed_frames_with_the_recorded_shake(tmp_path):
    import json
    from pathlib import Path

    import yaml

    from shadowcam.io.manifest import load_manifest
    from shadowcam.io.provenance import file_sha256
    from shadowcam.synthetic.outdoor.sample import write_sample

    source_path = Path(__file__).resolve().parents[2] / "data_manifest" / "dev_ridge.yaml"
    try:
        source = load_manifest(source_path)
    except (FileNotFoundError, ValueError) as exc:
        pytest.skip(f"dev_ridge not available: {exc}")
    manifest = write_sample(source, tmp_path / "sample", tmp_path / "m.yaml", name="tiny", size="96x64",
                            frames=3, first=10, seed=2, shake_px=1.5)
    assert yaml.safe_load((tmp_path / "m.yaml").read_text()) == manifest
    assert sorted(p.name for p in (tmp_path / "sample" / "frames").iterdir()) == [
        "000000.dng", "000001.dng", "000002.dng"]
    sidecar = json.loads((tmp_path / "sample" / "timestamps.json").read_text())
    assert sidecar["times_s"][0] == 0 and np.all(np.diff(sidecar["times_s"]) > 0)
    assert max(np.abs(sidecar["shake_dx_px"]).max(), np.abs(sidecar["shake_dy_px"]).max()) <= 1.5 + 1e-9
    for rel, digest in manifest["checksums"].items():
        assert file_sha256(tmp_path / "sample" / rel) == digest, rel
    # frames are lossless JPEG as cameras write them: the same mosaics as uncompressed DNGs, smaller files
    from shadowcam.io.raw_mosaic import read_mosaic

    write_sample(source, tmp_path / "plain", tmp_path / "p.yaml", name="plain", size="96x64",
                 frames=3, first=10, seed=2, shake_px=1.5, compression="none")
    for name in ("000000.dng", "000002.dng"):
        packed, plain = tmp_path / "sample" / "frames" / name, tmp_path / "plain" / "frames" / name
        np.testing.assert_array_equal(read_mosaic(packed)[0], read_mosaic(plain)[0])
        assert packed.stat().st_size < plain.stat().st_size
    with pytest.raises(ValueError, match="at least 3"):
        write_sample(source, tmp_path / "x", tmp_path / "x.yaml", name="x", size="96x64", frames=2)
