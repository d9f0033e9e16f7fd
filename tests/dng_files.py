"""Test helper: Bayer DNG files written the way the shared dev data are (pidng)."""

import numpy as np


def write_dng(path, mosaic, *, pattern="RGGB", black=256, white=4095, exposure=None, stamp=None):
    """12-bit uncompressed DNG as the shared dev data are written (pidng)."""
    from pidng.core import RAW2DNG, DNGTags, Tag
    from pidng.defs import CalibrationIlluminant, CFAPattern, DNGVersion, Orientation, PhotometricInterpretation

    height, width = mosaic.shape
    tags = DNGTags()
    identity = [[1, 1], [0, 1], [0, 1], [0, 1], [1, 1], [0, 1], [0, 1], [0, 1], [1, 1]]
    for tag, value in [
        (Tag.ImageWidth, width), (Tag.ImageLength, height), (Tag.TileWidth, width), (Tag.TileLength, height),
        (Tag.Orientation, Orientation.Horizontal),
        (Tag.PhotometricInterpretation, PhotometricInterpretation.Color_Filter_Array),
        (Tag.SamplesPerPixel, 1), (Tag.BitsPerSample, 12), (Tag.CFARepeatPatternDim, [2, 2]),
        (Tag.CFAPattern, getattr(CFAPattern, pattern)), (Tag.BlackLevel, black), (Tag.WhiteLevel, white),
        (Tag.ColorMatrix1, identity), (Tag.CalibrationIlluminant1, CalibrationIlluminant.D65),
        (Tag.AsShotNeutral, [[1, 2], [1, 1], [1, 4]]),  # neutral (0.5, 1, 0.25) -> multipliers (2, 1, 4)
        (Tag.Make, "shadowcam test"), (Tag.Model, "synthetic RGGB"),
        (Tag.DNGVersion, DNGVersion.V1_4), (Tag.DNGBackwardVersion, DNGVersion.V1_2),
    ]:
        tags.set(tag, value)
    if exposure is not None:
        tags.set(Tag.ExposureTime, [exposure])
    if stamp is not None:
        tags.set(Tag.DateTimeOriginal, stamp)
    writer = RAW2DNG()
    writer.options(tags, path=str(path.parent), compress=False)
    writer.convert(mosaic.astype(np.uint16), filename=path.stem)
    return path
