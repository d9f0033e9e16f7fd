"""Frame times: the auto source order (metadata, file names, sidecar), intervals and gaps."""

import json

import numpy as np
import pytest

from shadowcam.io.frame_times import auto_candidates, find_gaps, median_interval
from shadowcam.io.manifest import checksums_for, load_manifest


def test_auto_prefers_metadata_then_file_names_then_sidecar(tmp_path, make_capture, rewrite):
    names = ("img_0.0s.png", "img_61.5s.png", "img_180.0s.png")
    path, doc = make_capture(tmp_path, names=names, with_checksums=False)
    (tmp_path / "data" / "stamps.json").write_text(json.dumps({"times_s": [0.0, 60.0, 120.0]}))
    # PNGs carry no EXIF time: file names win over the sidecar
    doc["timing"] = {"source": "auto", "regex": r"_(?P<time_s>\d+\.\d+)s", "file": "stamps.json", "key": "times_s"}
    rewrite(path, doc)
    doc["checksums"] = checksums_for(path)
    assert load_manifest(rewrite(path, doc))["sweeps"]["u"]["times_s"] == [0.0, 61.5, 180.0]
    # without a regex: the sidecar
    doc["timing"] = {"source": "auto", "file": "stamps.json", "key": "times_s"}
    assert load_manifest(rewrite(path, doc))["sweeps"]["u"]["times_s"] == [0.0, 60.0, 120.0]
    # nothing usable: the error lists what was tried
    doc["timing"] = {"source": "auto"}
    with pytest.raises(ValueError, match="metadata: .*no EXIF DateTimeOriginal"):
        load_manifest(rewrite(path, doc))


def test_auto_uses_exif_times_when_every_file_has_one(tmp_path, write_image, rewrite):
    data = tmp_path / "data" / "u"
    data.mkdir(parents=True)
    for k, stamp in enumerate(["2024:05:01 18:59:00", "2024:05:01 19:00:05", "2024:05:01 19:02:00"]):
        write_image(data / f"f_{k}.tif", np.zeros((4, 4, 3), np.uint16), **{"Exif:DateTimeOriginal": stamp})
    doc = {"name": "m", "kind": "outdoor", "light": "distant", "root": "data", "sweeps": {"t": {"files": "u/*.tif"}},
           "timing": {"source": "auto", "regex": r"f_(?P<index>\d+)"}}
    path = rewrite(tmp_path / "m.yaml", doc)
    doc["checksums"] = checksums_for(path)
    assert load_manifest(rewrite(path, doc))["sweeps"]["t"]["times_s"] == [0.0, 65.0, 180.0]


def test_candidates_intervals_and_gaps():
    assert [c["source"] for c in auto_candidates({"source": "auto", "file": "s.json"})] == ["metadata", "sidecar"]
    times = np.array([0.0, 55.0, 108.0, 220.0, 275.0, 330.0])  # one frame dropped after frame 2
    assert median_interval(times) == pytest.approx(55.0)
    assert find_gaps(times) == [{"after_frame": 2, "interval_s": 112.0, "missing_frames": 1}]
    with pytest.raises(ValueError, match="increase"):
        median_interval(times[::-1])


def test_time_to_frame_is_piecewise_linear_and_clamps_or_gives_nan_outside():
    from shadowcam.io.frame_times import time_to_frame

    times, frames = [-5.0, 0.0, 15.0, 70.0, 130.0, np.nan, np.inf], [0.0, 10.0, 20.0, 120.0]
    np.testing.assert_allclose(time_to_frame(times, frames, outside="clamp"),
                               [0.0, 0.0, 1.5, 2.5, 3.0, np.nan, np.nan])
    np.testing.assert_allclose(time_to_frame(times, frames, outside="nan"),
                               [np.nan, 0.0, 1.5, 2.5, np.nan, np.nan, np.nan])
    with pytest.raises(ValueError, match="outside"):
        time_to_frame(times, frames, outside="wrap")


