"""``shadowcam outdoor-merge-photometry``: join the time parts of the first outdoor pass.

Reads the part datasets written by ``shadowcam outdoor-normalise --part``,
concatenates the per-frame shifts and gains and takes the per-pixel minimum
(:class:`shadowcam.outdoor.normalise.PartMerger`), then derives the lit and
shadow levels as the single job does. Parts are read one at a time (ordered by
their ``first_frame`` attribute, read without loading the data), so memory does
not grow with their number. Writes ``results/<ds>/outdoor/photometry.nc``.

Offers
------
add_parser : register the step and its options.
run : merge and write the photometry dataset.
"""

import numpy as np

from shadowcam.io.datasets import merge_input_checksums, open_dataset, read_attrs, write_dataset
from shadowcam.outdoor.datasets import photometry_dataset, photometry_part_arrays
from shadowcam.outdoor.normalise import PartMerger


def add_parser(subparsers, name):
    """Register ``outdoor-merge-photometry`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="merge the time parts of the first outdoor pass",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--parts", nargs="+", required=True, help="part datasets (any order)")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/outdoor/photometry.nc")
    return parser


def run(args):
    """Merge the parts and write the photometry dataset."""
    paths = sorted(args.parts, key=lambda path: int(read_attrs(path)["first_frame"]))
    merger = PartMerger()
    time_s, exposure, ranges, checksums, sky_source = [], [], [], {}, None
    for path in paths:
        part = open_dataset(path)
        merger.add(photometry_part_arrays(part))
        time_s.append(part["time_s"].values)
        exposure.append(part["exposure_gain"].values)
        first = int(part.attrs["first_frame"])
        ranges.append([first, first + part.sizes["time"]])
        checksums.update(merge_input_checksums(part))
        sky_source = sky_source or part.attrs["sky_source"]
        del part
    time_s, exposure = np.concatenate(time_s), np.concatenate(exposure)
    dataset = photometry_dataset(merger.result(), time_s,
                                 exposure_gain=None if np.isnan(exposure).all() else exposure, sky_source=sky_source)
    write_dataset(dataset, args.out, config={"parts": ranges}, checksums=checksums, step="outdoor-merge-photometry")
