"""Capture facts from a frame file's header: exposure time, capture time, bits per sample.

OpenImageIO reads the EXIF of TIFF, PNG, JPEG and EXR headers, and of uncompressed DNGs, but it
cannot open a lossless-JPEG DNG (what cameras write) nor most camera RAW files. Those are
TIFF-structured (DNG, CR2, NEF, ARW, ...), so their tags are read with tifffile: ``ExposureTime``,
``DateTimeOriginal`` and ``SubsecTimeOriginal`` from IFD 0 or its EXIF IFD, ``BitsPerSample`` from
the full-resolution colour-filter-array page (a DNG's IFD 0 is often an 8-bit preview). Only
the header is read, never the image data.

Offers
------
header_metadata : exposure and capture time (and bits per sample) of one file.
"""

import datetime as _dt

from shadowcam.io.mosaic_reader import raw_page

_EXPOSURE_TIME, _DATE_TIME_ORIGINAL, _SUBSEC_TIME_ORIGINAL = 33434, 36867, 37521


def _parse_exif_datetime(text, subsec=None):
    """EXIF "YYYY:MM:DD HH:MM:SS" (+ sub-second digits) -> naive datetime, or None."""
    if not text:
        return None
    text = str(text).strip().rstrip("\x00")
    for fmt in ("%Y:%m:%d %H:%M:%S", "%Y-%m-%d %H:%M:%S", "%Y-%m-%dT%H:%M:%S"):
        try:
            stamp = _dt.datetime.strptime(text[:19], fmt)
            break
        except ValueError:
            continue
    else:
        return None
    digits = "".join(ch for ch in str(subsec or "") if ch.isdigit())
    if digits:
        stamp += _dt.timedelta(seconds=float("0." + digits))
    return stamp


def _seconds(value):
    """An EXIF rational (numerator, denominator), or a number, in seconds; None if not positive."""
    try:
        if isinstance(value, (tuple, list)):
            seconds = float(value[0]) / float(value[1]) if len(value) == 2 else float(value[0])
        else:
            seconds = float(value)
    except (TypeError, ValueError, ZeroDivisionError, IndexError):
        return None
    return float(f"{seconds:.7g}") if seconds > 0 else None


def _oiio_header(path):
    """:func:`header_metadata` through OpenImageIO; None if it cannot open the file."""
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    if not inp:
        oiio.geterror()  # clear the error state; RAW formats may be unknown to OIIO
        return None
    try:
        spec = inp.spec()
        stamp = _parse_exif_datetime(
            spec.getattribute("Exif:DateTimeOriginal") or spec.getattribute("DateTimeOriginal"),
            spec.getattribute("Exif:SubsecTimeOriginal"),
        )
        bits = spec.getattribute("oiio:BitsPerSample")
        exposure = spec.getattribute("ExposureTime")
        return {"exposure_s": _seconds(exposure) if exposure is not None else None,
                "capture_time": stamp.isoformat() if stamp is not None else None,
                "bits_per_sample": int(bits) if bits else None}
    finally:
        inp.close()


def _tiff_header(path):
    """:func:`header_metadata` through tifffile; None if the file is not TIFF-structured."""
    import tifffile

    try:
        tif = tifffile.TiffFile(str(path))
    except (tifffile.TiffFileError, OSError, ValueError):
        return None
    with tif:
        first = tif.pages[0]
        exif = first.tags.valueof(34665) or {}  # the EXIF IFD, as a dict by tag name

        def tag(code, name):
            value = first.tags.valueof(code)
            return exif.get(name) if value is None and isinstance(exif, dict) else value

        stamp = _parse_exif_datetime(tag(_DATE_TIME_ORIGINAL, "DateTimeOriginal"),
                                     tag(_SUBSEC_TIME_ORIGINAL, "SubsecTimeOriginal"))
        exposure = tag(_EXPOSURE_TIME, "ExposureTime")
        bits = (raw_page(tif) or first).bitspersample
        return {"exposure_s": _seconds(exposure) if exposure is not None else None,
                "capture_time": stamp.isoformat() if stamp is not None else None,
                "bits_per_sample": int(bits) if bits else None}


def header_metadata(path):
    """Read exposure and capture time from a file header only.

    OpenImageIO first; the fields it cannot give (a file it cannot open, such as a
    lossless-JPEG DNG, or tags it does not report) come from the TIFF structure when the
    file has one.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    dict
        ``exposure_s`` (float or None), ``capture_time`` (ISO 8601 string from
        EXIF DateTimeOriginal plus SubsecTimeOriginal, or None) and
        ``bits_per_sample`` (int or None). All None if neither reader can open the
        file.
    """
    out = _oiio_header(path) or {"exposure_s": None, "capture_time": None, "bits_per_sample": None}
    if any(value is None for value in out.values()):
        tiff = _tiff_header(path)
        if tiff is not None:
            out = {key: tiff[key] if value is None else value for key, value in out.items()}
    return out
