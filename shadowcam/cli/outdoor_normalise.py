"""``shadowcam outdoor-normalise``: register a time-lapse and estimate its gains and levels.

First streaming pass over the frame store (:func:`shadowcam.outdoor.photometry.photometry_from_frames`):
sub-pixel shift of every frame to the first, lit and sky gains per frame, sky
mask (``--sky``: the sweep's, ``shadowcam outdoor-sky-mask``; else the manifest
``sky_mask`` override, else automatic), per-pixel lit and
shadow levels. Writes ``results/<ds>/outdoor/photometry.nc``; with
``--part START:STOP`` only that time part (after its warm-up frames), to be
merged by ``shadowcam outdoor-merge-photometry``.

Example::

    shadowcam outdoor-normalise --manifest data_manifest/dev_ridge.yaml \\
        --frames results/dev_ridge/frames/timelapse.zarr --out results/dev_ridge/outdoor/photometry.nc

Offers
------
add_parser : register the step and its options.
run : run the pass (or a part) and write the dataset.
"""

from shadowcam.cli.options import parse_params, parse_part
from shadowcam.io.datasets import open_dataset, write_dataset
from shadowcam.io.frame_store import open_frames
from shadowcam.io.manifest import load_manifest
from shadowcam.outdoor.photometry import PHOTOMETRY_OPTIONS, photometry_from_frames, sky_mask_from_manifest


def add_parser(subparsers, name):
    """Register ``outdoor-normalise`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="register an outdoor time-lapse; gains, sky mask, levels")
    parser.add_argument("--manifest", required=True, help="capture description (sky_mask, exposure keys)")
    parser.add_argument("--frames", required=True, help="frame store of the time-lapse sweep")
    parser.add_argument("--params", default="{}",
                        help="JSON: sky_params (automatic sky mask options), registration_size, registration_levels, "
                             "registration_margin, overlap (parts)")
    parser.add_argument("--sky", default=None,
                        help="the sweep's sky mask (shadowcam outdoor-sky-mask); default: the manifest's or automatic")
    parser.add_argument("--part", default=None, help="START:STOP: process only these frames (a time part)")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/outdoor/photometry.nc")
    return parser


def run(args):
    """Run the first outdoor pass (or one time part of it) and write the dataset."""
    params = parse_params(args.params, allowed=PHOTOMETRY_OPTIONS)
    manifest = load_manifest(args.manifest)
    frames = open_frames(args.frames)
    if args.sky is None:
        sky, sky_source = sky_mask_from_manifest(manifest, (frames.sizes["row"], frames.sizes["col"]))
    else:
        mask = open_dataset(args.sky)
        sky, sky_source = mask["sky_mask"].values.astype(bool), mask.attrs["sky_source"]
    part = None if args.part is None else parse_part(args.part, frames.sizes["time"])
    dataset = photometry_from_frames(
        frames, sky=sky, sky_source=sky_source, part=part, **params,
        exposure_metadata=manifest.get("exposure", {}).get("source", "metadata") == "metadata")
    config = {"manifest": manifest["name"], "sky_source": sky_source, **params}
    if part is not None:
        config["part"] = list(part)
    write_dataset(dataset, args.out, config=config, inputs=(frames,), step="outdoor-normalise")
