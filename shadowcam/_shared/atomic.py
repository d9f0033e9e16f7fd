"""Atomic writes: an output appears whole or not at all.

A write goes to a hidden temporary beside the target, named after the target, the
host and the writing process (``.<stem>.<host>.<pid>-XXXX<suffix>`` for a file,
``.<name>.<host>.<pid>.tmp`` for a directory), and is renamed onto the target only
when complete. On an exception (a full disk included) the temporary is removed. A
process killed outright (SIGKILL, out of memory, a cluster's time limit) cannot clean
up: the next write of the same target removes the temporaries of processes of this
host that no longer run, so leftovers never keep holding disk space.

Offers
------
atomic_path : context manager yielding a temporary file path that replaces the target on success.
atomic_directory : context manager yielding a temporary directory that replaces the target on success.
umask : the process's file-creation mask.

Outputs get the modes of a plain ``open``/``mkdir`` (``0o666`` / ``0o777``
less the umask), so a group that shares the results can read them.
"""

import contextlib
import os
import re
import shutil
import socket
import tempfile
from pathlib import Path


def _host():
    """This machine's name as it appears in temporary names (no dots or path separators)."""
    return re.sub(r"[^A-Za-z0-9_-]", "_", socket.gethostname().split(".")[0]) or "host"


def _running(pid):
    """True if process `pid` runs on this machine."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _remove_leftovers(path, pattern):
    """Remove the siblings of `path` matching `pattern` (groups ``host``, ``pid``) of dead processes here."""
    if not path.parent.is_dir():
        return
    host = _host()
    for sibling in path.parent.iterdir():
        match = re.fullmatch(pattern, sibling.name)
        if match is None or match["host"] != host or _running(int(match["pid"])):
            continue
        if sibling.is_dir() and not sibling.is_symlink():
            shutil.rmtree(sibling, ignore_errors=True)
        else:
            with contextlib.suppress(FileNotFoundError):
                sibling.unlink()


@contextlib.contextmanager
def atomic_path(path):
    """Yield a temporary path beside `path`; rename it onto `path` if the block succeeds.

    The temporary name keeps the suffix of `path` (writers choose the format
    from it). On an exception the temporary file is removed; temporaries left
    by killed writers of `path` are removed first.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    _remove_leftovers(path, rf"\.{re.escape(path.stem)}\.(?P<host>[A-Za-z0-9_-]+)\.(?P<pid>\d+)-[A-Za-z0-9_]+"
                            rf"{re.escape(path.suffix)}")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.{_host()}.{os.getpid()}-", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    os.chmod(tmp, 0o666 & ~umask())  # mkstemp creates 0o600
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def atomic_directory(path):
    """Yield an empty temporary directory beside `path`; put it in place of `path` on success.

    An old directory at `path` is replaced only after the block succeeded; on an
    exception the temporary directory is removed and `path` is left as it was.
    Temporaries left by killed writers of `path` are removed first.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    _remove_leftovers(path, rf"\.{re.escape(path.name)}\.(?P<host>[A-Za-z0-9_-]+)\.(?P<pid>\d+)\.(tmp|old)")
    stem = f".{path.name}.{_host()}.{os.getpid()}"
    tmp = path.parent / f"{stem}.tmp"
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir()
    try:
        yield tmp
        old = None
        if path.exists():
            old = path.parent / f"{stem}.old"
            path.rename(old)
        tmp.rename(path)
        if old is not None:
            shutil.rmtree(old)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def umask():
    """Return the process's umask (read without changing it where the system allows)."""
    with contextlib.suppress(OSError, ValueError), open("/proc/self/status") as status:
        for line in status:
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask
