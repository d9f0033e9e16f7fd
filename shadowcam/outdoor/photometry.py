"""The first outdoor pass on a frame store: the photometry dataset, whole or in time parts.

Registers a time-lapse to its first frame and estimates its per-frame gains,
sky mask and per-pixel lit and shadow levels (:mod:`shadowcam.outdoor.normalise`),
as one streaming job or as time parts merged afterwards (equal to one job).

Offers
------
PHOTOMETRY_OPTIONS : options of :func:`photometry_from_frames`.
sky_mask_from_manifest : the manifest's sky mask override (polygon or image), if any.
sweep_sky_mask : the sky mask of a sweep, once for all its time parts (override, else automatic).
photometry_from_frames : frame store -> photometry dataset (or the dataset of one time part).
merge_photometry_parts : the part datasets -> the photometry dataset of the whole sweep.
"""

import numpy as np

from shadowcam.io.datasets import merge_input_checksums
from shadowcam.io.decode import read_frame
from shadowcam.io.frame_store import iter_store_luminance
from shadowcam.io.manifest import verify_checksums
from shadowcam.outdoor.datasets import (
    photometry_dataset, photometry_part_arrays, photometry_part_dataset,
)
from shadowcam.outdoor.clipping import store_white_level
from shadowcam.outdoor.normalise import PartMerger, normalise_frames, normalise_part, part_frames
from shadowcam.outdoor.photometric import exposure_gains
from shadowcam.outdoor.sky_mask import auto_sky_mask, mask_from_image, polygon_mask

PHOTOMETRY_OPTIONS = frozenset({"sky_params", "registration_size", "registration_levels",
                                "registration_margin", "overlap", "clipping"})


def sky_mask_from_manifest(manifest, shape):
    """Return ``(mask, source)``: the manifest's ``sky_mask`` override, or ``(None, "auto")``.

    Parameters
    ----------
    manifest : mapping
        Loaded manifest; ``sky_mask`` holds a ``polygon`` or names a mask image in
        ``files.sky_mask`` (its checksum is verified).
    shape : (int, int)
        ``(rows, cols)`` of the frames.
    """
    spec = manifest.get("sky_mask")
    if not spec:
        return None, "auto"
    if "polygon" in spec:
        return polygon_mask(spec["polygon"], shape), "manifest polygon"
    verify_checksums(manifest, ["sky_mask"])
    path = manifest["files"]["sky_mask"][0]
    image = read_frame(f"{manifest['root']}/{path}")
    return mask_from_image(image, shape), f"manifest image {path}"


def sweep_sky_mask(frames, manifest, *, sky_params=None):
    """The sky mask of a sweep: the manifest's override, else automatic on its first frame.

    Computed once per sweep, it is what every time part of the first pass uses
    (:func:`photometry_from_frames` ``sky``): the same mask the pass would compute from
    the same first frame.

    Parameters
    ----------
    frames : xarray.Dataset
        Frame store (``image (time, row, col, channel)``).
    manifest : mapping
        Loaded manifest (its ``sky_mask`` override, if any).
    sky_params : dict, optional
        Options of :func:`shadowcam.outdoor.sky_mask.auto_sky_mask`.

    Returns
    -------
    mask : (rows, cols) bool ndarray
    source : str
        ``"auto"`` or the override's source.
    """
    mask, source = sky_mask_from_manifest(manifest, (frames.sizes["row"], frames.sizes["col"]))
    if mask is None:
        first = np.asarray(frames["image"].isel(time=0).values, dtype=np.float32)
        mask = auto_sky_mask(first, **dict(sky_params or {}))
    return np.asarray(mask, dtype=bool), source


def _pass_frames(frames, first, stop, *, what):
    """Frames ``first .. stop - 1`` as the pass reads them: frame 0 in colour, the others' luminance."""
    if first == 0:
        yield np.asarray(frames["image"].isel(time=0).values, dtype=np.float32)
        first = 1
    yield from iter_store_luminance(frames.isel(time=slice(first, stop)), what=what)