def _exif_timelapse(tmp_path, write_image, rewrite, stamps, *, timing=None, **extra):
    """An outdoor manifest over TIFFs whose EXIF DateTimeOriginal are `stamps` (None: no EXIF time)."""
    data = tmp_path / "data" / "u"
    data.mkdir(parents=True)
    for k, stamp in enumerate(stamps):
        tags = {} if stamp is None else {"Exif:DateTimeOriginal": stamp}
        write_image(data / f"f_{k:02d}.tif", np.zeros((4, 4, 3), np.uint16), **tags)
    doc = {"name": "m", "kind": "outdoor", "light": "distant", "root": "data",
           "sweeps": {"t": {"files": "u/*.tif"}}, "timing": timing or {"source": "metadata"}, **extra}
    path = rewrite(tmp_path / "m.yaml", doc)
    doc["checksums"] = checksums_for(path)
    return rewrite(path, doc), doc


def test_outdoor_exif_missing_on_some_frames_names_them_and_says_what_to_do(tmp_path, write_image, rewrite):
    stamps = ["2024:05:01 18:00:00", None, "2024:05:01 18:01:00", None, "2024:05:01 18:02:00"]
    path, doc = _exif_timelapse(tmp_path, write_image, rewrite, stamps)
    with pytest.raises(ValueError, match=r"sweep 't': 2 of 5 files have no EXIF DateTimeOriginal "
                                         r"\(u/f_01.tif, u/f_03.tif;.*timing.regex"):
        load_manifest(path)
    # auto: the file names take over when they give every frame a time
    doc["timing"] = {"source": "auto", "regex": r"f_(?P<index>\d+)", "rate_hz": 1 / 30}
    assert load_manifest(rewrite(path, doc))["sweeps"]["t"]["times_s"] == [0.0, 30.0, 60.0, 90.0, 120.0]


def test_outdoor_out_of_order_and_duplicated_exif_times_name_both_files(tmp_path, write_image, rewrite):
    stamps = ["2024:05:01 18:00:00", "2024:05:01 18:01:00", "2024:05:01 18:00:30"]
    path, _ = _exif_timelapse(tmp_path / "a", write_image, rewrite, stamps)
    with pytest.raises(ValueError, match="frame u/f_02.tif .* comes after u/f_01.tif .* but is earlier"):
        load_manifest(path)
    stamps = ["2024:05:01 18:00:00", "2024:05:01 18:01:00", "2024:05:01 18:01:00"]
    path, _ = _exif_timelapse(tmp_path / "b", write_image, rewrite, stamps)
    with pytest.raises(ValueError, match="frame u/f_02.tif .* has the same time as u/f_01.tif"):
        load_manifest(path)


def test_outdoor_gap_of_hours_is_refused_as_a_second_session_unless_allowed(tmp_path, write_image, rewrite):
    stamps = ["2024:05:01 18:00:00", "2024:05:01 18:01:00", "2024:05:01 18:02:00",
              "2024:05:02 18:03:00", "2024:05:02 18:04:00"]  # the next evening
    path, doc = _exif_timelapse(tmp_path, write_image, rewrite, stamps)
    with pytest.raises(ValueError, match=r"u/f_02.tif -> u/f_03.tif \(24.02 h\).*split it into one dataset "
                                         r"per session at u/f_03.tif, or set max_frame_gap_s"):
        load_manifest(path)
    doc["max_frame_gap_s"] = 90000
    times = load_manifest(rewrite(path, doc))["sweeps"]["t"]["times_s"]
    assert times == [0.0, 60.0, 120.0, 86580.0, 86640.0]
    assert find_gaps(times) == [{"after_frame": 2, "interval_s": 86460.0, "missing_frames": 1440}]
    # a pause under the limit (a dropped stretch of minutes) is kept and reported as a gap
    stamps[3:] = ["2024:05:01 18:40:00", "2024:05:01 18:41:00"]
    path, _ = _exif_timelapse(tmp_path / "c", write_image, rewrite, stamps)
    assert find_gaps(load_manifest(path)["sweeps"]["t"]["times_s"])[0]["missing_frames"] == 37
