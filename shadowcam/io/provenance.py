"""Provenance: file checksums, config digests and dataset attributes.

Offers
------
file_sha256 : hex sha256 of a file, streamed.
config_digest : short stable digest of a JSON-serialisable config mapping.
attach_provenance : copy of an xarray Dataset with provenance attrs set.
"""

import hashlib
import json
from pathlib import Path

from shadowcam import __version__

_BLOCK = 1 << 20


def file_sha256(path):
    """Return the hex sha256 digest of the file at `path` (streamed, bounded memory)."""
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(_BLOCK), b""):
            digest.update(block)
    return digest.hexdigest()


def config_digest(config):
    """Return a 16-hex-digit digest of `config` (key order does not matter)."""
    text = json.dumps(config, sort_keys=True, default=str, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def attach_provenance(dataset, *, config=None, input_checksums=None, step=None):
    """Return `dataset` with provenance attributes added.

    Parameters
    ----------
    dataset : xarray.Dataset
    config : mapping, optional
        Parameters that produced the dataset; stored as JSON and as a digest.
    input_checksums : mapping of str to str, optional
        Input file name -> sha256; stored as JSON.
    step : str, optional
        Name of the pipeline step that produced the dataset.

    Returns
    -------
    xarray.Dataset
        A shallow copy with attrs ``shadowcam_version``, ``config_digest``,
        ``config``, ``input_checksums`` and ``step``.
    """
    out = dataset.copy()
    config = dict(config or {})
    out.attrs.update(
        shadowcam_version=__version__,
        config_digest=config_digest(config),
        config=json.dumps(config, sort_keys=True, default=str),
        input_checksums=json.dumps(
            {str(Path(k)): v for k, v in sorted((input_checksums or {}).items())}
        ),
    )
    if step is not None:
        out.attrs["step"] = step
    return out
