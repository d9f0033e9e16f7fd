"""``shadowcam outdoor-sample``: a real-size RAW time-lapse sample and its manifest.

Steadies consecutive frames of a small outdoor capture (e.g. dev_ridge; its
recorded shake from the ground truth undone), upsamples them to a camera's
size, shakes them by a seeded realistic amount (``--shake-px``, sub-pixel to
2 px), adds full-resolution sensor noise and writes 14-bit RGGB DNGs, a sidecar with
the frame times and the applied shake (``timestamps.json``: ``times_s``,
``shake_dx_px``, ``shake_dy_px``) and a checksummed ``kind: outdoor`` manifest
(:func:`shadowcam.synthetic.outdoor.sample.write_sample`), for throughput, memory and
registration (against the recorded shake) measurements on a real capture's frames made
large. No arrival-time ground truth at that size: ``make bench-outdoor-size`` renders
the scene at its real size instead (``synthetic.outdoor.window``).

Example::

    shadowcam outdoor-sample --source data_manifest/dev_ridge.yaml --size 6000x4000 --frames 16 \\
        --name bench16 --outdir /tmp/bench/data/bench16 --manifest-out /tmp/bench/data_manifest/bench16.yaml

Offers
------
add_parser : register the step and its options.
run : write the sample and print the manifest path.
"""

from pathlib import Path

from shadowcam.io.manifest import load_manifest
from shadowcam.synthetic.outdoor.sample import write_sample


def add_parser(subparsers, name):
    """Register ``outdoor-sample`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="write a real-size DNG time-lapse sample (benchmarks)")
    parser.add_argument("--source", required=True, help="manifest of a small outdoor capture (data_manifest/dev_ridge.yaml)")
    parser.add_argument("--size", default="6000x4000", help="COLSxROWS of the sample (default 6000x4000 = 24 MP)")
    parser.add_argument("--frames", type=int, default=16, help="number of frames")
    parser.add_argument("--first", type=int, default=40, help="first source frame used")
    parser.add_argument("--bit-depth", type=int, default=14, help="sensor bit depth, bits")
    parser.add_argument("--seed", type=int, default=0, help="noise and shake seed")
    parser.add_argument("--shake-px", type=float, default=2.0,
                        help="largest camera shake of the sample, pixels (0: none; default 2)")
    parser.add_argument("--compression", choices=("ljpeg", "none"), default="ljpeg",
                        help="DNG compression: lossless JPEG as cameras write (default) or none")
    parser.add_argument("--name", required=True, help="dataset name")
    parser.add_argument("--outdir", required=True, help="directory of the frames (root of the new dataset)")
    parser.add_argument("--manifest-out", required=True, help="manifest to write, e.g. <workdir>/data_manifest/<name>.yaml")
    return parser


def run(args):
    """Write the sample frames, timestamps and manifest."""
    write_sample(load_manifest(args.source), args.outdir, args.manifest_out, name=args.name, size=args.size,
                 frames=args.frames, first=args.first, bit_depth=args.bit_depth, seed=args.seed,
                 shake_px=args.shake_px, source_label=str(args.source),
                 compression=args.compression)
    print(Path(args.manifest_out))
