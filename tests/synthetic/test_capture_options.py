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
