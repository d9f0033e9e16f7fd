"""A sweep's Bayer mosaics, read fast: DNG raw data straight from the TIFF structure, checked against rawpy.

rawpy (LibRaw) hands over a DNG's mosaic several times slower than tifffile
(with imagecodecs' codecs) reads the same data, and about as long as
everything else the shadow-time pipeline does with the frame (figures in
``docs/benchmarks.md``). A :class:`MosaicReader` decodes the first frame of a sweep both ways and reads
the rest directly only if the two mosaics are equal; every later frame must
then have the same raw-image layout, compression and level tags as the first
(so the levels rawpy reported hold), else it is read with rawpy. DNGs with a
linearisation table or opcode lists, and non-DNG RAW files, are always read
with rawpy.

Offers
------
MosaicReader : read the mosaics of one sweep (fast path verified on its first frame).
raw_page : the full-resolution CFA page of a DNG.
"""

import numpy as np

from shadowcam.io.raw_mosaic import read_mosaic

_CFA = 32803  # PhotometricInterpretation: colour filter array
_DIRECT_COMPRESSIONS = (1, 7)  # none (plain or bit-packed samples), lossless JPEG
#: tags that decide how raw samples map to the mosaic and its levels (DNG 1.6)
_LAYOUT_TAGS = (
    33421, 33422,  # CFARepeatPatternDim, CFAPattern
    50712,  # LinearizationTable
    50713, 50714, 50715, 50716, 50717,  # BlackLevelRepeatDim, BlackLevel, BlackLevelDeltaH/V, WhiteLevel
    50829,  # ActiveArea
    51008, 51009, 51022,  # OpcodeList1-3
)


def raw_page(tif):
    """The full-resolution CFA page of a DNG (IFD 0 or one of its SubIFDs), or None."""
    first = tif.pages[0]
    for page in [first] + list(first.pages or []):
        if page.photometric == _CFA and int(page.tags.valueof(254, 0)) & 1 == 0:
            return page
    return None


def _direct_layout(page):
    """Hashable description of `page`'s raw data, or None if it cannot be read directly."""
    if page is None or page.compression not in _DIRECT_COMPRESSIONS or page.samplesperpixel != 1:
        return None
    if page.tags.get(50712) is not None or any(page.tags.get(code) is not None for code in (51008, 51009, 51022)):
        return None  # linearisation or opcodes: rawpy applies them
    tags = tuple((code, repr(page.tags.valueof(code))) for code in _LAYOUT_TAGS)
    return page.shape, str(page.dtype), int(page.compression), int(page.bitspersample), tags


def _read_direct(page):
    """The mosaic of a directly readable page, cropped to its ActiveArea."""
    data = page.asarray()
    area = page.tags.valueof(50829)
    if area is not None:
        top, left, bottom, right = (int(a) for a in area)
        data = data[top:bottom, left:right]
    return np.ascontiguousarray(data, dtype=np.uint16)


class MosaicReader:
    """Read the mosaics of one sweep's RAW files, directly where that is exact.

    Parameters
    ----------
    first_path : str or Path
        A frame of the sweep: decoded with rawpy (the reference) and, if it
        is a DNG tifffile can decode, directly; the direct path is used for
        the sweep only if both mosaics are equal.

    Attributes
    ----------
    levels : dict
        The first frame's ``cfa_pattern``, ``black_sites``, ``white_sites``,
        ``white_balance`` and ``decoder`` (see :func:`shadowcam.io.raw_mosaic.read_mosaic`).
    shape : (int, int)
        Rows and cols of the mosaic.
    direct : bool
        Whether frames with the first frame's layout are read directly.
    """

    def __init__(self, first_path):
        mosaic, self.levels = read_mosaic(first_path)
        self.shape = mosaic.shape
        self._first = (str(first_path), mosaic)  # handed out by the first read of that path
        self._layout = None
        layout, direct = self._direct(first_path)
        if layout is not None and direct.shape == mosaic.shape and np.array_equal(direct, mosaic):
            self._layout = layout
            self._direct_levels = dict(self.levels, decoder="tifffile/imagecodecs DNG data (equal to rawpy "
                                                           "raw_image_visible on the sequence's first frame)")

    @property
    def direct(self):
        return self._layout is not None

    @staticmethod
    def _direct(path):
        import tifffile

        try:
            with tifffile.TiffFile(path) as tif:
                page = raw_page(tif)
                layout = _direct_layout(page)
                return (layout, _read_direct(page)) if layout is not None else (None, None)
        except (tifffile.TiffFileError, OSError, ValueError, KeyError, RuntimeError, NotImplementedError):
            return None, None

    def read(self, path):
        """Mosaic of one frame, ``(M, N)`` uint16, and its levels (as :func:`~shadowcam.io.raw_mosaic.read_mosaic`).

        Raises
        ------
        ValueError
            If the frame's mosaic size or CFA pattern differs from the first frame's.
        """
        if self._first is not None and str(path) == self._first[0]:
            mosaic, self._first = self._first[1], None  # equal to the direct read, if verified
            return mosaic, self._direct_levels if self._layout is not None else self.levels
        if self._layout is not None:
            import tifffile

            try:
                with tifffile.TiffFile(path) as tif:
                    page = raw_page(tif)
                    if _direct_layout(page) == self._layout:
                        return _read_direct(page), self._direct_levels
            except (tifffile.TiffFileError, OSError, ValueError, KeyError, RuntimeError, NotImplementedError):
                pass  # rawpy decides (and names the problem)
        mosaic, levels = read_mosaic(path)
        if mosaic.shape != self.shape or levels["cfa_pattern"] != self.levels["cfa_pattern"]:
            raise ValueError(f"frame {path} has a {mosaic.shape} {levels['cfa_pattern']} mosaic but the "
                             f"sweep's first frame has {self.shape} {self.levels['cfa_pattern']}")
        return mosaic, levels
