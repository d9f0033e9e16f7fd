"""Tests of shadowcam.io.manifest: validation, file resolution, timing, checksums, CLI."""

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from shadowcam.cli import main
from shadowcam.io.manifest import (
    checksums_for,
    format_checksums,
    load_manifest,
    manifest_files,
    natural_key,
    verify_checksums,
)

REPO = Path(__file__).resolve().parents[2]


def test_natural_key_orders_numbers():
    assert sorted(["f10.png", "f2.png", "f1.png"], key=natural_key) == ["f1.png", "f2.png", "f10.png"]


def test_load_resolves_root_paths_times(tmp_path, make_capture):
    path, _ = make_capture(tmp_path)
    manifest = load_manifest(path)
    root = (tmp_path / "data").resolve()
    assert manifest["root"] == str(root)
    assert manifest["sweeps"]["u"]["paths"] == [str(root / "u" / n) for n in ("f8.png", "f9.png", "f10.png")]
    assert manifest["sweeps"]["u"]["times_s"] == [0.0, 0.5, 1.0]  # 2 Hz
    assert manifest["reference_paths"] == [str(root / "ref.png")]
    assert set(manifest_files(manifest)) == {"u/f8.png", "u/f9.png", "u/f10.png", "ref.png"}
    assert len(verify_checksums(manifest)) == 4


def test_json_manifest_loads(tmp_path, make_capture):
    path, doc = make_capture(tmp_path)
    json_path = path.with_suffix(".json")
    json_path.write_text(json.dumps(doc))
    assert load_manifest(json_path)["sweeps"]["u"]["times_s"] == [0.0, 0.5, 1.0]


def test_synthetic_manifest_validates(tmp_path, rewrite):
    doc = {
        "name": "syn", "kind": "lab", "light": "point",
        "synthetic": {"scene": "tabletop", "seed": 1, "height": 64, "width": 64, "frames": 32,
                      "format": "dng", "bit_depth": 12, "noise": True, "calibration": False},
        "dual": {"width": 32, "height": 32},
    }
    manifest = load_manifest(rewrite(tmp_path / "syn.yaml", doc))
    assert manifest["sweeps"] == {} and manifest["synthetic"]["seed"] == 1


def test_extra_key_is_named(tmp_path, make_capture, rewrite):
    path, doc = make_capture(tmp_path)
    doc["sweeps"]["u"]["fles"] = "x"
    doc["colour"] = "red"
    with pytest.raises(ValueError) as info:
        load_manifest(rewrite(path, doc))
    assert "'fles' was unexpected" in str(info.value) and "'colour' was unexpected" in str(info.value)
    assert "sweeps.u" in str(info.value) and str(path) in str(info.value)


@pytest.mark.parametrize("timing, expected", [
    ({"source": "rate", "rate_hz": "fast"}, "key timing.rate_hz: 'fast' is not of type 'number'"),
    ({"source": "filename", "regex": 3}, "key timing.regex: 3 is not of type 'string'"),
    ({"source": "sidecar", "file": "t.json"}, "key timing: 'key' is a required property"),
    ({"source": "clock"}, "key timing.source: 'clock' is not one of ['rate', 'filename', 'metadata', 'auto', 'sidecar']"),
])
def test_wrong_timing_names_the_key_of_its_source(tmp_path, make_capture, rewrite, timing, expected):
    path, doc = make_capture(tmp_path)
    doc["timing"] = timing
    with pytest.raises(ValueError) as info:
        load_manifest(rewrite(path, doc))
    assert str(info.value).splitlines()[1:-1] == [f"  {expected}"], str(info.value)


def test_missing_root_named(tmp_path, make_capture, rewrite):
    path, doc = make_capture(tmp_path)
    doc["root"] = "../nowhere"
    with pytest.raises(ValueError, match="nowhere.*not a folder"):
        load_manifest(rewrite(path, doc))


def test_glob_matching_nothing_named(tmp_path, make_capture, rewrite):
    path, doc = make_capture(tmp_path)
    doc["sweeps"]["v"] = {"files": "v/*.dng"}
    with pytest.raises(ValueError, match=r"sweeps\.v\.files 'v/\*\.dng' matches no file"):
        load_manifest(rewrite(path, doc))


def test_missing_reference_file_named(tmp_path, make_capture):
    path, _ = make_capture(tmp_path)
    (tmp_path / "data" / "ref.png").unlink()
    with pytest.raises(ValueError, match="ref.png"):
        load_manifest(path)


def test_file_not_in_checksums_named(tmp_path, make_capture, rewrite):
    path, doc = make_capture(tmp_path)
    del doc["checksums"]["u/f9.png"]
    with pytest.raises(ValueError, match=r"not listed in checksums: u/f9\.png.*shadowcam checksum"):
        load_manifest(rewrite(path, doc))


