"""Tests of shadowcam.evaluate.workflow_benchmark: benchmark files, stage sums and the extrapolation."""

import numpy as np
import pytest

from shadowcam.evaluate.workflow_benchmark import (accuracy_line, benchmark_table, directory_bytes, growth_table, memory_growth,
                                                  read_benchmarks, read_runs,
                                                  scale_targets, time_decode)

HEADER = "s\th:m:s\tmax_rss\tmax_vms\n"


def _write(directory, name, seconds, rss):
    (directory / f"{name}.tsv").write_text(HEADER + f"{seconds}\t0:00:00\t{rss}\t0\n")


def test_parted_stage_jobs_are_grouped_and_the_extrapolation_divides_by_the_cores(tmp_path):
    _write(tmp_path, "decode_part0000", 10.0, 100)
    _write(tmp_path, "decode_part0001", 30.0, 300)
    _write(tmp_path, "arrival", 4.0, "NA")
    stages = read_benchmarks(tmp_path)
    assert stages == {"arrival": [(4.0, pytest.approx(float("nan"), nan_ok=True))],
                      "decode_parts": [(10.0, 100.0), (30.0, 300.0)]}
    lines = benchmark_table({"decode_parts": stages["decode_parts"]}, n_frames=20, shape=(1000, 2000),
                            store_bytes=20e6, extrapolate=1000, cores=2)
    stage = lines[2].split()
    assert stage[:4] == ["decode_parts", "2", "40.0", "2.00"]  # 40 s over 20 frames
    # 2 s/frame x 1000 frames / 2 jobs side by side = 1000 s = 0.3 h; memory 300 MB x 2
    assert "0.3 h" in lines[-1] and "peak memory 0.6 GB" in lines[-1] and "(1 MB/frame)" in lines[-1]


def test_cpu_clock_reads_the_cpu_time_column(tmp_path):
    (tmp_path / "arrival.tsv").write_text("s\th:m:s\tmax_rss\tcpu_time\n9.5\t0:00:09\t120\t2.25\n")
    assert read_benchmarks(tmp_path, clock="cpu") == {"arrival": [(2.25, 120.0)]}
    assert read_benchmarks(tmp_path) == {"arrival": [(9.5, 120.0)]}
    with pytest.raises(ValueError, match="clock"):
        read_benchmarks(tmp_path, clock="sun")


def test_missing_benchmarks_and_store_size(tmp_path):
    with pytest.raises(ValueError, match="no benchmark files"):
        read_benchmarks(tmp_path)
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "x.bin").write_bytes(b"12345")
    (tmp_path / "y.bin").write_bytes(b"123")
    assert directory_bytes(tmp_path) == 8


def test_memory_growth_is_the_line_through_the_two_runs():
    # 500 MB at 8 frames, 516 MB at 16: 2 MB/frame -> 684 MB at 100, 2484 MB at 1000
    growth = memory_growth([({"arrival": [(1.0, 516.0)], "solo": [(1.0, 9.0)]}, 16), ({"arrival": [(1.0, 500.0)]}, 8)])
    assert set(growth) == {"arrival"}
    low, high, ratio = growth["arrival"]
    assert low == pytest.approx(684.0) and high == pytest.approx(2484.0) and ratio == pytest.approx(2484 / 684)
    flat = memory_growth([({"a": [(1.0, 300.0), (1.0, 400.0)]}, 16), ({"a": [(1.0, 400.0)]}, 8)])
    assert flat["a"] == pytest.approx((400.0, 400.0, 1.0))
    shrinking = memory_growth([({"a": [(1.0, 380.0)]}, 16), ({"a": [(1.0, 400.0)]}, 8)])
    assert shrinking["a"] == pytest.approx((390.0, 390.0, 1.0))  # a lower peak of the longer run is noise: the mean
    with pytest.raises(ValueError, match="two different frame counts"):
        memory_growth([({}, 8), ({}, 8)])


def test_memory_growth_through_several_runs_is_the_least_squares_line():
    # 32, 64, 128 frames on 200 + 0.5 * frames, with +-4 MB of noise of zero sum and zero slope:
    # the fitted line is the exact one (residuals orthogonal to [1, frames])
    frames = np.array([32, 64, 128])
    noise = np.array([4.0, -6.0, 2.0])  # sum 0 and sum(noise * frames) = 128 - 384 + 256 = 0
    runs = [({"a": [(1.0, 200 + 0.5 * n + e)]}, int(n)) for n, e in zip(frames, noise)]
    low, high, ratio = memory_growth(runs)["a"]
    assert low == pytest.approx(250.0) and high == pytest.approx(700.0) and ratio == pytest.approx(700 / 250)
    assert growth_table(memory_growth(runs))[1].split() == ["a", "250", "700", "2.80"]


def test_read_runs_orders_the_runs_longest_first(tmp_path):
    for name, rss in (("short", 100.0), ("long", 120.0)):
        (tmp_path / name).mkdir()
        (tmp_path / name / "arrival.tsv").write_text("s\th:m:s\tmax_rss\tcpu_time\n1.0\t0:00:01\t%s\t0.5\n" % rss)
    runs = read_runs([tmp_path / "short", tmp_path / "long"], [8, 16])
    assert [n for _, n in runs] == [16, 8] and runs[0][0]["arrival"][0][1] == 120.0
    with pytest.raises(ValueError, match="one frame count per run"):
        read_runs([tmp_path / "short"], [8, 16])


