"""Tests of shadowcam.io.sweep_store: a sweep decoded whole or in parts, its files verified."""

import json

import numpy as np
import pytest

from shadowcam.io.frame_store import open_frames
from shadowcam.io.manifest import load_manifest
from shadowcam.io.sweep_store import decode_sweep
from shadowcam.synthetic.capture_options import capture_options
from shadowcam.synthetic.capture_writer import write_capture


@pytest.fixture(scope="module")
def manifest(tmp_path_factory):
    out = tmp_path_factory.mktemp("capture") / "capture"
    write_capture(capture_options(scene="tabletop", seed=2, height=24, width=24, frames=6, format="tiff",
                                  supersample=1, noise=False), out)
    return load_manifest(out / "capture.json")


def test_a_part_checks_and_names_only_its_own_files(manifest, tmp_path):
    decode_sweep(manifest, "u", tmp_path / "u.zarr")
    whole = open_frames(tmp_path / "u.zarr")
    attrs = decode_sweep(manifest, "u", tmp_path / "part.zarr", frames=(2, 4), chunk_frames=2)
    part = open_frames(tmp_path / "part.zarr")
    assert part.sizes["time"] == 2 and whole.sizes["time"] == 6
    np.testing.assert_array_equal(part["image"].values, whole["image"].values[2:4])
    assert sorted(json.loads(attrs["input_checksums"])) == ["frames_u/000002.tiff", "frames_u/000003.tiff"]
    assert attrs["sweep"] == "u" and attrs["step"] == "decode"


def test_reference_and_unknown_sweeps(manifest, tmp_path):
    decode_sweep(manifest, "reference", tmp_path / "reference.zarr")
    assert open_frames(tmp_path / "reference.zarr")["image"].dims == ("row", "col", "channel")
    with pytest.raises(ValueError, match="available"):
        decode_sweep(manifest, "w", tmp_path / "w.zarr")
    with pytest.raises(ValueError, match="reference"):
        decode_sweep(manifest, "reference", tmp_path / "r.zarr", frames=(0, 1))
