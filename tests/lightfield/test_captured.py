"""A captured (not rendered) kind: lightfield manifest: its description and HDR merge follow the
manifest's files and facts, and match the renderer's own description of the same frames."""

from pathlib import Path

import numpy as np
import pytest

from shadowcam.io.capture_plan import capture_plan
from shadowcam.lightfield.stages import describe_capture, merge_sweep, read_description, sweep_files
from shadowcam.synthetic.sensor import SensorModel


@pytest.fixture(scope="module")
def captured(tmp_path_factory, make_lightfield_manifest):
    folder = tmp_path_factory.mktemp("lf")
    path, rendered = make_lightfield_manifest(folder, sensor=SensorModel(bit_depth=12, black_level=256, gain=0.5,
                                                                         read_noise=3.0))
    return folder / "data", rendered, capture_plan(path)


def test_description_of_a_captured_light_field_follows_its_manifest(captured):
    root, rendered, plan = captured
    description = describe_capture(plan)
    assert [s["name"] for s in description["screens"]] == ["near", "far"]
    for mine, truth in zip(description["screens"], rendered["screens"]):
        assert mine["position_mm"] == pytest.approx(truth["position_mm"])
        assert np.allclose(mine["homography"], truth["homography"])
    for key in ("start_mm", "step_mm", "position_mm"):
        assert description["mask"][key] == pytest.approx(rendered["mask"][key])
    assert description["mask"]["n_frames"] == 12 and plan.sweep("far_v").n_frames == 12
    assert description["exposure_times"] == pytest.approx(rendered["exposure_times"])
    assert description["sensor"]["black_level"] == rendered["sensor"]["black_level"]
    assert description["sensor"]["white_level"] == rendered["sensor"]["white_level"]
    # the camera's noise from the manifest's lightfield.camera keys: the merge weights
    assert description["sensor"]["gain"] == 0.5 and description["sensor"]["read_noise"] == 3.0
    assert len(sweep_files(root, description, "near_h")) == 12 * 3


def test_captured_hdr_merge_equals_the_rendered_one_up_to_the_responsivity(captured, tmp_path):
    root, rendered, plan = captured
    description = describe_capture(plan)
    mine = tmp_path / "captured.npy"
    merge_sweep(sweep_files(root, description, "near_h"), mine, exposure_times=description["exposure_times"],
                sensor=description["sensor"])
    theirs = tmp_path / "rendered.npy"
    layout = read_description(root)
    merge_sweep(sweep_files(root, layout, "near_h"), theirs, exposure_times=layout["exposure_times"],
                sensor=layout["sensor"])
    a, b = np.load(mine), np.load(theirs) * rendered["sensor"]["responsivity"]  # DN/s vs lux
    lit = np.isfinite(b) & (b > 0.05 * np.nanmax(b))
    assert np.isfinite(a[lit]).all()
    assert np.median(np.abs(a[lit] / b[lit] - 1)) < 1e-3


def test_rendered_light_field_is_exposed_with_the_manifests_camera_noise(tmp_path):
    import yaml

    from shadowcam.io.manifest import load_manifest
    from shadowcam.synthetic.lightfield.capture import capture_from_plan

    repo = Path(__file__).resolve().parents[2]
    manifest = yaml.safe_load((repo / "data_manifest" / "synthetic_lightfield.yaml").read_text())
    manifest["lightfield"]["camera"] = {"gain_dn_per_e": 0.25, "read_noise_dn": 7.5}
    path = tmp_path / "lf.yaml"
    path.write_text(yaml.safe_dump(manifest))
    capture = capture_from_plan(capture_plan(path), load_manifest(path)["synthetic"])
    assert (capture.sensor.gain, capture.sensor.read_noise) == (0.25, 7.5)
    del manifest["lightfield"]["camera"]
    path.write_text(yaml.safe_dump(manifest))
    plain = capture_from_plan(capture_plan(path), load_manifest(path)["synthetic"])
    assert plain.sensor == capture.__class__().sensor  # the renderer's default camera
