"""Tests of shadowcam.io.frame_files: a sweep's files share one format, decode path and size."""

import numpy as np
import pytest
import yaml

from shadowcam.cli import main
from shadowcam.io.capture_plan import capture_plan
from shadowcam.io.frame_files import check_frame_files, file_format, header_size
from shadowcam.io.manifest import checksums_for, load_manifest
from shadowcam.io.sweep_store import decode_sweep

ROWS, COLS = 24, 32


@pytest.fixture
def frames(tmp_path, write_image, write_pidng):
    """One file of each kind, ROWS x COLS, under tmp_path/kinds."""
    folder = tmp_path / "kinds"
    folder.mkdir()
    pixels = np.full((ROWS, COLS, 3), 1000, np.uint16)
    made = {ext: write_image(folder / f"a.{ext}", pixels) for ext in ("png", "tif", "jpg")}
    made["exr"] = write_image(folder / "a.exr", pixels.astype(np.float32))
    made["dng"] = write_pidng(folder / "a.dng", np.full((ROWS, COLS), 1000, np.uint16))
    return made


def test_format_from_content_and_size_from_header(frames, tmp_path):
    assert {ext: file_format(p) for ext, p in frames.items()} == {
        "png": "PNG", "tif": "TIFF", "jpg": "JPEG", "exr": "OpenEXR", "dng": "DNG"}
    assert all(header_size(p) == (ROWS, COLS) for p in frames.values())
    renamed = tmp_path / "renamed.png"
    renamed.write_bytes(frames["dng"].read_bytes())
    assert file_format(renamed) == "DNG"


def test_dng_among_pngs_and_dng_renamed_png_are_named(frames, tmp_path, write_image):
    pngs = [write_image(tmp_path / f"{k}.png", np.zeros((ROWS, COLS, 3), np.uint16)) for k in range(3)]
    with pytest.raises(ValueError, match=r"a\.dng is DNG.*first file .*0\.png is PNG.*one format"):
        check_frame_files(pngs + [frames["dng"]], what="sweep 'u'")
    renamed = tmp_path / "3.png"
    renamed.write_bytes(frames["dng"].read_bytes())
    with pytest.raises(ValueError, match=r"3\.png holds DNG data.*rename it"):
        check_frame_files(pngs + [renamed], what="sweep 'u'")
    with pytest.raises(ValueError, match=r"3\.png holds DNG data"):
        check_frame_files([renamed], what="sweep 'u'")


def test_odd_frame_size_is_named_with_the_expected_size(tmp_path, write_image):
    paths = [write_image(tmp_path / f"{k}.png", np.zeros((ROWS, COLS, 3), np.uint16)) for k in range(3)]
    odd = write_image(tmp_path / "3.png", np.zeros((ROWS + 1, COLS, 3), np.uint16))
    with pytest.raises(ValueError, match=rf"3\.png is {ROWS + 1}x{COLS}.*0\.png.*{ROWS}x{COLS}"):
        check_frame_files(paths + [odd], what="sweep 'u'")


def _lab(tmp_path, write_image, *, u=(ROWS, COLS), v=(ROWS, COLS), ref=(ROWS, COLS), names=None):
    data = tmp_path / "data"
    for sweep, shape in (("u", u), ("v", v)):
        (data / sweep).mkdir(parents=True)
        for k, size in enumerate(names or [shape] * 3):
            write_image(data / sweep / f"{k:03d}.png", np.full(size + (3,), 100 * k, np.uint16))
    write_image(data / "ref.png", np.full(ref + (3,), 7, np.uint16))
    doc = {"name": "cap", "kind": "lab", "light": "point", "root": "data",
           "sweeps": {"u": {"files": "u/*.png", "axis": "u"}, "v": {"files": "v/*.png", "axis": "v"}},
           "reference": "ref.png", "timing": {"source": "rate", "rate_hz": 1.0}}
    path = tmp_path / "cap.yaml"
    path.write_text(yaml.safe_dump(doc))
    path.write_text(yaml.safe_dump({**doc, "checksums": checksums_for(path)}))
    return path


def test_u_and_v_of_different_sizes_fail_when_planned(tmp_path, write_image):
    path = _lab(tmp_path, write_image, v=(ROWS, COLS + 2))
    with pytest.raises(ValueError, match=rf"v/000\.png is {ROWS}x{COLS + 2}.*u/000\.png.*{ROWS}x{COLS}"):
        capture_plan(path)
    with pytest.raises(ValueError, match=r"v/000\.png"):  # the decode step alone says the same
        decode_sweep(load_manifest(path), "v", tmp_path / "v.zarr")
    assert not (tmp_path / "v.zarr").exists()


def test_reference_of_another_size_fails_when_planned(tmp_path, write_image):
    path = _lab(tmp_path, write_image, ref=(ROWS * 2, COLS * 2))
    with pytest.raises(ValueError, match=rf"ref\.png is {2 * ROWS}x{2 * COLS}.*u/000\.png"):
        capture_plan(path)


def test_decode_names_an_odd_frame_before_writing(tmp_path, write_image):
    path = _lab(tmp_path, write_image, names=[(ROWS, COLS), (ROWS, COLS), (ROWS - 2, COLS)])
    capture_plan(path)  # planning reads only the first file of each sweep
    out = tmp_path / "u.zarr"
    assert main(["decode", "--manifest", str(path), "--sweep", "u", "--out", str(out)]) != 0
    assert not out.exists() and not (tmp_path / "u.zarr.tmp").exists()
    with pytest.raises(ValueError, match=rf"u/002\.png is {ROWS - 2}x{COLS}.*u/000\.png.*{ROWS}x{COLS}"):
        decode_sweep(load_manifest(path), "u", out, frames=(2, 3), chunk_frames=1)
