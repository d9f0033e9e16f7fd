"""Tests of shadowcam.evaluate.workflow_benchmark: benchmark files, stage sums and the extrapolation."""

import pytest

from shadowcam.evaluate.workflow_benchmark import benchmark_table, directory_bytes, read_benchmarks

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


def test_missing_benchmarks_and_store_size(tmp_path):
    with pytest.raises(ValueError, match="no benchmark files"):
        read_benchmarks(tmp_path)
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "x.bin").write_bytes(b"12345")
    (tmp_path / "y.bin").write_bytes(b"123")
    assert directory_bytes(tmp_path) == 8