def test_bad_checksum_names_file_expected_actual(tmp_path, make_capture):
    path, doc = make_capture(tmp_path)
    manifest = load_manifest(path)
    target = tmp_path / "data" / "u" / "f10.png"
    target.write_bytes(target.read_bytes() + b"\0")
    with pytest.raises(ValueError) as info:
        verify_checksums(manifest, ["u"])
    message = str(info.value)
    assert "f10.png" in message and doc["checksums"]["u/f10.png"] in message
    from shadowcam.io.provenance import file_sha256

    assert file_sha256(target) in message
    # the reference group is still fine
    assert list(verify_checksums(manifest, ["reference"])) == ["ref.png"]


def test_file_removed_after_load_named(tmp_path, make_capture):
    path, _ = make_capture(tmp_path)
    manifest = load_manifest(path)
    (tmp_path / "data" / "u" / "f8.png").unlink()
    with pytest.raises(ValueError, match=r"f8\.png.*does not exist"):
        verify_checksums(manifest)


def test_timing_from_filename(tmp_path, make_capture, rewrite):
    path, _ = make_capture(
        tmp_path, names=("img_0.000s.png", "img_0.250s.png", "img_1.500s.png"),
        timing={"source": "filename", "regex": r"_(?P<time_s>\d+\.\d+)s"},
    )
    assert load_manifest(path)["sweeps"]["u"]["times_s"] == [0.0, 0.25, 1.5]
    path, doc = make_capture(tmp_path / "b", timing={"source": "filename", "regex": r"f(?P<index>\d+)", "rate_hz": 4.0})
    assert load_manifest(path)["sweeps"]["u"]["times_s"] == [2.0, 2.25, 2.5]
    doc["timing"]["regex"] = r"g(?P<index>\d+)"
    with pytest.raises(ValueError, match="f8.png.*does not match timing.regex"):
        load_manifest(rewrite(path, doc))


def test_timing_from_exif_metadata_with_subseconds(tmp_path, write_image, rewrite):
    data = tmp_path / "data" / "u"
    data.mkdir(parents=True)
    stamps = [("2024:05:01 18:59:59", "500"), ("2024:05:01 19:00:00", "750"), ("2024:05:01 19:00:02", "")]
    for k, (stamp, sub) in enumerate(stamps):
        write_image(data / f"{k}.tif", np.zeros((4, 4, 3), np.uint16),
                    **{"Exif:DateTimeOriginal": stamp, "Exif:SubsecTimeOriginal": sub})
    doc = {"name": "m", "kind": "outdoor", "light": "distant", "root": "data",
           "sweeps": {"t": {"files": "u/*.tif"}}, "timing": {"source": "metadata"}}
    path = rewrite(tmp_path / "m.yaml", doc)
    doc["checksums"] = checksums_for(path)
    times = load_manifest(rewrite(path, doc))["sweeps"]["t"]["times_s"]
    np.testing.assert_allclose(times, [0.0, 1.25, 2.5], atol=1e-6)


def test_timing_from_sidecar(tmp_path, make_capture, rewrite):
    path, doc = make_capture(tmp_path, with_checksums=False)
    side = tmp_path / "data" / "stamps.json"
    side.write_text(json.dumps({"times_s": {"u": [0.0, 0.9, 2.1]}}))
    doc["timing"] = {"source": "sidecar", "file": "stamps.json", "key": "times_s"}
    rewrite(path, doc)
    doc["checksums"] = checksums_for(path)
    assert "stamps.json" in doc["checksums"]  # the sidecar is a referenced file too
    assert load_manifest(rewrite(path, doc))["sweeps"]["u"]["times_s"] == [0.0, 0.9, 2.1]
    side.write_text(json.dumps({"times_s": {"u/f8.png": 1.0, "f9.png": 2.0, "u/f10.png": 3.0}}))
    doc["checksums"] = checksums_for(path)
    assert load_manifest(rewrite(path, doc))["sweeps"]["u"]["times_s"] == [1.0, 2.0, 3.0]
    side.write_text(json.dumps({"times_s": [0.0, 1.0]}))
    doc["checksums"] = checksums_for(path)
    with pytest.raises(ValueError, match="2 times for sweep 'u' but it has 3 files"):
        load_manifest(rewrite(path, doc))


def test_checksum_cli_block_pastes_into_manifest(tmp_path, capsys, make_capture):
    path, doc = make_capture(tmp_path, with_checksums=False)
    with pytest.raises(ValueError, match="not listed in checksums"):
        load_manifest(path)
    assert main(["checksum", "--manifest", str(path)]) == 0
    block = capsys.readouterr().out
    assert block.startswith("checksums:\n")
    path.write_text(path.read_text() + block)
    manifest = load_manifest(path)
    assert len(verify_checksums(manifest)) == 4
    assert yaml.safe_load(format_checksums(manifest["checksums"])) == {"checksums": manifest["checksums"]}


