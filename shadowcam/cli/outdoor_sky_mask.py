"""``shadowcam outdoor-sky-mask``: the sky mask of an outdoor sweep, once for all its time parts.

The manifest's ``sky_mask`` override, else the automatic mask of the first frame
(:func:`shadowcam.outdoor.photometry.sweep_sky_mask`), with the first pass's
``sky_params``. Every time part of the first pass reads it
(``shadowcam outdoor-normalise --sky``) instead of computing it again.

Example::

    shadowcam outdoor-sky-mask --manifest data_manifest/dev_ridge.yaml \\
        --frames results/dev_ridge/frames/timelapse.zarr --out results/dev_ridge/outdoor/sky_mask.nc

Offers
------
add_parser : register the step and its options.
run : compute the mask and write the dataset.
"""

from shadowcam.cli.options import parse_params
from shadowcam.io.datasets import write_dataset
from shadowcam.io.frame_store import open_frames
from shadowcam.io.manifest import load_manifest
from shadowcam.outdoor.datasets import sky_mask_dataset
from shadowcam.outdoor.photometry import PHOTOMETRY_OPTIONS, sweep_sky_mask


def add_parser(subparsers, name):
    """Register ``outdoor-sky-mask`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="sky mask of an outdoor sweep (read by every first-pass part)")
    parser.add_argument("--manifest", required=True, help="capture description (sky_mask override)")
    parser.add_argument("--frames", required=True, help="frame store of the time-lapse sweep")
    parser.add_argument("--params", default="{}", help="JSON: the first pass's options (sky_params is used)")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/outdoor/sky_mask.nc")
    return parser


def run(args):
    """Compute the sweep's sky mask and write it."""
    params = parse_params(args.params, allowed=PHOTOMETRY_OPTIONS)
    manifest = load_manifest(args.manifest)
    frames = open_frames(args.frames)
    mask, source = sweep_sky_mask(frames, manifest, sky_params=params.get("sky_params"))
    write_dataset(sky_mask_dataset(mask, source=source), args.out,
                  config={"manifest": manifest["name"], "sky_params": params.get("sky_params") or {}},
                  inputs=(frames,), step="outdoor-sky-mask")
