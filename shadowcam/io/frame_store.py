"""Time-chunked frame stores (zarr v3): write decoded frames, open and stream them.

A sweep store reads as variable ``image (time, row, col, channel)`` float32
(linear, black = 0, white level = 1) with coords ``time`` (frame index,
float64, units ``frame``), ``time_s`` and ``exposure_s`` (seconds, NaN where
unknown) and ``channel`` (``R``, ``G``, ``B``), chunked along time only. A
sweep of camera RAW frames is stored as its Bayer mosaics: ``mosaic (time,
row, col)`` uint16 DN (Blosc LZ4, bit-shuffled: a little larger than the
lossless-JPEG RAW files, and fast to decompress) with the per-frame levels
``black_sites`` and ``white_sites (time, cfa_row, cfa_col)``; its time chunks
are read straight from their files into one reused buffer
(:class:`shadowcam.io.mosaic_chunks.MosaicChunks`, any Blosc setting; zarr
reads other layouts). :func:`open_frames` presents it as
the lazy ``image`` above, demosaiced on indexing
(:func:`shadowcam.io.decode.mosaic_image`: the values a float store of the
same frames holds, bit for bit), reading only the window of the mosaic the
index needs, and adds the lazy ``luminance (time, row, col)``, the mean of
those channels computed from the mosaic without the colour image
(:func:`shadowcam.io.luminance.mosaic_luminance`, equal bit for bit). Other frames (TIFF, PNG, EXR ...) are stored as the float32
``image`` itself, compressed with zstd level 1. A reference store holds
``image (row, col, channel)`` (the mean of the reference frames). Stores are written to a hidden
temporary directory beside the store and renamed when complete
(:func:`shadowcam._shared.atomic.atomic_directory`), so an interrupted job never
leaves a store that looks finished, and a killed job's leftovers are removed by
the next write.

A long sweep can be decoded as several *part* stores, one per job, each
holding a range of frames that starts on a chunk boundary;
:func:`merge_frame_stores` joins them into the sweep store by hard-linking
their chunk files (no data copied; the result equals a single-job decode
bit for bit).

Offers
------
CHUNK_BYTES : target size of one uncompressed time chunk (64 MiB).
default_chunk_frames : frames per chunk for a frame shape.
write_frames : decode frames one at a time into a sweep store.
merge_frame_stores : join part stores (consecutive frame ranges) into one sweep store.
write_reference : decode and average reference frame(s) into a reference store.
open_frames : open a store lazily (xarray, no dask).
iter_frame_chunks : yield (start, (T_chunk, H, W, C) float32 block) in time order (optionally a frame range).
iter_store_frames : yield the (H, W, C) float32 frames one at a time (logging progress).
iter_store_luminance : yield the frames' (H, W) float32 luminance one at a time (a mosaic store's
    straight from the mosaic, without the colour image).
"""

import glob
import json
import logging
import os
import shutil
import warnings
from pathlib import Path

import numpy as np
import xarray as xr
from xarray.backends import BackendArray
from xarray.core import indexing
from zarr.codecs import BloscCodec, ZstdCodec

from shadowcam._shared.atomic import atomic_directory
from shadowcam._shared.progress import Progress
from shadowcam.io.decode import iter_frames, iter_mosaics, mosaic_image
from shadowcam.io.luminance import channel_mean, mosaic_luminance
from shadowcam.io.mosaic_chunks import MosaicChunks
from shadowcam.io.raw_mosaic import is_raw

log = logging.getLogger(__name__)

#: target uncompressed size of one time chunk
CHUNK_BYTES = 64 * 2**20
CHANNELS = ("R", "G", "B")
_COMPRESSORS = (ZstdCodec(level=1),)
_MOSAIC_COMPRESSORS = (BloscCodec(cname="lz4", clevel=9, shuffle="bitshuffle", typesize=2),)
#: mosaic pixels read beyond an indexed window (bilinear demosaic: 3x3 neighbourhoods)
_WINDOW_MARGIN = 2


