"""Tests of shadowcam._shared.atomic: outputs appear whole or not at all."""

import pytest

from shadowcam._shared.atomic import atomic_directory, atomic_path


def test_atomic_path_removes_temporary_on_failure(tmp_path):
    target = tmp_path / "x.nc"
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            assert tmp.suffix == ".nc" and tmp.parent == tmp_path
            tmp.write_text("half")
            raise RuntimeError("boom")
    assert list(tmp_path.iterdir()) == []


def test_atomic_path_replaces_the_target(tmp_path):
    target = tmp_path / "sub" / "x.txt"
    with atomic_path(target) as tmp:
        tmp.write_text("new")
    assert target.read_text() == "new"
    assert sorted(p.name for p in target.parent.iterdir()) == ["x.txt"]


def test_atomic_directory_replaces_old_directory_only_on_success(tmp_path):
    out = tmp_path / "capture"
    out.mkdir()
    (out / "old.txt").write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_directory(out) as tmp:
            (tmp / "half.txt").write_text("half")
            raise RuntimeError("boom")
    assert sorted(p.name for p in out.iterdir()) == ["old.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["capture"]
    with atomic_directory(out) as tmp:
        assert tmp != out and not any(tmp.iterdir())
        (tmp / "new.txt").write_text("new")
    assert sorted(p.name for p in out.iterdir()) == ["new.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["capture"]
