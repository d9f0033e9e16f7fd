"""``shadowcam outdoor-normalise``: register a time-lapse and estimate its gains and levels.

First streaming pass over the frame store (:mod:`shadowcam.outdoor.normalise`):
sub-pixel shift of every frame to the first, lit and sky gains per frame, sky
mask (manifest ``sky_mask`` override, else automatic), per-pixel lit and
shadow levels. Writes ``results/<ds>/outdoor/photometry.nc``; with
``--part START:STOP`` only that time part (after its warm-up frames), to be
merged by ``shadowcam outdoor-merge-photometry``.

Offers
------
add_parser : register the step and its options.
sky_override : the manifest's sky mask, if any.
parse_part : START:STOP of a time part.
run : run the pass (or a part) and write the dataset.
"""

import numpy as np

from shadowcam.cli.options import parse_params
from shadowcam.io.datasets import write_dataset
from shadowcam.io.decode import read_frame
from shadowcam.io.frame_store import iter_store_frames, open_frames
from shadowcam.io.manifest import load_manifest, verify_checksums
from shadowcam.outdoor.datasets import photometry_dataset, photometry_part_dataset
from shadowcam.outdoor.normalise import normalise_frames, normalise_part, part_frames
from shadowcam.outdoor.photometric import exposure_gains
from shadowcam.outdoor.sky_mask import mask_from_image, polygon_mask


def add_parser(subparsers, name):
    """Register ``outdoor-normalise`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="register an outdoor time-lapse; gains, sky mask, levels",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--manifest", required=True, help="capture description (sky_mask, exposure keys)")
    parser.add_argument("--frames", required=True, help="frame store of the time-lapse sweep")
    parser.add_argument("--params", default="{}",
                        help="JSON: sky_params (automatic sky mask options), registration_size, registration_levels, "
                             "registration_margin, overlap (parts)")
    parser.add_argument("--part", default=None, help="START:STOP: process only these frames (a time part)")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/outdoor/photometry.nc")
    return parser


def sky_override(manifest, shape):
    """Return ``(mask, source)``: the manifest's sky mask override, or ``(None, "auto")``."""
    spec = manifest.get("sky_mask")
    if not spec:
        return None, "auto"
    if "polygon" in spec:
        return polygon_mask(spec["polygon"], shape), "manifest polygon"
    verify_checksums(manifest, ["sky_mask"])
    path = manifest["files"]["sky_mask"][0]
    image = read_frame(f"{manifest['root']}/{path}")
    return mask_from_image(image, shape), f"manifest image {path}"


def parse_part(text, n_frames):
    """Return ``(start, stop)`` of a ``START:STOP`` part of `n_frames` frames (``START:`` = to the end)."""
    try:
        start, stop = text.split(":")
        start, stop = int(start), (int(stop) if stop else n_frames)
    except ValueError:
        raise ValueError(f"--part must be START:STOP (frame indices); got {text!r}") from None
    if not 0 <= start < stop <= n_frames:
        raise ValueError(f"--part {text}: need 0 <= START < STOP <= {n_frames} (frames in the store)")
    return start, stop


def run(args):
    """Run the first outdoor pass (or one time part of it) and write the dataset."""
    params = parse_params(args.params, allowed={"sky_params", "registration_size", "registration_levels",
                                                "registration_margin", "overlap"})
    manifest = load_manifest(args.manifest)
    frames = open_frames(args.frames)
    shape = (frames.sizes["row"], frames.sizes["col"])
    sky, sky_source = sky_override(manifest, shape)
    exposure = None
    if manifest.get("exposure", {}).get("source", "metadata") == "metadata":
        exposure = exposure_gains(frames["exposure_s"].values)
        if not np.isfinite(exposure).any():
            exposure = None
    options = dict(sky=sky, exposure_gain=exposure, sky_params=params.get("sky_params"),
                   registration_size=params.get("registration_size", 1536),
                   registration_levels=params.get("registration_levels", 2),
                   registration_margin=params.get("registration_margin", 6))
    config = {"manifest": manifest["name"], "sky_source": sky_source, **params}
    time_s = frames["time_s"].values
    if args.part is None:
        result = normalise_frames(iter_store_frames(frames), **options)
        dataset = photometry_dataset(result, time_s, exposure_gain=exposure, sky_source=sky_source)
    else:
        start, stop = parse_part(args.part, frames.sizes["time"])
        overlap = int(params.get("overlap", 2))
        first, _ = part_frames(start, stop, overlap=overlap)
        reference = frames["image"].isel(time=0).values
        part = normalise_part(iter_store_frames(frames.isel(time=slice(first, stop))), start=start, stop=stop,
                              reference=reference, overlap=overlap, **options)
        dataset = photometry_part_dataset(part, time_s[start:stop], sky_source=sky_source,
                                          exposure_gain=None if exposure is None else exposure[start:stop])
        config["part"] = [start, stop]
    write_dataset(dataset, args.out, config=config, inputs=(frames,), step="outdoor-normalise")
