"""``shadowcam outdoor-merge-photometry``: join the time parts of the first outdoor pass.

Reads the part datasets written by ``shadowcam outdoor-normalise --part``,
concatenates the per-frame shifts and gains and takes the per-pixel minimum
(:func:`shadowcam.outdoor.photometry.merge_photometry_parts`), then derives the lit and
shadow levels as the single job does. Parts are read one at a time (ordered by
their ``first_frame`` attribute, read without loading the data), so memory does
not grow with their number. Writes ``results/<ds>/outdoor/photometry.nc``.

Example::

    shadowcam outdoor-merge-photometry --parts results/dev_ridge/outdoor/photometry.part0.nc \\
        results/dev_ridge/outdoor/photometry.part1.nc --out results/dev_ridge/outdoor/photometry.nc

Offers
------
add_parser : register the step and its options.
run : merge and write the photometry dataset.
"""

from shadowcam.io.datasets import open_dataset, read_attrs, write_dataset
from shadowcam.outdoor.photometry import merge_photometry_parts


def add_parser(subparsers, name):
    """Register ``outdoor-merge-photometry`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="merge the time parts of the first outdoor pass")
    parser.add_argument("--parts", nargs="+", required=True, help="part datasets (any order)")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/outdoor/photometry.nc")
    return parser


def run(args):
    """Merge the parts and write the photometry dataset."""
    paths = sorted(args.parts, key=lambda path: int(read_attrs(path)["first_frame"]))
    dataset, ranges, checksums = merge_photometry_parts(open_dataset(path) for path in paths)
    write_dataset(dataset, args.out, config={"parts": ranges}, checksums=checksums, step="outdoor-merge-photometry")
