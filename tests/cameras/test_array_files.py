"""The virtual camera array from a capture's files: a user's manifest over files the renderer
wrote (frame sweeps, crossing images), against the renderer's ground truth."""

import json
import shutil

import numpy as np
import pytest
import xarray as xr
import yaml

from shadowcam.cameras.array import camera_array, capture_accuracy, estimate_spacing
from shadowcam.cameras.array_files import camera_array_of_plan
from shadowcam.io.capture_plan import capture_plan
from shadowcam.synthetic.capture_options import capture_options
from shadowcam.synthetic.lab.array_capture import render_array_capture, write_array_capture

SPACING = 6.0
SYNTHETIC = {"scene": "tabletop", "seed": 2, "height": 32, "width": 32, "frames": 24, "supersample": 2,
             "format": "tiff", "bit_depth": 16, "noise": False,
             "camera_array": {"rows": 2, "cols": 3, "spacing_frames": SPACING}}


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    """A rendered camera-array capture folder (tiff frames, crossings, capture.json, ground truth)."""
    folder = tmp_path_factory.mktemp("array")
    manifest = folder / "synthetic_array_small.yaml"
    manifest.write_text(yaml.safe_dump({"name": "synthetic_array_small", "kind": "lab", "light": "point",
                                        "synthetic": SYNTHETIC}))
    return write_array_capture(capture_options(manifest), folder / "capture")


def _user_manifest(folder, capture, *, crossings="crossings/*.tiff", **array):
    """A user's manifest over the rendered files (glob crossings, no spacing unless given)."""
    described = json.loads((capture / "capture.json").read_text())
    doc = {"name": "my_array", "kind": "lab", "light": "point", "root": str(capture),
           "sweeps": {"horizontal": {"files": "horizontal/*.tiff"}, "vertical": {"files": "vertical/*.tiff"}},
           "timing": {"source": "rate", "rate_hz": 2.0}, "checksums": described["checksums"],
           "camera_array": {"rows": 2, "cols": 3, "crossings": crossings, **array},
           "ground_truth": {"format": "shadowcam_array_nc", "file": "ground_truth.nc"}}
    path = folder / "my_array.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


@pytest.fixture(scope="module")
def truth(rendered):
    with xr.open_dataset(rendered / "ground_truth.nc") as opened:
        return opened.load()


@pytest.fixture(scope="module")
def user_array(rendered, tmp_path_factory):
    path = _user_manifest(tmp_path_factory.mktemp("user"), rendered)
    return camera_array_of_plan(capture_plan(path))


def test_user_manifest_gives_the_renderers_array_within_the_tolerances(user_array, truth):
    assert user_array["view"].dims == ("camera_row", "camera_col", "v", "u", "channel")
    assert user_array["view"].shape[:2] == (2, 3)
    assert user_array.attrs["spacing_source"] == "estimated"
    # the farthest point's dips bound the spacing from above (gaps are s (1 + g / d) >= s)
    assert np.all((SPACING <= np.array(user_array.attrs["spacing_frames"]))
                  & (np.array(user_array.attrs["spacing_frames"]) <= SPACING * 1.1))
    acc = capture_accuracy(user_array, truth)
    assert np.all(np.array(acc["coordinate_rmse"]) <= 0.3)      # dual px per camera
    assert max(acc["u_rmse_per_column"] + acc["v_rmse_per_row"]) <= 0.3  # rectified
    assert acc["disparity_rmse"] <= 0.3                          # s (1 + g / d)
    assert np.all(np.array(acc["coverage"]) > 0.75)
    assert np.all(np.array(acc["view_rmse"]) < 0.3)


def test_files_and_the_in_memory_render_give_the_same_wire_times(user_array, truth):
    capture = render_array_capture(SYNTHETIC)
    direct = camera_array(capture["frames_horizontal"].values, capture["frames_vertical"].values,
                          capture["crossing_images"].values, spacing_frames=SPACING)
    for name in ("u", "v"):
        a, b = user_array[name].values, direct[name].values
        both = np.isfinite(a) & np.isfinite(b)
        # 16-bit linear files: the same pixels timed, to a hundredth of a frame
        assert np.mean(np.isfinite(a) != np.isfinite(b)) < 0.01
        assert np.max(np.abs(a[both] - b[both])) < 0.01


