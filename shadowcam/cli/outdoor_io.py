"""I/O shared by the outdoor command-line steps (not a step itself).

Offers
------
iter_frames : the frames of a frame store one at a time, read chunk by chunk.
input_checksums : merged ``input_checksums`` provenance of input datasets.
write_dataset : attach provenance and write a dataset as netCDF, atomically.
open_dataset : open a netCDF dataset written by a previous step (loaded).
read_attrs : its global attributes only (data not loaded).
"""

import json
import logging
from pathlib import Path

import xarray as xr

from shadowcam.io.frame_store import iter_frame_chunks
from shadowcam.io.images import write_netcdf
from shadowcam.io.provenance import attach_provenance

log = logging.getLogger(__name__)


def iter_frames(frames, *, progress_every=50):
    """Yield the ``(H, W, C)`` float32 frames of an opened frame store in time order."""
    n_frames = frames.sizes["time"]
    for start, block in iter_frame_chunks(frames):
        for offset, frame in enumerate(block):
            done = start + offset + 1
            if done % progress_every == 0 or done == n_frames:
                log.info("frame %d/%d", done, n_frames)
            yield frame


def input_checksums(*datasets):
    """Return the union of the ``input_checksums`` attrs of `datasets` (dict)."""
    merged = {}
    for dataset in datasets:
        merged.update(json.loads(dataset.attrs.get("input_checksums", "{}")))
    return merged


def write_dataset(dataset, path, *, config, checksums, step):
    """Attach provenance to `dataset` and write it to `path` (netCDF, atomic)."""
    dataset = attach_provenance(dataset, config=config, input_checksums=checksums, step=step)
    write_netcdf(dataset, Path(path))
    log.info("wrote %s", path)
    return dataset


def _existing(path):
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"input dataset {path} does not exist; run the step that makes it first")
    return path


def read_attrs(path):
    """Return the global attributes (dict) of a netCDF dataset of a previous step, data not loaded."""
    with xr.open_dataset(_existing(path), engine="h5netcdf") as source:
        return dict(source.attrs)


def open_dataset(path):
    """Open and load a netCDF dataset of a previous step; ValueError if missing."""
    with xr.open_dataset(_existing(path), engine="h5netcdf") as source:
        return source.load()
