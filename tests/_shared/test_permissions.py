"""Written outputs respect the user's umask (a shared cluster group can read results)."""

import os
import stat

import numpy as np
import pytest
import xarray as xr

from shadowcam._shared.atomic import atomic_directory, atomic_path
from shadowcam.io.datasets import write_dataset
from shadowcam.io.frame_store import write_frames


@pytest.fixture(params=[0o022, 0o027], ids=["umask022", "umask027"])
def umask(request):
    old = os.umask(request.param)
    yield request.param
    os.umask(old)


def _mode(path):
    return stat.S_IMODE(os.stat(path).st_mode)


def _expect_tree(root, umask):
    """Every file of `root` has mode 0o666 & ~umask, every folder 0o777 & ~umask."""
    assert _mode(root) == (0o777 & ~umask if os.path.isdir(root) else 0o666 & ~umask), root
    for folder, dirs, files in os.walk(root):
        for name in dirs:
            assert _mode(os.path.join(folder, name)) == 0o777 & ~umask, os.path.join(folder, name)
        for name in files:
            assert _mode(os.path.join(folder, name)) == 0o666 & ~umask, os.path.join(folder, name)


def test_atomic_path_and_directory(tmp_path, umask):
    with atomic_path(tmp_path / "a" / "out.json") as tmp:
        tmp.write_text("{}")
    _expect_tree(tmp_path / "a" / "out.json", umask)
    with atomic_directory(tmp_path / "figures") as tmp:
        with atomic_path(tmp / "f.png") as inner:
            inner.write_bytes(b"png")
        (tmp / "sub").mkdir()
    _expect_tree(tmp_path / "figures", umask)


def test_dataset_and_frame_store(tmp_path, umask, make_frames):
    write_dataset(xr.Dataset({"x": ("row", np.arange(3.0))}), tmp_path / "outdoor" / "arrival.nc")
    _expect_tree(tmp_path / "outdoor", umask)
    paths, _ = make_frames(tmp_path / "in", 3)
    write_frames(paths, tmp_path / "frames" / "u.zarr", times_s=np.arange(3.0), chunk_frames=2)
    _expect_tree(tmp_path / "frames", umask)