def test_the_rendered_capture_json_takes_the_same_path(rendered, user_array):
    plan = capture_plan(rendered / "capture.json")
    assert plan.camera_array["spacing_frames"] == SPACING and plan.stages == ("camera_array",)
    assert [p.rsplit("/", 1)[-1] for p in plan.camera_array["crossings"]] == [
        f"r{i}_c{j}.tiff" for i in range(2) for j in range(3)]
    array = camera_array_of_plan(plan)
    assert array.attrs["spacing_source"] == "manifest"
    assert list(array.attrs["spacing_frames"]) == [SPACING, SPACING]
    # its own spacing or the estimated one: the same wires timed (the estimates bound it closely)
    np.testing.assert_array_equal(array["u"].values, user_array["u"].values)
    np.testing.assert_array_equal(array["view"].values, user_array["view"].values)


def test_a_pattern_orders_the_crossings_by_row_and_column(rendered, tmp_path):
    path = _user_manifest(tmp_path, rendered, crossings="crossings/r{row}_c{col}.tiff", spacing_frames=SPACING)
    plan = capture_plan(path)
    assert plan.camera_array["crossings"][4].endswith("r1_c1.tiff")
    assert plan.camera_array["spacing_frames"] == SPACING
    assert plan.sweep("horizontal").times_s[:2] == (0.0, 0.5)


def test_crossing_images_counted_wrong_name_the_key(rendered, tmp_path):
    path = _user_manifest(tmp_path, rendered, crossings="crossings/r0_*.tiff")
    with pytest.raises(ValueError, match=r"my_array.yaml: key 'camera_array.crossings' gives 3 images.*need 6"):
        capture_plan(path)


def test_a_missing_crossing_image_names_the_file_and_key(rendered, tmp_path):
    path = _user_manifest(tmp_path, rendered, crossings="crossings/r{row}_c{col}.png")
    with pytest.raises(ValueError, match=r"r0_c0.png does not exist \(key camera_array.crossings\)"):
        capture_plan(path)


@pytest.mark.parametrize("key", ["rows", "cols"])
def test_rows_or_cols_below_one_are_refused(rendered, tmp_path, key):
    path = _user_manifest(tmp_path, rendered, **{key: 0})
    message = rf"(?s)my_array.yaml.*key camera_array.{key}: 0 is less than the minimum of 1"
    with pytest.raises(ValueError, match=message):
        capture_plan(path)


def test_a_crossing_image_of_another_size_is_named(rendered, tmp_path):
    capture = tmp_path / "capture"
    shutil.copytree(rendered, capture)
    from shadowcam.io.raw_writer import write_tiff16
    write_tiff16(capture / "crossings" / "r1_c2.tiff", np.zeros((30, 32, 3), np.uint16))
    path = _user_manifest(tmp_path, capture)
    text = yaml.safe_load(path.read_text())
    from shadowcam.io.manifest import checksums_for
    path.write_text(yaml.safe_dump({**text, "checksums": checksums_for(path)}))
    with pytest.raises(ValueError, match=r"camera_array.crossings.*r1_c2.tiff is 30x32.*frame size"):
        capture_plan(path)


def test_an_experiment_missing_is_named(rendered, tmp_path):
    path = _user_manifest(tmp_path, rendered)
    doc = yaml.safe_load(path.read_text())
    del doc["sweeps"]["vertical"]
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ValueError, match=r"key 'sweeps' has no sweep 'vertical'"):
        capture_plan(path)


def _dips(n_frames, centres, *, width=1.2, depth=0.8):
    """Box shadows sampled per frame at two pixels (centres per pixel)."""
    k = np.arange(n_frames, dtype=np.float64)[:, None]
    centres = np.asarray(centres, np.float64)  # (wires, pixels)
    signal = np.ones((n_frames, centres.shape[1]))
    for c in centres:
        signal -= depth * np.clip(np.minimum(k + 0.5, c + width / 2) - np.maximum(k - 0.5, c - width / 2), 0, 1)
    return signal[:, None, :].astype(np.float32)


def test_spacing_is_the_smallest_even_gap():
    # two pixels, gaps 7.0 and 9.5 frames (points at two depths): the spacing is at most 7
    frames = _dips(40, [[5.0, 4.0], [12.0, 13.5], [19.0, 23.0]])
    assert estimate_spacing(frames, 3) == pytest.approx(7.0, abs=0.15)
    with pytest.raises(ValueError, match="n_wires"):
        estimate_spacing(frames, 1)
    with pytest.raises(ValueError, match="spacing_frames"):
        estimate_spacing(np.ones((40, 1, 2), np.float32), 3)


