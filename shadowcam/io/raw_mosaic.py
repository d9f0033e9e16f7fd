"""Camera RAW files through rawpy (LibRaw): which files are RAW, and their Bayer mosaic.

Offers
------
RAW_EXTENSIONS : file-name suffixes decoded with rawpy.
is_raw : whether a path is decoded as camera RAW.
check_frame_path : the path of a frame file that must exist.
read_mosaic : a RAW frame's Bayer mosaic (uint16) and per-site black / white levels.
"""

from pathlib import Path

import numpy as np

from shadowcam.io.cfa import bayer_pattern

#: file-name suffixes (lower case) decoded as camera RAW with rawpy
RAW_EXTENSIONS = frozenset(
    ".dng .cr2 .cr3 .crw .nef .nrw .arw .srf .sr2 .raf .orf .rw2 .rwl .pef "
    ".srw .3fr .iiq .erf .kdc .dcr .mef .mos .mrw .x3f .raw".split()
)


def is_raw(path):
    """Return True if `path` is decoded as camera RAW (by its suffix)."""
    return Path(path).suffix.lower() in RAW_EXTENSIONS


def check_frame_path(path):
    """Return `path` as a Path; raise ValueError naming it if the file does not exist."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"frame file {path} does not exist (check the manifest's root and file globs)")
    return path

def _white_balance_rgb(multipliers):
    """rawpy 4-entry multipliers (R, G, B, G2; 0 = same as G) -> [R, G, B] with G = 1."""
    mult = [float(m) for m in multipliers]
    if len(mult) < 3 or mult[1] <= 0:
        return None
    return [mult[0] / mult[1], 1.0, mult[2] / mult[1]]

def read_mosaic(path):
    """Read a camera RAW file's visible Bayer mosaic and its levels, undemosaiced.

    Parameters
    ----------
    path : str or Path
        Camera RAW file (see :data:`RAW_EXTENSIONS`).

    Returns
    -------
    mosaic : (M, N) uint16 ndarray
        ``raw_image_visible``, in file units (DN).
    levels : dict
        ``cfa_pattern`` (e.g. ``"RGGB"``), ``black_sites`` and ``white_sites``
        ((2, 2) float64 arrays: the black and white level of each site of the
        top-left 2x2 block), ``white_balance`` (as :func:`frame_info`) and
        ``decoder`` (what read the mosaic).
    """
    import rawpy

    path = check_frame_path(path)
    try:
        raw = rawpy.imread(str(path))
    except (rawpy.LibRawError, OSError) as exc:
        raise ValueError(f"cannot read camera RAW file {path}: {exc}") from None
    with raw:
        if raw.raw_type != rawpy.RawType.Flat:
            raise ValueError(
                f"{path}: RAW type {raw.raw_type.name} is not a single-plane Bayer mosaic; "
                "convert it to TIFF or a Bayer DNG first"
            )
        mosaic = raw.raw_image_visible.copy()
        colours = raw.raw_colors_visible[:2, :2]  # CFA phase at the visible origin
        pattern = bayer_pattern(colours, raw.color_desc)
        black_sites = np.asarray(raw.black_level_per_channel, dtype=np.float64)[colours]
        white_per = raw.camera_white_level_per_channel
        white_sites = (
            np.asarray(white_per, dtype=np.float64)[colours] if white_per is not None
            else np.full((2, 2), float(raw.white_level))
        )
        wb = _white_balance_rgb(raw.camera_whitebalance)
    if np.any(white_sites <= black_sites):
        raise ValueError(f"{path}: white level {white_sites.tolist()} not above black {black_sites.tolist()}")
    return mosaic, {"cfa_pattern": pattern, "black_sites": black_sites, "white_sites": white_sites,
                    "white_balance": wb, "decoder": "rawpy raw_image_visible"}
