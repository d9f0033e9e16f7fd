"""Tests of shadowcam.synthetic.capture_options: defaults < manifest < explicit options."""

import pytest
import yaml

from shadowcam.synthetic.capture_options import DEFAULTS, capture_options, outdoor_options


def _manifest(tmp_path, document):
    path = tmp_path / "m.yaml"
    path.write_text(yaml.safe_dump(document))
    return path


def test_manifest_overrides_defaults_and_flags_override_manifest(tmp_path):
    path = _manifest(tmp_path, {"name": "demo", "light": "area",
                                "synthetic": {"scene": "tabletop", "seed": 4, "frames": 32, "light": "point"}})
    options = capture_options(path, frames=16, height=None)
    assert options["seed"] == 4 and options["frames"] == 16 and options["height"] == DEFAULTS["height"]
    assert options["light"] == "area"  # the top-level manifest key wins over the block's
    assert options["name"] == "demo" and options["kind"] == "lab"


def test_outdoor_scene_and_name_defaults():
    options = capture_options(scene="ridge", seed=2)
    assert options["kind"] == "outdoor" and options["name"] == "synthetic_ridge_2"
    assert capture_options(scene="ridge", name="x")["name"] == "x"


def test_invalid_options_name_the_key(tmp_path):
    with pytest.raises(ValueError, match="format"):
        capture_options(format="png")
    with pytest.raises(ValueError, match="bit_depth"):
        capture_options(bit_depth=11)
    with pytest.raises(ValueError, match="height"):
        capture_options(height=10)
    with pytest.raises(ValueError, match="unknown"):
        capture_options(colour=True)
    with pytest.raises(ValueError, match="synthetic"):
        capture_options(_manifest(tmp_path, {"name": "real"}))
    with pytest.raises(FileNotFoundError):
        capture_options(tmp_path / "missing.yaml")
    with pytest.raises(ValueError, match="cloudy"):
        outdoor_options({"cloudy": True})
    assert outdoor_options({"cloud": False})["cloud"] is False


def test_sun_diameter_defaults_to_the_point_sun_and_the_manifest_schema_bounds_it(tmp_path):
    from shadowcam.io.manifest import load_manifest

    assert outdoor_options(None)["sun_diameter_deg"] == 0.0  # existing renders stay as they were
    assert outdoor_options({"sun_diameter_deg": 0.53})["sun_diameter_deg"] == 0.53
    doc = {"name": "r", "kind": "outdoor", "light": "distant",
           "synthetic": {"scene": "ridge", "seed": 0, "height": 32, "width": 48, "frames": 10,
                         "outdoor": {"sun_diameter_deg": 0.53}}}
    assert load_manifest(_manifest(tmp_path, doc))["synthetic"]["outdoor"]["sun_diameter_deg"] == 0.53
    doc["synthetic"]["outdoor"]["sun_diameter_deg"] = 2.0
    with pytest.raises(ValueError, match="sun_diameter_deg"):
        load_manifest(_manifest(tmp_path, doc))


def test_wire_radius_and_area_light_reach_the_scene_description(repo):
    from shadowcam.synthetic.capture_options import capture_options, lab_scene_description

    description = lab_scene_description(capture_options(repo / "data_manifest" / "synthetic_area.yaml"))
    assert description["light"] == "area" and description["wire_radius_frames"] == 4
    assert description["area_light"] == {"shape": "disc", "size": 0.006, "samples": 4}
    plain = lab_scene_description(capture_options(repo / "data_manifest" / "synthetic_tiny.yaml"))
    assert "wire_radius_frames" not in plain and "area_light" not in plain
