"""Datasets on disk: the one netCDF writer and reader of every pipeline step.

A step's output dataset carries provenance (:mod:`shadowcam.io.provenance`):
its parameters and the checksums of every file it depends on. The checksums
of an input dataset's own inputs are carried forward, so the final products
name every raw file they came from.

Offers
------
merge_input_checksums : union of the ``input_checksums`` attrs of input datasets (and extra checksums).
write_dataset : attach provenance once and write a dataset as netCDF, atomically.
write_netcdf : write a dataset as netCDF-4 (engine h5netcdf) atomically, attrs as they are.
open_dataset : open and load a netCDF dataset of a previous step.
read_attrs : the global attributes of such a dataset, data not loaded.
"""

import json
import logging
from collections.abc import Mapping
from pathlib import Path

import xarray as xr

from shadowcam._shared.atomic import atomic_path
from shadowcam.io.provenance import attach_provenance

log = logging.getLogger(__name__)


def _attrs_of(source):
    # an xarray.Dataset is itself a Mapping (of its variables): test for attrs first
    if hasattr(source, "attrs"):
        return source.attrs
    if isinstance(source, Mapping):
        return source
    raise ValueError(f"inputs: expected datasets or attribute mappings, got {type(source).__name__}")


def merge_input_checksums(*inputs, checksums=None):
    """Return the union of the ``input_checksums`` of `inputs`, then `checksums`.

    Parameters
    ----------
    *inputs : xarray.Dataset or mapping
        Input datasets (or their attrs); a missing ``input_checksums`` attr counts as empty.
    checksums : mapping of str to str, optional
        Further file name -> sha256 entries (e.g. of the input files themselves), applied last.

    Returns
    -------
    dict
        File name -> sha256.
    """
    merged = {}
    for source in inputs:
        merged.update(json.loads(_attrs_of(source).get("input_checksums", "{}")))
    merged.update(checksums or {})
    return merged


def write_netcdf(dataset, path):
    """Write `dataset` to `path` as netCDF-4 (engine h5netcdf) atomically, attrs unchanged."""
    with atomic_path(path) as tmp:
        dataset.to_netcdf(tmp, engine="h5netcdf")


def write_dataset(dataset, path, *, config=None, inputs=(), checksums=None, step=None):
    """Attach provenance to `dataset` and write it to `path` (netCDF, atomic).

    Parameters
    ----------
    dataset : xarray.Dataset
    path : str or Path
        Output file; its folder is created.
    config : mapping, optional
        Parameters of the step (stored as JSON and digest).
    inputs : sequence of xarray.Dataset or mapping, optional
        Input datasets whose ``input_checksums`` are carried forward.
    checksums : mapping of str to str, optional
        Checksums of further input files, merged after those of `inputs`.
    step : str, optional
        Name of the pipeline step.

    Returns
    -------
    xarray.Dataset
        The dataset as written (with provenance attrs).
    """
    dataset = attach_provenance(dataset, config=config, step=step,
                                input_checksums=merge_input_checksums(*inputs, checksums=checksums))
    write_netcdf(dataset, Path(path))
    log.info("wrote %s", path)
    return dataset


def _existing(path):
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"input dataset {path} does not exist; run the step that makes it first")
    return path


def read_attrs(path):
    """Return the global attributes (dict) of the netCDF dataset at `path`, data not loaded."""
    with xr.open_dataset(_existing(path), engine="h5netcdf") as source:
        return dict(source.attrs)


def open_dataset(path):
    """Open and load the netCDF dataset at `path` (ValueError naming it if missing)."""
    with xr.open_dataset(_existing(path), engine="h5netcdf") as source:
        return source.load()
