"""Long loops report frames done, rate and time left (stderr when run by hand)."""

import logging
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from shadowcam._shared.progress import Progress, format_duration

LINE = re.compile(r"(?P<what>[\w -]+): (?P<done>\d+)/(?P<total>\d+) frames, (?P<rate>[\d.e+]+) frames/s, "
                  r"(?P<tail>\d.* left|done in .*)$")


class _Clock:
    """A clock that advances `step` seconds at each reading."""

    def __init__(self, step):
        self.now, self.step = 0.0, step

    def __call__(self):
        self.now += self.step
        return self.now


def test_progress_lines_rate_and_time_left(caplog):
    caplog.set_level(logging.INFO)
    progress = Progress(100, "decode u", every_s=10.0, clock=_Clock(1.0))  # one frame per second
    for k in range(100):
        progress.update(k + 1)
    lines = [LINE.search(r.getMessage()) for r in caplog.records]
    assert all(lines) and 9 <= len(lines) <= 11
    first = lines[0]
    assert first["what"] == "decode u" and int(first["done"]) == 10
    assert float(first["rate"]) == pytest.approx(1.0, rel=0.1)
    assert first["tail"] == "1 min 30 s left"
    assert lines[-1]["done"] == "100" and lines[-1]["tail"].startswith("done in 1 min 4")


def test_short_loop_says_only_when_done(caplog):
    caplog.set_level(logging.INFO)
    progress = Progress(5, "render", clock=_Clock(0.01))
    for k in range(5):
        progress.update(k + 1)
    assert [r.getMessage().split(",")[0] for r in caplog.records] == ["render: 5/5 frames"]


def test_format_duration_and_checks():
    assert [format_duration(s) for s in (0, 41.2, 200, 3900)] == ["0 s", "42 s", "3 min 20 s", "1 h 05 min"]
    with pytest.raises(ValueError, match="total"):
        Progress(0, "x")
    with pytest.raises(ValueError, match="every_s"):
        Progress(3, "x", every_s=-1)


def test_streaming_passes_report_progress(caplog, monkeypatch, make_frames, tmp_path):
    from shadowcam.io.frame_store import iter_store_frames, open_frames, write_frames

    paths, _ = make_frames(tmp_path / "in", 8)
    store = open_frames(write_frames(paths, tmp_path / "u.zarr", times_s=np.arange(8.0), chunk_frames=3))
    monkeypatch.setattr("shadowcam._shared.progress.time.monotonic", _Clock(6.0))
    caplog.set_level(logging.INFO)
    assert len(list(iter_store_frames(store))) == 8
    lines = [m for m in (LINE.search(r.getMessage()) for r in caplog.records) if m]
    assert [int(m["done"]) for m in lines] == list(range(1, 9))


def test_decode_by_hand_prints_progress_on_stderr(tmp_path, make_frames, sweep_manifest):
    make_frames(tmp_path / "data" / "u", 6)
    manifest = sweep_manifest(tmp_path, rate_hz=10.0)
    # each clock reading advances 6 s: every frame is past the 5 s between two lines
    code = ("import sys, itertools, shadowcam._shared.progress as p; c = itertools.count(); "
            "p.time.monotonic = lambda: 6.0 * next(c); from shadowcam.cli import main; sys.exit(main(sys.argv[1:]))")
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[2])}
    run = subprocess.run([sys.executable, "-c", code, "decode", "--manifest", str(manifest), "--sweep", "u",
                          "--out", str(tmp_path / "u.zarr")], capture_output=True, text=True, env=env, check=True)
    lines = [m for m in map(LINE.search, run.stderr.splitlines()) if m]
    assert [int(m["done"]) for m in lines] == list(range(1, 7)), run.stderr
    assert lines[0]["what"].endswith("decode u") and lines[0]["tail"].endswith("left")
