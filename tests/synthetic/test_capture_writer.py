"""Tests of shadowcam.synthetic.capture_writer: a capture directory like a camera's, checksummed."""

import json

import numpy as np
import pytest

from shadowcam.io.datasets import open_dataset
from shadowcam.io.provenance import file_sha256
from shadowcam.synthetic.capture_options import capture_options
from shadowcam.synthetic.capture_writer import write_capture


def test_lab_capture_directory_lists_every_file_with_its_checksum(tmp_path):
    out = tmp_path / "capture"
    options = capture_options(scene="tabletop", seed=1, height=24, width=24, frames=6, format="tiff",
                              supersample=1, noise=False)
    write_capture(options, out)
    description = json.loads((out / "capture.json").read_text())
    assert description["kind"] == "lab" and set(description["sweeps"]) == {"u", "v"}
    assert len(list((out / "frames_u").glob("*.tiff"))) == 6
    for rel, digest in description["checksums"].items():
        assert file_sha256(out / rel) == digest, rel
    truth = open_dataset(out / "ground_truth.nc")
    assert truth.attrs["step"] == "render" and truth.attrs["frame_format"] == "tiff"
    assert set(json.loads(truth.attrs["input_checksums"])) == set(description["checksums"]) - {"ground_truth.nc"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["capture"]


def test_a_failed_render_keeps_the_old_capture(tmp_path):
    out = tmp_path / "capture"
    out.mkdir()
    (out / "old.txt").write_text("old")
    options = capture_options(scene="tabletop", height=24, width=24, frames=4, format="tiff")
    options["scene"] = "no-such-scene"
    with pytest.raises((ValueError, KeyError)):
        write_capture(options, out)
    assert sorted(p.name for p in out.iterdir()) == ["old.txt"]
    with pytest.raises(ValueError, match="kind"):
        write_capture(dict(options, kind="indoor"), out)
    assert np.all([p.name == "capture" for p in tmp_path.iterdir()])


def _camera_options(tmp_path, camera, *, light="point", frames=12):
    import yaml

    path = tmp_path / "cam.yaml"
    path.write_text(yaml.safe_dump({
        "name": "cam", "kind": "lab", "light": light,
        "synthetic": {"scene": "tabletop", "seed": 0, "height": 24, "width": 24, "frames": frames,
                      "format": "tiff", "noise": False, "supersample": 1, "camera": camera}}))
    return path, capture_options(path)


def test_camera_block_renders_the_planned_sweeps_with_their_geometry(tmp_path):
    """Slanted, slow sweeps: frame counts as planned, times affine in (t_u, t_v) as declared."""
    from shadowcam.cameras.models import estimate_sweep
    from shadowcam.io.capture_plan import capture_plan

    camera = {"sweeps": [{"name": "u"}, {"name": "v", "direction_deg": 90, "speed": 0.5},
                         {"name": "s", "direction_deg": 60}]}
    manifest, options = _camera_options(tmp_path, camera)
    out = write_capture(options, tmp_path / "capture")
    planned = capture_plan(manifest)
    rendered = capture_plan(out / "capture.json")
    assert planned.camera_model == rendered.camera_model == "linear"
    for name in ("u", "v", "s"):
        assert rendered.n_frames(name) == planned.n_frames(name), name
        assert len(list((out / ("s" if name == "s" else f"frames_{name}")).glob("*.tiff"))) == \
            planned.n_frames(name)
    assert (rendered.sweep("s").direction_deg, rendered.sweep("v").speed) == (60.0, 0.5)
    truth = open_dataset(out / "ground_truth.nc")
    t = {n: truth[f"t_{n}"].values.astype(float) for n in ("u", "v", "s")}
    # t_v counts frames at half speed: dual v = 0.5 t_v; the s sweep is at 60 deg, unit speed
    fit = estimate_sweep(t["s"], t["u"], 0.5 * (t["v"] - (planned.n_frames("v") - 1) / 2)
                         + (12 - 1) / 2)
    assert fit["angle_deg"] == pytest.approx(60.0, abs=1e-3)
    assert fit["speed"] == pytest.approx(1.0, rel=1e-4)
    assert json.loads(truth.attrs["config"])["camera"] == camera


def test_cross_slit_camera_writes_each_sweeps_light(tmp_path):
    from shadowcam.io.capture_plan import capture_plan
    from shadowcam.synthetic.lab.scenes import make_scene

    camera = {"model": "cross_slit",
              "sweeps": [{"name": "u"}, {"name": "v", "direction_deg": 90,
                                         "light_offset": [0.0, 0.01, 0.0]}]}
    _, options = _camera_options(tmp_path, camera)
    out = write_capture(options, tmp_path / "capture")
    description = json.loads((out / "capture.json").read_text())
    scene = make_scene("tabletop", seed=0, height=24, width=24, frames=12)
    lights = {n: np.array(description["sweeps"][n]["light_position"]) for n in ("u", "v")}
    np.testing.assert_allclose(lights["u"], scene.light.position, atol=1e-12)
    np.testing.assert_allclose(lights["v"], scene.light.position + 0.01 * scene.mask.e_v, atol=1e-12)
    assert capture_plan(out / "capture.json").camera_model == "cross_slit"
    assert "lit_v" in open_dataset(out / "ground_truth.nc")


def test_a_light_on_the_wire_path_names_the_key_and_writes_nothing(tmp_path):
    from shadowcam.synthetic.lab.scenes import make_scene

    scene = make_scene("tabletop", seed=0, height=24, width=24, frames=12)
    height = float((scene.mask.origin - scene.light.position) @ scene.mask.normal)
    camera = {"sweeps": [{"name": "u"}, {"name": "v", "direction_deg": 90,
                                         "light_offset": [0.0, 0.0, height]}]}
    _, options = _camera_options(tmp_path, camera)
    with pytest.raises(ValueError, match=r"capture 'cam': key 'synthetic.camera': sweeps\[1\] "
                                         r"\('v'\).light: lies \(nearly\) in the plane"):
        write_capture(options, tmp_path / "capture")
    assert not (tmp_path / "capture").exists()


def test_a_lossless_jpeg_frame_holds_the_same_mosaic_as_an_uncompressed_one(tmp_path):
    import datetime

    from shadowcam.io.raw_mosaic import read_mosaic
    from shadowcam.synthetic.capture_writer import write_frame
    from shadowcam.synthetic.sensor import SensorModel

    radiance = np.random.default_rng(1).uniform(0.0, 1.0, (24, 32, 3)).astype(np.float32)
    sensor = SensorModel(bit_depth=14)
    when = datetime.datetime(2026, 1, 15, 16, 0, 0)
    for compression in ("none", "ljpeg"):
        write_frame(tmp_path / f"{compression}.dng", radiance, frame_format="dng", noise=True, sensor=sensor,
                    scale=5000.0, seed=[3, 1, 0], when=when, compression=compression)
    plain, compressed = read_mosaic(tmp_path / "none.dng")[0], read_mosaic(tmp_path / "ljpeg.dng")[0]
    np.testing.assert_array_equal(compressed, plain)
    assert (tmp_path / "ljpeg.dng").stat().st_size < (tmp_path / "none.dng").stat().st_size