def test_scale_targets_are_the_ratios_of_one_run():
    stages = {"decode_timelapse_parts": [(4.0, 900.0), (4.0, 800.0)], "outdoor_normalise_parts": [(3.0, 5000.0)],
              "outdoor_normalise": [(1.0, 100.0)], "arrival": [(8.0, float("nan"))]}
    decode = {"frames": 10, "raw_bytes": 1000, "mosaic_s": 5.0, "mosaic_cpu_s": 2.5, "rgb_s": 7.0, "direct": True}
    # the 5-frame run: 6 s less, 2 of them in pass 1
    before = {"decode_timelapse_parts": [(4.0, 900.0)], "outdoor_normalise_parts": [(1.0, 5000.0)],
              "outdoor_normalise": [(1.0, 100.0)], "arrival": [(8.0, float("nan"))]}
    lines = scale_targets(stages, n_frames=10, store_bytes=2000, decode=decode, before=before, before_frames=5,
                          growth={"arrival": (100.0, 110.0, 1.1), "a": (100.0, 150.0, 1.5),
                                  "decode_timelapse_parts": (100.0, 900.0, 9.0)})
    rows = {name: rest for name, *rest in (line.rsplit(None, 3) for line in lines[2:] if not line.startswith("  ("))}
    assert "0.500 s/frame mosaic, 0.700 s/frame to float RGB" in lines[0] and "direct mosaic reader" in lines[0]
    assert rows["frame store / RAW bytes"] == ["2.00", "1.50", "MISSED"]
    assert rows["end-to-end (all jobs) / decode-only time"] == ["4.00", "3.00", "MISSED"]  # 20 s / 5 s
    assert rows["pass 1 (registration, gains) / decode-only time"] == ["0.80", "1.00", "ok"]  # 4 s / 5 s
    # per added frame: 6 s / 5 frames = 1.2 s against 0.5 s decode; pass 1 2 s / 5 frames = 0.4 s
    added = [rest for name, *rest in (line.rsplit(None, 3) for line in lines) if "per added frame (5 -> 10)" in name]
    assert added == [["2.40", "3.00", "ok"], ["0.80", "1.00", "ok"]]
    assert rows["peak RSS per job, MB (outdoor_normalise_parts)"] == ["5000.00", "4096.00", "MISSED"]
    assert rows["peak RSS 1000 / 100 frames (a)"] == ["1.50", "1.20", "MISSED"]  # parted jobs: fixed frames
    cpu = scale_targets(stages, n_frames=10, store_bytes=2000, decode=decode, clock="cpu")
    assert cpu[0].startswith("cpu time") and "0.250 s/frame mosaic" in cpu[0]
    assert [line.split()[-3] for line in cpu if "/ decode-only time" in line] == ["8.00", "1.60"]  # against 2.5 s
    with pytest.raises(ValueError, match="clock"):
        scale_targets(stages, n_frames=10, store_bytes=1, decode=decode, clock="gpu")
    with pytest.raises(ValueError, match="10 frames"):
        scale_targets(stages, n_frames=10, store_bytes=1, decode=dict(decode, frames=9))


def test_time_decode_reads_every_frame_with_the_pipeline_reader(tmp_path):
    from shadowcam.io.raw_writer import write_dng

    rng = np.random.default_rng(0)
    paths = []
    for k in range(3):
        mosaic = rng.integers(600, 16000, size=(24, 32), dtype=np.uint16)
        paths.append(write_dng(tmp_path / f"{k}.dng", mosaic, bit_depth=14, black_level=512, compression="ljpeg"))
    decode = time_decode(paths)
    assert decode["frames"] == 3 and decode["raw_bytes"] == sum(p.stat().st_size for p in paths)
    assert decode["mosaic_s"] > 0 and decode["mosaic_cpu_s"] > 0 and decode["rgb_s"] > 0
    assert decode["direct"]  # lossless-JPEG DNGs the writer makes are read directly, as the pipeline does
    with pytest.raises(ValueError, match="at least one"):
        time_decode([])


def test_column_strip_jobs_are_one_stage_apart_from_their_merge(tmp_path):
    _write(tmp_path, "track_edges_strip0", 5.0, 700)
    _write(tmp_path, "track_edges_strip1", 6.0, 720)
    _write(tmp_path, "track_edges", 1.0, 900)
    assert read_benchmarks(tmp_path) == {"track_edges": [(1.0, 900.0)],
                                         "track_edges_strips": [(5.0, 700.0), (6.0, 720.0)]}


def test_accuracy_line_reports_the_primary_errors_and_every_target_verdict():
    errors = {"n_evaluated": 5000, "coverage": 0.987, "median_abs": 0.25, "p95_abs": 2.5, "frac_over_5": 0.004}
    accuracy = {"primary_estimator": "combined", "primary_definition": "pixel_centre", "interval_s": 300.0,
                "errors": {"combined": {"pixel_centre": errors, "half_coverage": dict(errors, median_abs=9.0)}},
                "targets": [{"target": "median_abs", "comparison": "<=", "threshold": 0.5, "pass": True},
                            {"target": "p95_abs", "comparison": "<=", "threshold": 2.0, "pass": False}]}
    line = accuracy_line(accuracy, shape=(4000, 128))
    assert line.startswith("arrival accuracy at 128x4000 (combined, pixel_centre, 5000 pixels, interval 300.0 s)")
    assert "median 0.250, p95 2.500 intervals, beyond 5 intervals 0.40 %, coverage 98.7 %" in line
    assert line.endswith("(median_abs <= 0.5 pass, p95_abs <= 2 FAIL)")
