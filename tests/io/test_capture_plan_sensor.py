"""A lab capture's declared pixel footprint (``sensor.footprint_variance_px2``)."""

import numpy as np
import pytest
import yaml

from shadowcam.io.capture_plan import footprint_variance
from shadowcam.io.manifest import checksums_for, load_manifest


def _manifest(tmp_path, write_image, **extra):
    data = tmp_path / "data"
    for folder, names in (("u", ["a.png", "b.png"]), ("v", ["a.png", "b.png"]), ("", ["ref.png"])):
        for name in names:
            path = data / folder / name
            path.parent.mkdir(parents=True, exist_ok=True)
            write_image(path, np.full((4, 5, 3), 100, np.uint16))
    doc = {"name": "cap", "kind": "lab", "light": "point", "root": "data",
           "sweeps": {"u": {"files": "u/*.png", "axis": "u"}, "v": {"files": "v/*.png", "axis": "v"}},
           "reference": "ref.png", "timing": {"source": "rate", "rate_hz": 1.0}, **extra}
    path = tmp_path / "cap.yaml"
    path.write_text(yaml.safe_dump(doc))
    path.write_text(yaml.safe_dump({**doc, "checksums": checksums_for(path)}))
    return path


def test_declared_footprint_is_read_and_absent_is_none(tmp_path, write_image):
    assert footprint_variance(load_manifest(_manifest(tmp_path, write_image))) is None
    declared = _manifest(tmp_path, write_image, sensor={"footprint_variance_px2": 0.25})
    assert footprint_variance(load_manifest(declared)) == 0.25


def test_negative_footprint_names_the_key(tmp_path, write_image):
    with pytest.raises(ValueError, match="footprint_variance_px2"):
        load_manifest(_manifest(tmp_path, write_image, sensor={"footprint_variance_px2": -1.0}))
    with pytest.raises(ValueError, match="sensor.footprint_variance_px2"):
        footprint_variance({"sensor": {"footprint_variance_px2": float("nan")}})
