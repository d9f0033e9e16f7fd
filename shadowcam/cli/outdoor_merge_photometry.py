"""``shadowcam outdoor-merge-photometry``: join the time parts of the first outdoor pass.

Reads the part datasets written by ``shadowcam outdoor-normalise --part``,
concatenates the per-frame shifts and gains and takes the per-pixel minimum
(:func:`shadowcam.outdoor_normalise.merge_parts`), then derives the lit and
shadow levels as the single job does. Writes ``results/<ds>/outdoor/photometry.nc``.

Offers
------
add_parser : register the step and its options.
run : merge and write the photometry dataset.
"""

import numpy as np

from shadowcam.cli.outdoor_io import input_checksums, open_dataset, write_dataset
from shadowcam.outdoor_datasets import photometry_dataset, photometry_part_arrays
from shadowcam.outdoor_normalise import merge_parts


def add_parser(subparsers, name):
    """Register ``outdoor-merge-photometry`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="merge the time parts of the first outdoor pass",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--parts", nargs="+", required=True, help="part datasets (any order)")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/outdoor/photometry.nc")
    return parser


def run(args):
    """Merge the parts and write the photometry dataset."""
    parts = sorted((open_dataset(path) for path in args.parts), key=lambda ds: int(ds.attrs["first_frame"]))
    merged = merge_parts([photometry_part_arrays(ds) for ds in parts])
    time_s = np.concatenate([ds["time_s"].values for ds in parts])
    exposure = np.concatenate([ds["exposure_gain"].values for ds in parts])
    sky_source = parts[0].attrs["sky_source"]
    dataset = photometry_dataset(merged, time_s, exposure_gain=None if np.isnan(exposure).all() else exposure,
                                 sky_source=sky_source)
    config = {"parts": [[int(ds.attrs["first_frame"]), int(ds.attrs["first_frame"]) + ds.sizes["time"]]
                        for ds in parts]}
    write_dataset(dataset, args.out, config=config, checksums=input_checksums(*parts),
                  step="outdoor-merge-photometry")
