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