def test_noisy_raw_capture_meets_the_tolerances(tmp_path):
    # the 48 x 48 capture as 12-bit RGGB DNGs with shot and read noise, decoded as
    # the lab sweeps are, its spacing estimated
    manifest = tmp_path / "noisy_array.yaml"
    synthetic = {**SYNTHETIC, "height": 48, "width": 48, "format": "dng", "bit_depth": 12, "noise": True}
    manifest.write_text(yaml.safe_dump({"name": "noisy_array", "kind": "lab", "light": "point",
                                        "synthetic": synthetic}))
    capture = write_array_capture(capture_options(manifest), tmp_path / "capture")
    described = json.loads((capture / "capture.json").read_text())
    assert described["camera_array"]["crossings"] == "crossings/r{row}_c{col}.dng"
    del described["camera_array"]["spacing_frames"]
    (capture / "capture.json").write_text(json.dumps(described))
    array = camera_array_of_plan(capture_plan(capture / "capture.json"))
    spacing = np.array(array.attrs["spacing_frames"])
    assert np.all((SPACING <= spacing) & (spacing <= SPACING * 1.1))
    with xr.open_dataset(capture / "ground_truth.nc") as opened:
        acc = capture_accuracy(array, opened.load())
    assert np.all(np.array(acc["coordinate_rmse"]) <= 0.3)
    assert max(acc["u_rmse_per_column"] + acc["v_rmse_per_row"]) <= 0.3
    assert acc["disparity_rmse"] <= 0.3
    assert np.all(np.array(acc["coverage"]) > 0.75)


def test_an_experiment_of_another_frame_size_is_named(rendered, tmp_path):
    from shadowcam.io.manifest import checksums_for
    from shadowcam.io.raw_writer import write_tiff16

    capture = tmp_path / "capture"
    shutil.copytree(rendered, capture)
    for frame in sorted((capture / "vertical").glob("*.tiff")):
        write_tiff16(frame, np.zeros((32, 30, 3), np.uint16))
    path = _user_manifest(tmp_path, capture)
    path.write_text(yaml.safe_dump({**yaml.safe_load(path.read_text()), "checksums": checksums_for(path)}))
    with pytest.raises(ValueError, match=r"(?s)my_array.yaml.*vertical/000000.tiff is 32x30.*frame size"):
        capture_plan(path)


def test_a_rendered_manifest_is_not_read_as_files(tmp_path):
    manifest = tmp_path / "to_render.yaml"
    manifest.write_text(yaml.safe_dump({"name": "to_render", "kind": "lab", "light": "point",
                                        "synthetic": SYNTHETIC}))
    with pytest.raises(ValueError, match="to_render.yaml is not a captured camera array.*render-array"):
        camera_array_of_plan(capture_plan(manifest))


def test_one_horizontal_wire_takes_the_vertical_wires_spacing(tmp_path):
    manifest = tmp_path / "row_array.yaml"
    synthetic = {**SYNTHETIC, "camera_array": {"rows": 1, "cols": 3, "spacing_frames": SPACING}}
    manifest.write_text(yaml.safe_dump({"name": "row_array", "kind": "lab", "light": "point",
                                        "synthetic": synthetic}))
    capture = write_array_capture(capture_options(manifest), tmp_path / "capture")
    described = json.loads((capture / "capture.json").read_text())
    del described["camera_array"]["spacing_frames"]
    (capture / "capture.json").write_text(json.dumps(described))
    array = camera_array_of_plan(capture_plan(capture / "capture.json"))
    horizontal, vertical = array.attrs["spacing_frames"]
    assert vertical == horizontal and SPACING <= horizontal <= SPACING * 1.1
    assert array["view"].shape[:2] == (1, 3)
    with xr.open_dataset(capture / "ground_truth.nc") as opened:
        acc = capture_accuracy(array, opened.load())
    assert np.all(np.array(acc["coordinate_rmse"]) <= 0.3)


def test_crossing_images_are_checksummed_like_the_sweeps(rendered, tmp_path):
    path = _user_manifest(tmp_path, rendered)
    doc = yaml.safe_load(path.read_text())
    del doc["checksums"]["crossings/r1_c2.tiff"]
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ValueError, match=r"not listed in checksums: crossings/r1_c2.tiff; run `shadowcam checksum"):
        capture_plan(path)
