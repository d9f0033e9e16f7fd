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


def _killed_writer(code):
    """Run `code` (which writes through atomic_path / atomic_directory) in a child that SIGKILLs itself."""
    import os
    import signal
    import subprocess
    import sys

    script = f"import os, signal\nfrom shadowcam._shared.atomic import atomic_directory, atomic_path\n{code}\n"
    result = subprocess.run([sys.executable, "-c", script], env=dict(os.environ))
    assert result.returncode == -signal.SIGKILL


@pytest.mark.parametrize("kind", ["file", "directory"])
def test_leftovers_of_a_killed_writer_are_removed_by_the_next_write(tmp_path, kind):
    target = tmp_path / ("x.nc" if kind == "file" else "u.zarr")
    if kind == "file":
        code = (f"with atomic_path({str(target)!r}) as tmp:\n    tmp.write_bytes(b'half' * 1000)\n"
                "    os.kill(os.getpid(), signal.SIGKILL)")
    else:
        code = (f"with atomic_directory({str(target)!r}) as tmp:\n    (tmp / 'c0').write_bytes(b'half')\n"
                "    os.kill(os.getpid(), signal.SIGKILL)")
    _killed_writer(code)
    assert len(list(tmp_path.iterdir())) == 1  # the killed writer's hidden temporary
    context = atomic_path(target) if kind == "file" else atomic_directory(target)
    with context as tmp:
        (tmp.write_text("new") if kind == "file" else (tmp / "c0").write_text("new"))
    assert sorted(p.name for p in tmp_path.iterdir()) == [target.name]


def test_a_writer_still_running_keeps_its_temporary(tmp_path):
    target = tmp_path / "x.nc"
    with atomic_path(target) as outer:
        outer.write_text("outer")
        with atomic_path(target) as inner:  # same process: alive
            inner.write_text("inner")
        assert outer.exists()
    assert target.read_text() == "outer"


def test_a_full_disk_leaves_no_temporary(tmp_path):
    import errno

    target = tmp_path / "shadow_time.nc"
    with pytest.raises(OSError, match="No space"):
        with atomic_path(target) as tmp:
            tmp.write_bytes(b"x" * 4096)
            raise OSError(errno.ENOSPC, "No space left on device")
    assert list(tmp_path.iterdir()) == []
