"""``shadowcam lightfield-shadow-times``: where the wire's shadow crosses each pixel of one sweep.

Streams the HDR stack through the lab wing's dip tracker and turns each pixel's shadow
time (frames) into the mask position of the wire (mm, ``start_mm + step_mm * time``
from ``capture.json``) (:func:`shadowcam.lightfield.stages.sweep_dataset`).

Example::

    shadowcam lightfield-shadow-times --hdr results/synthetic_lightfield/lightfield/hdr/near_h.npy \\
        --capture results/synthetic_lightfield/lightfield/capture \\
        --out results/synthetic_lightfield/lightfield/shadow_times/near_h.nc

Offers
------
add_parser : register the step and its options.
run : estimate and write the sweep's mask positions.
"""

from shadowcam.io.datasets import write_dataset
from shadowcam.lightfield.stages import read_description, sweep_dataset


def add_parser(subparsers, name):
    """Register ``lightfield-shadow-times`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="mask positions of one light-field sweep")
    parser.add_argument("--hdr", required=True, help="HDR stack of lightfield-hdr (.npy)")
    parser.add_argument("--capture", required=True, help="capture folder with capture.json")
    parser.add_argument("--out", required=True, help="output netCDF")
    return parser


def run(args):
    """Estimate the sweep's mask positions."""
    mask = read_description(args.capture)["mask"]
    dataset = sweep_dataset(args.hdr, mask_start=mask["start_mm"], mask_step=mask["step_mm"])
    write_dataset(dataset, args.out, config={"mask": mask}, step="lightfield-shadow-times")
