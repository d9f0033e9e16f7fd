"""Real-size outdoor time-lapse samples for throughput and memory benchmarks.

A camera time-lapse is tens of megapixels per frame; the shared development
capture (dev_ridge) is 192x128. This module turns small linear frames into
real-size sensor mosaics: the frame is steadied (its recorded shake undone at
the source resolution: upsampled ~31x, dev_ridge's <= 1 px shake would become
~30 px), upsampled (bilinear, so the shadow edge becomes a ramp as wide as the
scale factor), shaken by a realistic amount at full resolution (sub-pixel to
2 px, recorded), exposed, and given the Poisson-Gaussian noise and 14-bit
quantisation of :mod:`shadowcam.synthetic.sensor` at full resolution, so that decoding,
compression and every per-pixel stage see data of the real size and noise. It
is for measuring speed and memory, and the registration against the recorded
shake; the arrival times have no ground truth at the new size.

Shake convention (as dev_ridge, shared/data README 2.3): ``frame(u, v) =
image(u - dx, v - dy)``, content moves by ``+dx`` (cols) and ``+dy`` (rows).

Offers
------
parse_size : ``"6000x4000"`` (cols x rows) -> ``(rows, cols)``.
steady_frame : undo a frame's recorded shake (source resolution).
sample_shake : seeded per-frame shake of a real-size sample, on OpenCV's 1/32 px grid.
upsample_frame : bilinear upsampling of a linear (H, W, C) frame to (rows, cols, C).
sample_mosaic : one real-size noisy RGGB mosaic (uint16 DN) from a small frame, optionally shaken.
"""

import cv2
import numpy as np

from shadowcam._shared.validation import check_array
from shadowcam.synthetic.outdoor.nuisance import apply_shake, shake_offsets
from shadowcam.outdoor.translation import translate
from shadowcam.synthetic.sensor import simulate_raw

#: sub-pixel grid of OpenCV's warps (INTER_BITS = 5): a shake on it is applied exactly
SHAKE_STEP_PX = 1.0 / 32


def parse_size(text):
    """Return ``(rows, cols)`` of a ``"COLSxROWS"`` size string (e.g. ``"6000x4000"``)."""
    try:
        cols, rows = (int(part) for part in str(text).lower().split("x"))
    except ValueError:
        raise ValueError(f"size must be COLSxROWS, e.g. 6000x4000; got {text!r}") from None
    if rows < 22 or cols < 22 or rows % 2 or cols % 2:
        raise ValueError(f"size {text!r}: rows and cols must be even and >= 22 (Bayer mosaic, LibRaw limit)")
    return rows, cols


def steady_frame(image, *, dx, dy):
    """Undo a recorded shake: return ``image`` with ``frame(u, v) = image(u - dx, v - dy)`` solved.

    Parameters
    ----------
    image : (H, W, C) ndarray
        A shaken linear frame.
    dx, dy : float
        Its recorded shake along cols and rows, pixels.

    Returns
    -------
    (H, W, C) ndarray
        Resampled at ``(u + dx, v + dy)`` with the cubic spline the shake was
        made with (:func:`shadowcam.synthetic.outdoor.nuisance.apply_shake`), edges replicated.
    """
    image = np.asarray(image, dtype=np.float32)
    check_array(image, "image", ndim=3)
    return apply_shake(image, -float(dx), -float(dy))


def sample_shake(frames, *, seed, max_px=2.0):
    """Per-frame camera shake of a real-size sample (content moves by +dx, +dy).

    :func:`shadowcam.synthetic.outdoor.nuisance.shake_offsets` (AR(1) jitter, rms ~0.3
    `max_px`, plus gusts up to `max_px`), rounded to :data:`SHAKE_STEP_PX` so that
    OpenCV's warp applies it without quantisation error.

    Parameters
    ----------
    frames : int
    seed : int
    max_px : float, optional
        Largest shake, pixels of the sample (2: sub-pixel to 2 px, a tripod in wind).

    Returns
    -------
    dx, dy : (frames,) float64 ndarray
    """
    if int(frames) < 1:
        raise ValueError(f"frames must be >= 1; got {frames}")
    dx, dy = shake_offsets(int(frames), seed=seed, max_px=max_px)
    return (np.round(dx / SHAKE_STEP_PX) * SHAKE_STEP_PX, np.round(dy / SHAKE_STEP_PX) * SHAKE_STEP_PX)


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
    check_array(image, "image", ndim=3)
    if rows < 1 or cols < 1:
        raise ValueError(f"rows and cols must be positive; got {rows}, {cols}")
    return cv2.resize(image, (int(cols), int(rows)), interpolation=cv2.INTER_LINEAR).reshape(rows, cols, -1)


def sample_mosaic(image, *, rows, cols, sensor, scale, seed, shake=(0.0, 0.0)):
    """One real-size noisy RGGB mosaic of a small linear frame.

    Parameters
    ----------
    image : (H, W, 3) ndarray
        Linear frame (e.g. a dev_ridge PNG, white level = 1).
    rows, cols : int
        Sensor size (even).
    sensor : shadowcam.synthetic.sensor.SensorModel
        Bit depth, black level, gain, read noise.
    scale : float
        Electrons per unit of `image` (:func:`shadowcam.synthetic.sensor.electrons_per_unit_radiance`); the same
        for every frame, so that the capture's own exposure changes are kept.
    seed : int or sequence of int
        Noise seed (``numpy.random.default_rng``).
    shake : (2,) array_like, optional
        ``(dx, dy)``, pixels of the sample: the upsampled frame is moved by it
        (cubic, edges replicated, clipped at 0) before exposure and noise.

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
    dx, dy = (float(v) for v in shake)
    if dx or dy:
        big = np.maximum(translate(big, (-dy, -dx), method="opencv_cubic"), np.float32(0))
    return simulate_raw(big, sensor=sensor, scale=scale, seed=seed, noise=True, mosaic=True)
