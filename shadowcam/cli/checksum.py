"""``shadowcam checksum``: print the ``checksums:`` block of a manifest.

Declaring a capture: write ``data_manifest/<name>.yaml`` without (or with a
stale) ``checksums`` block, run ``shadowcam checksum --manifest <it>``, paste
the printed block into the file.

Example::

    shadowcam checksum --manifest data_manifest/my_capture.yaml

Offers
------
add_parser : register the step and its options.
run : compute and print the block.
"""

from shadowcam.io.manifest import checksums_for, format_checksums


def add_parser(subparsers, name):
    """Register ``checksum`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(
        name,
        help="print the sha256 checksums block for a manifest",
    )
    parser.add_argument("--manifest", required=True, help="data_manifest/<name>.yaml (or capture.json)")
    return parser


def run(args):
    """Print the ``checksums:`` YAML block of ``args.manifest`` to stdout."""
    print(format_checksums(checksums_for(args.manifest)), end="")
