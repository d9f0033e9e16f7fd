"""``shadowcam outdoor-normalise``: register a time-lapse and estimate its gains and levels.

First streaming pass over the frame store (:mod:`shadowcam.outdoor_normalise`):
sub-pixel shift of every frame to the first, lit and sky gains per frame, sky
mask (manifest ``sky_mask`` override, else automatic), per-pixel lit and
shadow levels. Writes ``results/<ds>/outdoor/photometry.nc``.

Offers
------
add_parser : register the step and its options.
run : run the pass and write the dataset.
"""

import numpy as np

from shadowcam.cli.options import parse_params
from shadowcam.cli.outdoor_io import input_checksums, iter_frames, write_dataset
from shadowcam.decode import read_frame
from shadowcam.frame_store import open_frames
from shadowcam.manifest import load_manifest, verify_checksums
from shadowcam.outdoor_datasets import photometry_dataset
from shadowcam.outdoor_normalise import normalise_frames
from shadowcam.photometric import exposure_gains
from shadowcam.sky_mask import mask_from_image, polygon_mask


def add_parser(subparsers, name):
    """Register ``outdoor-normalise`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="register an outdoor time-lapse; gains, sky mask, levels",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--manifest", required=True, help="capture description (sky_mask, exposure keys)")
    parser.add_argument("--frames", required=True, help="frame store of the time-lapse sweep")
    parser.add_argument("--params", default="{}", help="JSON: sky_params (automatic sky mask options)")
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


def run(args):
    """Run the first outdoor pass and write the photometry dataset."""
    params = parse_params(args.params, allowed={"sky_params"})
    manifest = load_manifest(args.manifest)
    frames = open_frames(args.frames)
    shape = (frames.sizes["row"], frames.sizes["col"])
    sky, sky_source = sky_override(manifest, shape)
    exposure = None
    if manifest.get("exposure", {}).get("source", "metadata") == "metadata":
        exposure = exposure_gains(frames["exposure_s"].values)
        if not np.isfinite(exposure).any():
            exposure = None
    result = normalise_frames(iter_frames(frames), sky=sky, exposure_gain=exposure,
                              sky_params=params.get("sky_params"))
    dataset = photometry_dataset(result, frames["time_s"].values, exposure_gain=exposure, sky_source=sky_source)
    config = {"manifest": manifest["name"], "sky_source": sky_source, **params}
    write_dataset(dataset, args.out, config=config, checksums=input_checksums(frames), step="outdoor-normalise")