@pytest.mark.usefixtures("shared_data")  # the repository manifest reads the shared dev data
@pytest.mark.parametrize("name, suffix", [("dev_spheres", ".png"), ("dev_spheres_raw", ".dng")])
def test_shared_dev_manifests(name, suffix):
    manifest = load_manifest(REPO / "data_manifest" / f"{name}.yaml")
    assert manifest["name"] == name
    for sweep in ("u", "v"):
        paths = manifest["sweeps"][sweep]["paths"]
        assert [Path(p).name for p in paths] == [f"{k:06d}{suffix}" for k in range(96)]
        assert manifest["sweeps"][sweep]["times_s"] == [float(k) for k in range(96)]  # frame t = file index
    noise = "raw12" if suffix == ".dng" else "noise_free"
    assert manifest["ground_truth"] == {"format": "mitsuba_lab_npz", "file": "gt.npz", "noise": noise}
    assert len(verify_checksums(manifest)) == 2 * 96 + 2


# --------------------------------------------------------------------------- what the capture contains


def test_listed_file_missing_is_named_before_any_work(tmp_path, make_capture):
    path, _ = make_capture(tmp_path, names=("f1.png", "f2.png", "f3.png"))
    (tmp_path / "data" / "u" / "f2.png").unlink()
    with pytest.raises(ValueError, match=r"listed in checksums.*missing.*u/f2\.png"):
        load_manifest(path)


def test_unlisted_file_matching_the_glob_is_named(tmp_path, make_capture, write_image):
    path, _ = make_capture(tmp_path, names=("f1.png", "f2.png", "f3.png"))
    write_image(tmp_path / "data" / "u" / "f4.png", np.zeros((6, 8, 3), np.uint16))
    with pytest.raises(ValueError, match=r"not listed in checksums: u/f4\.png"):
        load_manifest(path)


def test_gap_in_frame_numbers_is_named(tmp_path, make_capture):
    path, _ = make_capture(tmp_path, names=("f000.png", "f001.png", "f003.png", "f004.png"))
    with pytest.raises(ValueError, match=r"sweep 'u'.*gap.*u/f001\.png.*u/f003\.png.*frame number 2"):
        load_manifest(path)
    # a constant step other than 1 (every other frame kept) is a sequence, not a gap
    path, _ = make_capture(tmp_path / "b", names=("f0.png", "f2.png", "f4.png"))
    assert len(load_manifest(path)["sweeps"]["u"]["paths"]) == 3


def test_mixed_file_types_in_a_sweep_are_named(tmp_path, make_capture, rewrite):
    path, doc = make_capture(tmp_path, names=("f1.png", "f2.png", "f3.png"), with_checksums=False)
    (tmp_path / "data" / "u" / "f2.tif").write_bytes((tmp_path / "data" / "u" / "f2.png").read_bytes())
    (tmp_path / "data" / "u" / "f2.png").unlink()
    doc["sweeps"]["u"]["files"] = "u/*"
    rewrite(path, doc)
    doc["checksums"] = checksums_for(path)
    with pytest.raises(ValueError, match=r"sweep 'u'.*one file type.*\.png.*u/f2\.tif"):
        load_manifest(rewrite(path, doc))


@pytest.mark.parametrize("stamps, problem", [
    ({"u/f1.png": 0.0, "u/f2.png": 2.0, "u/f3.png": 1.0}, r"u/f3\.png \(1 s\).*after u/f2\.png \(2 s\)"),
    ({"u/f1.png": 0.0, "u/f2.png": 1.0, "u/f3.png": 1.0}, r"u/f3\.png \(1 s\).*same time.*u/f2\.png"),
])
def test_times_out_of_order_or_duplicated_are_named(tmp_path, make_capture, rewrite, stamps, problem):
    path, doc = make_capture(tmp_path, names=("f1.png", "f2.png", "f3.png"), with_checksums=False)
    (tmp_path / "data" / "stamps.json").write_text(json.dumps({"times_s": stamps}))
    doc["timing"] = {"source": "sidecar", "file": "stamps.json", "key": "times_s"}
    rewrite(path, doc)
    doc["checksums"] = checksums_for(path)
    with pytest.raises(ValueError, match=problem + r".*timing source sidecar"):
        load_manifest(rewrite(path, doc))


def test_duplicated_exif_times_are_named(tmp_path, write_image, rewrite):
    data = tmp_path / "data" / "t"
    data.mkdir(parents=True)
    for k, stamp in enumerate(["2024:05:01 19:00:00", "2024:05:01 19:00:01", "2024:05:01 19:00:01"]):
        write_image(data / f"{k}.tif", np.zeros((4, 4, 3), np.uint16), **{"Exif:DateTimeOriginal": stamp})
    doc = {"name": "m", "kind": "outdoor", "light": "distant", "root": "data",
           "sweeps": {"t": {"files": "t/*.tif"}}, "timing": {"source": "metadata"}}
    path = rewrite(tmp_path / "m.yaml", doc)
    doc["checksums"] = checksums_for(path)
    with pytest.raises(ValueError, match=r"t/2\.tif \(1 s\).*same time.*t/1\.tif.*timing source metadata"):
        load_manifest(rewrite(path, doc))
