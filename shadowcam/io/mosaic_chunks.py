"""A mosaic store's time chunks read straight from their chunk files into one reused buffer.

zarr reads a chunk into an array of its own and copies the selection into
another: for whole 24 MP frames two fresh 48 MB arrays per frame (their page
faults and a copy) on top of the decompression itself. A frame store's
``mosaic (time, row, col)`` written by :func:`shadowcam.io.frame_store.write_frames`
has a plain layout (whole frames per chunk, chunk files ``c/<t>/0/0``, the
``bytes`` codec then Blosc), so its chunks are decompressed here straight into
one buffer that is kept and reused, with the Blosc compressor, shuffle and
block size each chunk's own header declares (stores written with any Blosc
setting read alike). Anything else (another codec, a missing chunk file, a
window across chunks) is left to zarr: :meth:`MosaicChunks.window` returns None.

Offers
------
MosaicChunks : windows of a store's mosaic from one decompressed time chunk (None where zarr must read).
"""

import json
import threading
from pathlib import Path

import numpy as np
from numcodecs import Blosc


def _decoded_bytes(encoded):
    """Uncompressed size a Blosc chunk's header declares (bytes 4-7, little-endian)."""
    return int.from_bytes(encoded[4:8], "little") if len(encoded) >= 16 else -1


def _plain_blosc_layout(meta):
    """True if the array metadata `meta` (zarr v3) is the plain layout read directly here."""
    codecs = meta.get("codecs") or []
    return (meta.get("zarr_format") == 3 and meta.get("data_type") == "uint16"
            and len(meta.get("shape", ())) == 3 and not meta.get("storage_transformers")
            and meta.get("chunk_grid", {}).get("name") == "regular"
            and list(meta["chunk_grid"]["configuration"]["chunk_shape"][1:]) == list(meta["shape"][1:])
            and meta.get("chunk_key_encoding", {}).get("name") == "default"
            and meta["chunk_key_encoding"].get("configuration", {}).get("separator", "/") == "/"
            and [c.get("name") for c in codecs] == ["bytes", "blosc"]
            and codecs[0].get("configuration", {}).get("endian", "little") == "little")


class MosaicChunks:
    """The ``mosaic (time, row, col)`` uint16 array of a frame store, read one time chunk at a time.

    The last chunk decompressed is kept (and its buffer reused for the next),
    so that windows of several frames of one chunk decompress it once. A window
    is a view into that buffer, valid until the next call: callers sharing a
    reader between threads hold :attr:`lock` while they use one.

    Parameters
    ----------
    array_path : str or Path
        The store's ``mosaic`` array directory (holding its ``zarr.json``).
    """

    def __init__(self, array_path):
        self._path = Path(array_path)
        meta = json.loads((self._path / "zarr.json").read_text())
        self._direct = _plain_blosc_layout(meta)
        self.shape = tuple(meta["shape"])
        self._chunk_frames = int(meta["chunk_grid"]["configuration"]["chunk_shape"][0]) if self._direct else 0
        self._buffer, self._held = None, None
        self.lock = threading.Lock()

    def __getstate__(self):
        return {**self.__dict__, "_buffer": None, "_held": None, "lock": None}

    def __setstate__(self, state):
        self.__dict__.update(state, lock=threading.Lock())

    def window(self, t0, t1, r0, r1, c0, c1):
        """Return ``mosaic[t0:t1, r0:r1, c0:c1]`` from one decompressed chunk, or None.

        Parameters
        ----------
        t0, t1, r0, r1, c0, c1 : int
            The window, ``0 <= t0 < t1 <= T``, rows and cols within the frame.

        Returns
        -------
        (t1 - t0, r1 - r0, c1 - c0) uint16 ndarray or None
            A read-only view into the reused buffer (valid until the next call);
            None where the store's layout is not the plain one, the frames span
            two chunks or the chunk file is missing (zarr then reads the window).
        """
        if not self._direct or not 0 <= t0 < t1 <= self.shape[0]:
            return None
        chunk = t0 // self._chunk_frames
        if (t1 - 1) // self._chunk_frames != chunk:
            return None
        if self._held != chunk:
            path = self._path.joinpath("c", str(chunk), "0", "0")
            if not path.is_file():
                return None
            encoded = path.read_bytes()
            shape = (self._chunk_frames,) + self.shape[1:]
            if _decoded_bytes(encoded) != int(np.prod(shape)) * 2:
                return None
            if self._buffer is None:
                self._buffer = np.empty(shape, dtype="<u2")
            self._held = None  # the buffer is being overwritten
            Blosc().decode(encoded, out=self._buffer)
            self._held = chunk
        first = chunk * self._chunk_frames
        view = self._buffer[t0 - first:t1 - first, r0:r1, c0:c1]
        view.flags.writeable = False
        return view