def photometry_from_frames(frames, *, sky=None, sky_source="auto", exposure_metadata=True, part=None,
                           **options):
    """Run the first outdoor pass over a frame store.

    Parameters
    ----------
    frames : xarray.Dataset
        Frame store (``image (time, row, col, channel)``, coords ``time_s``, ``exposure_s``).
    sky : (rows, cols) bool ndarray, optional
        Sky mask override (default: automatic).
    sky_source : str
        How the sky mask was obtained (stored as attr).
    exposure_metadata : bool
        Divide by the exposure gains of the frames' ExposureTime metadata (when any is known).
    part : (int, int), optional
        ``(start, stop)``: only this time part (read with its warm-up frames), to be merged by
        :func:`merge_photometry_parts`.
    **options
        :data:`PHOTOMETRY_OPTIONS`; ``clipping`` (default True): the frame store's white level
        (:func:`shadowcam.outdoor.clipping.store_white_level`) marks clipped samples
        (:class:`shadowcam.outdoor.normalise.SequenceNormaliser` ``white_level``).

    Returns
    -------
    xarray.Dataset
        :func:`shadowcam.outdoor.datasets.photometry_dataset` (or ``photometry_part_dataset``).
    """
    unknown = set(options) - PHOTOMETRY_OPTIONS
    if unknown:
        raise ValueError(f"options: unknown {sorted(unknown)}; allowed {sorted(PHOTOMETRY_OPTIONS)}")
    exposure = None
    if exposure_metadata:
        exposure = exposure_gains(frames["exposure_s"].values)
        if not np.isfinite(exposure).any():
            exposure = None
    pass_options = dict(sky=sky, exposure_gain=exposure, sky_params=options.get("sky_params"),
                        registration_size=options.get("registration_size", 1536),
                        registration_levels=options.get("registration_levels", 2),
                        registration_margin=options.get("registration_margin", 6),
                        white_level=store_white_level(frames) if options.get("clipping", True) else None)
    time_s = frames["time_s"].values
    if part is None:
        result = normalise_frames(_pass_frames(frames, 0, frames.sizes["time"], what="registration and gains"),
                                  **pass_options)
        return photometry_dataset(result, time_s, exposure_gain=exposure, sky_source=sky_source)
    start, stop = part
    if not 0 <= start < stop <= frames.sizes["time"]:
        raise ValueError(f"part: need 0 <= start < stop <= {frames.sizes['time']}; got {part}")
    overlap = int(options.get("overlap", 2))
    first, _ = part_frames(start, stop, overlap=overlap)
    reference = frames["image"].isel(time=0).values
    stream = _pass_frames(frames, first, stop, what=f"registration and gains {start}:{stop}")
    result = normalise_part(stream, start=start, stop=stop, reference=reference, overlap=overlap, **pass_options)
    return photometry_part_dataset(result, time_s[start:stop], sky_source=sky_source,
                                   exposure_gain=None if exposure is None else exposure[start:stop])


def merge_photometry_parts(parts):
    """Merge the time parts of the first pass into the photometry dataset of the whole sweep.

    Parameters
    ----------
    parts : iterable of xarray.Dataset
        :func:`photometry_from_frames` part datasets in time order (read one at a time;
        memory does not grow with their number).

    Returns
    -------
    dataset : xarray.Dataset
    ranges : list of [int, int]
        Frame range of every part.
    checksums : dict
        The parts' merged ``input_checksums``.
    """
    merger = PartMerger()
    time_s, exposure, ranges, checksums, sky_source = [], [], [], {}, None
    for part in parts:
        merger.add(photometry_part_arrays(part))
        time_s.append(part["time_s"].values)
        exposure.append(part["exposure_gain"].values)
        first = int(part.attrs["first_frame"])
        ranges.append([first, first + part.sizes["time"]])
        checksums.update(merge_input_checksums(part))
        sky_source = sky_source or part.attrs["sky_source"]
        del part
    if not ranges:
        raise ValueError("parts: no part datasets given")
    time_s, exposure = np.concatenate(time_s), np.concatenate(exposure)
    dataset = photometry_dataset(merger.result(), time_s, sky_source=sky_source,
                                 exposure_gain=None if np.isnan(exposure).all() else exposure)
    return dataset, ranges, checksums
