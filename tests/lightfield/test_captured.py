"""A captured (not rendered) kind: lightfield manifest: its description and HDR merge follow the
manifest's files and facts, and match the renderer's own description of the same frames."""

import hashlib

import numpy as np
import pytest
import yaml

from shadowcam.io.capture_plan import capture_plan
from shadowcam.lightfield.stages import describe_capture, merge_sweep, read_description, sweep_files
from shadowcam.synthetic.lightfield.capture import LightFieldCapture, write_capture


@pytest.fixture(scope="module")
def captured(tmp_path_factory):
    root = tmp_path_factory.mktemp("lf") / "data"
    capture = LightFieldCapture(shape=(32, 32), n_frames=12, quadrature=300, noise=False)
    rendered = write_capture(root, capture)
    screens = rendered["screens"]
    manifest = {
        "name": "captured_lf", "kind": "lightfield", "light": "area", "root": "data",
        "sweeps": {f"{s}_{suffix}": {"files": f"{s}/{axis}/*.dng"}
                   for s in ("screen0", "screen1") for suffix, axis in (("h", "x"), ("v", "y"))},
        "timing": {"source": "rate", "rate_hz": 3.0},
        "checksums": {p.relative_to(root).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
                      for p in root.rglob("*.dng")},
        "lightfield": {
            "screens": [{"id": s["name"], "position_m": s["position_mm"] / 1e3, "homography": s["homography"]}
                        for s in screens],
            "mask": {"position_m": rendered["mask"]["position_mm"] / 1e3,
                     "start_m": rendered["mask"]["start_mm"] / 1e3, "step_m": rendered["mask"]["step_mm"] / 1e3},
            "exposure_times_s": rendered["exposure_times"],
        },
    }
    path = root.parent / "captured_lf.yaml"
    path.write_text(yaml.safe_dump(manifest))
    return root, rendered, capture_plan(path)


def test_description_of_a_captured_light_field_follows_its_manifest(captured):
    root, rendered, plan = captured
    description = describe_capture(plan)
    assert [s["name"] for s in description["screens"]] == ["screen0", "screen1"]
    for mine, truth in zip(description["screens"], rendered["screens"]):
        assert mine["position_mm"] == pytest.approx(truth["position_mm"])
        assert np.allclose(mine["homography"], truth["homography"])
    for key in ("start_mm", "step_mm", "position_mm"):
        assert description["mask"][key] == pytest.approx(rendered["mask"][key])
    assert description["mask"]["n_frames"] == 12 and plan.sweep("screen1_v").n_frames == 12
    assert description["exposure_times"] == pytest.approx(rendered["exposure_times"])
    assert description["sensor"]["black_level"] == rendered["sensor"]["black_level"]
    assert description["sensor"]["white_level"] == rendered["sensor"]["white_level"]
    assert len(sweep_files(root, description, "screen0_h")) == 12 * 3


def test_captured_hdr_merge_equals_the_rendered_one_up_to_the_responsivity(captured, tmp_path):
    root, rendered, plan = captured
    description = describe_capture(plan)
    mine = tmp_path / "captured.npy"
    merge_sweep(sweep_files(root, description, "screen0_h"), mine, exposure_times=description["exposure_times"],
                sensor=description["sensor"])
    theirs = tmp_path / "rendered.npy"
    layout = read_description(root)
    merge_sweep(sweep_files(root, layout, "screen0_h"), theirs, exposure_times=layout["exposure_times"],
                sensor=layout["sensor"])
    a, b = np.load(mine), np.load(theirs) * rendered["sensor"]["responsivity"]  # DN/s vs lux
    lit = np.isfinite(b) & (b > 0.05 * np.nanmax(b))
    assert np.isfinite(a[lit]).all()
    assert np.median(np.abs(a[lit] / b[lit] - 1)) < 1e-3