def default_chunk_frames(frame_shape, *, itemsize=4, target_bytes=CHUNK_BYTES):
    """Return the number of frames whose data make about `target_bytes` (>= 1).

    Parameters
    ----------
    frame_shape : tuple of int
        Shape of one frame, e.g. ``(H, W, 3)``.
    itemsize : int, optional
        Bytes per value (4 for float32).
    target_bytes : int, optional
    """
    frame_bytes = int(np.prod(frame_shape)) * int(itemsize)
    if frame_bytes <= 0:
        raise ValueError(f"frame_shape must be positive; got {frame_shape}")
    return max(1, int(target_bytes) // frame_bytes)


def _decoder_attrs(info):
    return {
        "decoder": info["decoder"],
        "bit_depth": info["bit_depth"],
        "cfa_pattern": info["cfa_pattern"] or "",
        "black_level": info["black_level"],
        "white_level": info["white_level"],
        "white_balance_as_shot": info["white_balance"] or [],
        "white_balance_applied": 0,
        "normalisation": "linear; (value - black_level) / (white_level - black_level)",
    }


def _json_safe(attrs):
    out = {}
    for key, value in (attrs or {}).items():
        if isinstance(value, dict):
            value = json.dumps(value, sort_keys=True, default=str)
        out[str(key)] = value
    return out


def _image_attrs():
    return {"long_name": "linear image", "units": "1 (black = 0, white level = 1)"}


def _block_dataset(block, start, times_s, exposure_s, *, first_frame=0):
    """Dataset of a block of frames: `block` maps a variable name to ``(dims, array, attrs)``."""
    stop = start + next(iter(block.values()))[1].shape[0]
    frames = np.arange(first_frame + start, first_frame + stop, dtype=np.float64)
    return xr.Dataset(
        block,
        coords={
            "time": ("time", frames, {"units": "frame", "long_name": "frame index"}),
            "time_s": ("time", np.asarray(times_s[start:stop], dtype=np.float64), {"units": "s", "long_name": "frame time"}),
            "exposure_s": (
                "time",
                np.asarray(exposure_s[start:stop], dtype=np.float64),
                {"units": "s", "long_name": "exposure time"},
            ),
            "channel": ("channel", np.array(CHANNELS, dtype=object)),
        },
    )


def _frame_source(paths):
    """Frames of `paths` as ``(info, {variable: (dims, array, attrs)})``: mosaics of RAW sweeps, else float RGB."""
    if all(is_raw(p) for p in paths):
        mosaic_attrs = {"long_name": "Bayer mosaic", "units": "DN"}
        for _, mosaic, levels, info in iter_mosaics(paths):
            yield info, {"mosaic": (("time", "row", "col"), mosaic, mosaic_attrs),
                         "black_sites": (("time", "cfa_row", "cfa_col"), levels["black_sites"], {"units": "DN"}),
                         "white_sites": (("time", "cfa_row", "cfa_col"), levels["white_sites"], {"units": "DN"})}
    else:
        for _, image, info in iter_frames(paths):
            yield info, {"image": (("time", "row", "col", "channel"), image, _image_attrs())}


def _atomic_store(out_path):
    """Context manager: a temporary directory that replaces the ``.zarr`` store `out_path` on success."""
    out_path = Path(out_path)
    if out_path.suffix != ".zarr":
        raise ValueError(f"out_path must end with .zarr; got {out_path}")
    return atomic_directory(out_path)


def write_frames(paths, out_path, *, times_s, exposure_s=None, attrs=None, chunk_frames=None,
                 first_frame=0):
    """Decode frames one at a time into a time-chunked zarr v3 store.

    A sweep of camera RAW frames is stored as its mosaics and levels (read
    back demosaiced by :func:`open_frames`), other frames as float32 RGB.
    Memory stays bounded by one time chunk whatever the number of frames.
    Progress (frames done, rate, time left) is logged about every 5 s.

    Parameters
    ----------
    paths : sequence of str or Path
        Frame files in time order (all of the same size).
    out_path : str or Path
        Store to create (``*.zarr``); replaced if it exists. Written to a
        hidden temporary beside it first and renamed when complete.
    times_s : (T,) array_like of float
        Frame times in seconds.
    exposure_s : (T,) array_like of float, optional
        Exposure times in seconds; default: from each file's metadata (NaN if absent).
    attrs : mapping, optional
        Extra dataset attrs (e.g. provenance); dict values are stored as JSON.
    chunk_frames : int, optional
        Frames per time chunk; default: about :data:`CHUNK_BYTES` per chunk
        (at most the number of frames). When given, it is the store's chunk
        size even if the store holds fewer frames, so that part stores of
        one sweep share it (see :func:`merge_frame_stores`).
    first_frame : int, optional
        Frame index of ``paths[0]`` in the whole sweep (a part store); the
        ``time`` coordinate counts from it. Must be a multiple of
        `chunk_frames` so that the part's chunks are chunks of the sweep.

    Returns
    -------
    Path
        `out_path`.
    """
    paths = [Path(p) for p in paths]
    if not paths:
        raise ValueError("paths must list at least one frame")
    times_s = np.asarray(times_s, dtype=np.float64)
    if times_s.shape != (len(paths),):
        raise ValueError(f"times_s must have one value per frame ({len(paths)}); got shape {times_s.shape}")
    exposure_given = exposure_s is not None
    exposure = np.asarray(exposure_s, dtype=np.float64) if exposure_given else np.full(len(paths), np.nan)
    if exposure.shape != (len(paths),):
        raise ValueError(f"exposure_s must have one value per frame ({len(paths)}); got shape {exposure.shape}")
    if chunk_frames is not None and int(chunk_frames) < 1:
        raise ValueError(f"chunk_frames must be >= 1; got {chunk_frames}")
    first_frame = int(first_frame)
    if first_frame < 0 or (first_frame and (chunk_frames is None or first_frame % int(chunk_frames))):
        raise ValueError(
            f"first_frame must be >= 0 and a multiple of chunk_frames (given explicitly); "
            f"got first_frame={first_frame}, chunk_frames={chunk_frames}"
        )

    n = len(paths)
    progress = Progress(n, f"decode {Path(out_path).stem}")
    with _atomic_store(out_path) as tmp:
        block, start, written = None, 0, 0
        for k, (info, frame) in enumerate(_frame_source(paths)):
            if block is None:
                shape = next(iter(frame.values()))[1].shape
                chunk = int(chunk_frames) if chunk_frames else min(n, default_chunk_frames(shape + (3,)))
                block = {name: (dims, np.empty((min(n, chunk),) + np.shape(data), dtype=np.asarray(data).dtype), attrs)
                         for name, (dims, data, attrs) in frame.items()}
                store_attrs = {**_decoder_attrs(info), **_json_safe(attrs), "n_frames": n}
            if not exposure_given and info["exposure_s"] is not None:
                exposure[k] = info["exposure_s"]
            for name, (_, data, _) in frame.items():
                block[name][1][k - start] = data
            size = next(iter(block.values()))[1].shape[0]
            if k - start + 1 == size or k == n - 1:
                filled = {name: (dims, data[: k - start + 1], a) for name, (dims, data, a) in block.items()}
                ds = _block_dataset(filled, start, times_s, exposure, first_frame=first_frame)
                ds.attrs.update(store_attrs)  # appends rewrite the group attrs
                if start == 0:
                    encoding = {name: {"chunks": (chunk,) + data.shape[1:],
                                       "compressors": _MOSAIC_COMPRESSORS if name == "mosaic" else _COMPRESSORS}
                                for name, (_, data, _) in block.items()}
                    encoding.update({name: {"chunks": (chunk,)} for name in ("time", "time_s", "exposure_s")})
                    ds.to_zarr(tmp, mode="w-", zarr_format=3, encoding=encoding, consolidated=False)
                else:
                    ds.to_zarr(tmp, append_dim="time", zarr_format=3, consolidated=False)
                written = k + 1
                start = k + 1
            progress.update(k + 1)
    assert written == n
    return Path(out_path)


def _part_layout(path):
    """(first frame, frame count, chunk frames, frame shape) of a part store."""
    image = open_frames(path)["image"]
    if image.dims != ("time", "row", "col", "channel"):
        raise ValueError(f"parts: {path} is not a sweep store (image dims {image.dims})")
    times = image["time"].values
    first = int(times[0]) if times.size else 0
    if times.size and not np.array_equal(times, np.arange(first, first + times.size)):
        raise ValueError(f"parts: {path} holds non-consecutive frames")
    return first, int(times.size), int(image.encoding["chunks"][0]), tuple(image.shape[1:])


def _link(source, target):
    """Hard-link `source` to `target` (copy where the file system cannot link)."""
    target.parent.mkdir(parents=True, exist_ok=True)
    try:
        os.link(source, target)
    except OSError:
        shutil.copy2(source, target)


def _read_json(path):
    with open(path) as handle:
        return json.load(handle)


def _write_json(path, document):
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as handle:
        json.dump(document, handle, indent=2)


def merge_frame_stores(parts, out_path, *, attrs=None):
    """Join part stores of one sweep into a single sweep store, without copying data.

    Each part's compressed chunk files are hard-linked into the new store under
    their chunk index in the whole sweep, and the array metadata are those of
    the first part with the time length of the whole sweep. The result reads
    exactly like a store written by one :func:`write_frames` call over all frames
    with the same `chunk_frames` (same values, same chunk files). Written to
    a hidden temporary beside it and renamed when complete.

    Parameters
    ----------
    parts : sequence of str or Path
        Part stores from :func:`write_frames` (with ``first_frame``), in time
        order: the first starts at frame 0 (for a whole sweep) or on a chunk
        boundary, each starts where the previous ends, all share the chunk
        size and frame shape.
    out_path : str or Path
        Store to create (``*.zarr``); replaced if it exists. If the first part
        starts at frame F > 0 the result is itself a part store starting at F,
        which a later merge joins like any part (merges can be nested).
    attrs : mapping, optional
        Dataset attrs to set or replace (e.g. the merged provenance); ``n_frames``
        is set to the total. Other attrs are the first part's.

    Returns
    -------
    Path
        `out_path`.
    """
    parts = [Path(p) for p in parts]
    if not parts:
        raise ValueError("parts must list at least one part store")
    layouts = [_part_layout(p) for p in parts]
    chunk, shape = layouts[0][2], layouts[0][3]
    start = expected = layouts[0][0]
    for path, (first, count, part_chunk, part_shape) in zip(parts, layouts):
        if part_chunk != chunk or part_shape != shape:
            raise ValueError(
                f"parts: {path} has chunks of {part_chunk} frames of {part_shape} but {parts[0]} has "
                f"{chunk} of {shape}; decode every part with the same --chunk-frames"
            )
        if first != expected or first % chunk:
            raise ValueError(
                f"parts: {path} starts at frame {first}, expected {expected} (on a multiple of "
                f"{chunk}); list the parts in time order without gaps"
            )
        expected += count
    total = expected - start
    with _atomic_store(out_path) as tmp:
        group = _read_json(parts[0] / "zarr.json")
        group["attributes"] = {**group.get("attributes", {}), **_json_safe(attrs), "n_frames": total}
        _write_json(tmp / "zarr.json", group)
        for meta_path in sorted(parts[0].glob("*/zarr.json")):
            name = meta_path.parent.name
            meta = _read_json(meta_path)
            encoding = meta.get("chunk_key_encoding", {})
            if encoding.get("name") != "default" or encoding.get("configuration", {}).get("separator") != "/":
                raise ValueError(f"parts: {meta_path} uses chunk key encoding {encoding}; expected default '/'")
            along_time = (meta.get("dimension_names") or [None])[0] == "time"
            if along_time:
                meta["shape"][0] = total
            _write_json(tmp / name / "zarr.json", meta)
            for path, (first, *_rest) in zip(parts if along_time else parts[:1], layouts):
                offset = (first - start) // chunk if along_time else 0
                for source in sorted((path / name / "c").rglob("*")):
                    if source.is_file():
                        key = source.relative_to(path / name / "c").parts
                        index = (str(int(key[0]) + offset),) + key[1:]
                        _link(source, tmp.joinpath(name, "c", *index))
    log.info("merged %d part store(s), %d frames -> %s", len(parts), total, out_path)
    return Path(out_path)


def write_reference(paths, out_path, *, attrs=None):
    """Decode reference frame(s) and store their mean as ``image (row, col, channel)``.

    Parameters
    ----------
    paths : sequence of str or Path
        One or more unshadowed frames of the same size.
    out_path : str or Path
        Store to create (``*.zarr``), written atomically like :func:`write_frames`.
    attrs : mapping, optional
        Extra dataset attrs.

    Returns
    -------
    Path
    """
    paths = [Path(p) for p in paths]
    if not paths:
        raise ValueError("paths must list at least one reference frame")
    total, info = None, None
    for _, image, frame_info in iter_frames(paths):
        total = image.astype(np.float64) if total is None else total + image
        info = info or frame_info
    mean = (total / len(paths)).astype(np.float32)
    ds = xr.Dataset(
        {"image": (("row", "col", "channel"), mean, _image_attrs())},
        coords={"channel": ("channel", np.array(CHANNELS, dtype=object))},
        attrs={**_decoder_attrs(info), **_json_safe(attrs), "n_frames_averaged": len(paths)},
    )
    with _atomic_store(out_path) as tmp:
        ds.to_zarr(tmp, mode="w-", zarr_format=3, encoding={"image": {"compressors": _COMPRESSORS}}, consolidated=False)
    return Path(out_path)


def open_frames(path):
    """Open a frame store lazily (no data read until indexed; no dask).

    Parameters
    ----------
    path : str or Path
        A store written by :func:`write_frames` or :func:`write_reference`.

    Returns
    -------
    xarray.Dataset
        ``image (time, row, col, channel)`` (or ``(row, col, channel)`` for a reference);
        a mosaic store's ``image`` is demosaiced when indexed.
    """
    path = Path(path)
    if not path.is_dir():
        unfinished = any(path.parent.glob(f".{glob.escape(path.name)}.*.tmp"))
        hint = " (an unfinished write left a hidden temporary beside it)" if unfinished else ""
        raise ValueError(f"frame store {path} does not exist{hint}; rerun the decode step that writes it")
    with warnings.catch_warnings():
        # Snakemake marks directory outputs with a .snakemake_timestamp file, which zarr warns about
        warnings.filterwarnings("ignore", message=r"Object at \.snakemake_timestamp is not recognized")
        dataset = xr.open_zarr(path, chunks=None, zarr_format=3, consolidated=False)
    if "mosaic" not in dataset:
        return dataset
    mosaic = dataset["mosaic"]
    reader = MosaicChunks(path / "mosaic")  # one decompressed chunk shared by the image and the luminance
    image = _MosaicImage(mosaic.variable, reader, dataset["black_sites"].values, dataset["white_sites"].values,
                         dataset.attrs["cfa_pattern"])
    chunks = (mosaic.encoding["chunks"][0],) + image.shape[1:]
    variable = xr.Variable(("time", "row", "col", "channel"), indexing.LazilyIndexedArray(image),
                           attrs=_image_attrs(), encoding={"chunks": chunks})
    luminance = _MosaicImage(mosaic.variable, reader, dataset["black_sites"].values, dataset["white_sites"].values,
                             dataset.attrs["cfa_pattern"], luminance=True)
    luminance = xr.Variable(("time", "row", "col"), indexing.LazilyIndexedArray(luminance),
                            attrs={"long_name": "luminance (mean of R, G, B)", "units": _image_attrs()["units"]},
                            encoding={"chunks": chunks[:3]})
    return dataset.drop_vars(["mosaic", "black_sites", "white_sites"]).assign(image=variable, luminance=luminance)


def _local_index(index, origin):
    """`index` (1-D ints) relative to `origin`, as a slice where it is an increasing progression."""
    step = int(index[1] - index[0]) if index.size > 1 else 1
    if step > 0 and np.array_equal(index, index[0] + step * np.arange(index.size)):
        return slice(int(index[0] - origin), int(index[-1] - origin + 1), step)
    return index - origin


class _MosaicImage(BackendArray):
    """``image (time, row, col, channel)`` float32 of a mosaic store, demosaiced on indexing.

    An index reads the mosaic window of the indexed rows and cols, widened by
    :data:`_WINDOW_MARGIN` pixels and started on even rows and cols (the CFA
    phase), frame by frame from `chunks` (a :class:`shadowcam.io.mosaic_chunks.MosaicChunks`
    of the store; zarr reads the window where it cannot), demosaics it (:func:`shadowcam.io.decode.mosaic_image`) and crops it:
    the values of the whole frame's decode, bit for bit. With ``luminance=True``
    it is ``luminance (time, row, col)``, the mean of those channels computed
    from the mosaic directly (:func:`shadowcam.io.luminance.mosaic_luminance`, equal bit for bit).
    """

    def __init__(self, mosaic, chunks, black_sites, white_sites, cfa_pattern, *, luminance=False):
        self._mosaic, self._black, self._white, self._pattern = mosaic, black_sites, white_sites, cfa_pattern
        self._chunks = chunks
        self._luminance = luminance
        self.shape = tuple(mosaic.shape) + (() if luminance else (len(CHANNELS),))
        self.dtype = np.dtype(np.float32)

    def __getitem__(self, key):
        return indexing.explicit_indexing_adapter(key, self.shape, indexing.IndexingSupport.BASIC, self._getitem)

    def _getitem(self, key):
        picks = [np.arange(n)[k] for n, k in zip(self.shape, key)]
        out_shape = sum((p.shape for p in picks), ())
        times, rows, cols, channels = (np.atleast_1d(p) for p in picks + [np.zeros(1, int)] * self._luminance)
        if min(times.size, rows.size, cols.size, channels.size) == 0:
            return np.empty(out_shape, dtype=np.float32)
        height, width = self.shape[1:3]
        r0, c0 = (max(0, int(p.min()) - _WINDOW_MARGIN) // 2 * 2 for p in (rows, cols))
        r1, c1 = min(height, int(rows.max()) + 1 + _WINDOW_MARGIN), min(width, int(cols.max()) + 1 + _WINDOW_MARGIN)
        with self._chunks.lock:
            return self._convert(times, rows, cols, channels, out_shape, (r0, r1, c0, c1))

    def _convert(self, times, rows, cols, channels, out_shape, window):
        """The frames `times` of the mosaic window ``(r0, r1, c0, c1)`` demosaiced (or their luminance), cropped."""
        r0, r1, c0, c1 = window
        t0 = int(times.min())
        mosaics = None  # zarr's read of the whole window, only where the chunk files cannot be read directly
        local_rows, local_cols = _local_index(rows, r0), _local_index(cols, c0)
        whole = (isinstance(local_rows, slice) and isinstance(local_cols, slice)
                 and local_rows == slice(0, r1 - r0, 1) and local_cols == slice(0, c1 - c0, 1)
                 and (self._luminance or (channels.size == len(CHANNELS)
                                          and np.array_equal(channels, np.arange(len(CHANNELS))))))
        convert = mosaic_luminance if self._luminance else mosaic_image
        out = None
        for k, t in enumerate(times):
            mosaic = self._chunks.window(int(t), int(t) + 1, r0, r1, c0, c1)
            if mosaic is None:
                if mosaics is None:
                    mosaics = np.asarray(self._mosaic[t0:int(times.max()) + 1, r0:r1, c0:c1].values)
                mosaic = mosaics[t - t0]
            else:
                mosaic = mosaic[0]
            image = convert(mosaic, cfa_pattern=self._pattern, black_sites=self._black[t],
                            white_sites=self._white[t])
            if whole and times.size == 1:
                return image.reshape(out_shape)
            if out is None:
                out = np.empty((times.size, rows.size, cols.size) + (() if self._luminance else (channels.size,)),
                               dtype=np.float32)
            if whole:
                out[k] = image
            elif self._luminance:
                out[k] = image[local_rows][:, local_cols]
            else:
                out[k] = image[local_rows][:, local_cols][:, :, channels]
        return out.reshape(out_shape)


def iter_frame_chunks(dataset, *, chunk_frames=None, start=0, stop=None):
    """Yield blocks of consecutive frames, reading one chunk at a time.

    Parameters
    ----------
    dataset : xarray.Dataset
        With ``image (time, row, col, channel)`` (e.g. from :func:`open_frames`).
    chunk_frames : int, optional
        Frames per block; default: the store's time chunk (or about
        :data:`CHUNK_BYTES` for in-memory data).
    start, stop : int, optional
        Read only frames ``[start, stop)`` (`stop` clipped to the frame count;
        default: all).

    Yields
    ------
    start : int
        Index of the block's first frame.
    block : (T_chunk, H, W, C) float32 ndarray
    """
    if "image" not in dataset or dataset["image"].dims != ("time", "row", "col", "channel"):
        raise ValueError("dataset must have variable image with dims (time, row, col, channel)")
    image = dataset["image"]
    if chunk_frames is None:
        stored = image.encoding.get("chunks") or image.encoding.get("preferred_chunks", {}).get("time")
        chunk_frames = stored[0] if isinstance(stored, (tuple, list)) else stored
        chunk_frames = chunk_frames or default_chunk_frames(image.shape[1:])
    chunk_frames = int(chunk_frames)
    if chunk_frames < 1:
        raise ValueError(f"chunk_frames must be >= 1; got {chunk_frames}")
    n = image.sizes["time"]
    stop = n if stop is None else min(int(stop), n)
    if not 0 <= int(start) <= stop:
        raise ValueError(f"start must be in [0, {stop}] (frames {n}); got start={start}, stop={stop}")
    for first in range(int(start), stop, chunk_frames):
        block = image.isel(time=slice(first, min(first + chunk_frames, stop))).values
        yield first, np.asarray(block, dtype=np.float32)


def iter_store_frames(dataset, *, what="read frames"):
    """Yield the ``(H, W, C)`` float32 frames of `dataset` one at a time, in time order.

    Reads one chunk at a time (:func:`iter_frame_chunks`) and logs the progress
    of the pass (:class:`shadowcam._shared.progress.Progress`), naming it `what`.
    """
    progress = Progress(max(dataset.sizes["time"], 1), what)
    for start, block in iter_frame_chunks(dataset):
        for offset, frame in enumerate(block):
            yield frame
            progress.update(start + offset + 1)


def iter_store_luminance(dataset, *, what="read luminance"):
    """Yield the ``(H, W)`` float32 luminance (mean of R, G, B) of `dataset`'s frames one at a time.

    A mosaic store's ``luminance`` is read one time chunk at a time, straight
    from the mosaic (no colour image); other stores' colour frames are read
    (:func:`iter_store_frames`) and averaged over their channels. Either way
    the values are ``channel_mean`` of the frames :func:`iter_store_frames`
    yields, bit for bit. Logs the progress of the pass, naming it `what`.
    """
    if "luminance" not in dataset:
        for frame in iter_store_frames(dataset, what=what):
            yield channel_mean(frame)
        return
    luminance = dataset["luminance"]
    chunk_frames = int(luminance.encoding["chunks"][0])
    n = luminance.sizes["time"]
    progress = Progress(max(n, 1), what)
    for start in range(0, n, chunk_frames):
        block = luminance.isel(time=slice(start, min(start + chunk_frames, n))).values
        for offset, frame in enumerate(block):
            yield frame
            progress.update(start + offset + 1)
