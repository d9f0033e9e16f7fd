"""Real-size outdoor time-lapse samples for throughput and memory benchmarks.

A camera time-lapse is tens of megapixels per frame; the shared development
capture (dev_ridge) is 192x128. This module turns small linear frames into
real-size sensor mosaics: the frame is upsampled (bilinear, so the shadow edge
becomes a ramp as wide as the scale factor), exposed, and given the
Poisson-Gaussian noise and 14-bit quantisation of :mod:`shadowcam.sensor` at
full resolution, so that decoding, compression and every per-pixel stage see
data of the real size and noise. It is for measuring speed and memory, not
accuracy: upsampled frames carry no ground truth at the new size.

Offers
------
parse_size : ``"6000x4000"`` (cols x rows) -> ``(rows, cols)``.
upsample_frame : bilinear upsampling of a linear (H, W, C) frame to (rows, cols, C).
sample_mosaic : one real-size noisy RGGB mosaic (uint16 DN) from a small frame.
"""

import cv2
import numpy as np

from shadowcam.sensor import simulate_raw


def parse_size(text):
    """Return ``(rows, cols)`` of a ``"COLSxROWS"`` size string (e.g. ``"6000x4000"``)."""
    try:
        cols, rows = (int(part) for part in str(text).lower().split("x"))
    except ValueError:
        raise ValueError(f"size must be COLSxROWS, e.g. 6000x4000; got {text!r}") from None
    if rows < 22 or cols < 22 or rows % 2 or cols % 2:
        raise ValueError(f"size {text!r}: rows and cols must be even and >= 22 (Bayer mosaic, LibRaw limit)")
    return rows, cols


def upsample_frame(image, *, rows, cols):
    """Upsample a linear frame bilinearly.

    Parameters
    ----------
    image : (H, W, C) ndarray
        Linear frame.
    rows, cols : int
        Output size.

    Returns
    -------
    (rows, cols, C) float32 ndarray
        Pixel centres map to pixel centres (OpenCV ``INTER_LINEAR``).
    """
    image = np.asarray(image, dtype=np.float32)
    if image.ndim != 3:
        raise ValueError(f"image must be (H, W, C); got shape {image.shape}")
    if rows < 1 or cols < 1:
        raise ValueError(f"rows and cols must be positive; got {rows}, {cols}")
    return cv2.resize(image, (int(cols), int(rows)), interpolation=cv2.INTER_LINEAR).reshape(rows, cols, -1)


def sample_mosaic(image, *, rows, cols, sensor, scale, seed):
    """One real-size noisy RGGB mosaic of a small linear frame.

    Parameters
    ----------
    image : (H, W, 3) ndarray
        Linear frame (e.g. a dev_ridge PNG, white level = 1).
    rows, cols : int
        Sensor size (even).
    sensor : shadowcam.sensor.SensorModel
        Bit depth, black level, gain, read noise.
    scale : float
        Electrons per unit of `image` (:func:`shadowcam.sensor.exposure_scale`); the same
        for every frame, so that the capture's own exposure changes are kept.
    seed : int or sequence of int
        Noise seed (``numpy.random.default_rng``).

    Returns
    -------
    (rows, cols) uint16 ndarray
        DN in ``[0, sensor.white_level]``.
    """
    if rows % 2 or cols % 2:
        raise ValueError(f"rows and cols must be even (RGGB mosaic); got {rows}, {cols}")
    big = upsample_frame(image, rows=rows, cols=cols)
    if big.shape[2] != 3:
        raise ValueError(f"image must have 3 channels (RGB); got {big.shape[2]}")
    return simulate_raw(big, sensor=sensor, scale=scale, seed=seed, noise=True, mosaic=True)
