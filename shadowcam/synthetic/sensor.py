"""Sensor model: exposure, Poisson-Gaussian noise, black/white level, quantisation, Bayer mosaic.

Model (all values per photosite)::

    electrons = Poisson(scale * radiance)                 (shot noise; exact mean without noise)
    DN        = clip(round(black + gain * electrons + Normal(0, read_noise^2)), 0, white)

``scale`` is electrons per unit radiance (the exposure), ``gain`` DN per electron, ``read_noise``
in DN, ``white = 2**bit_depth - 1``. The mosaic is RGGB: R at (even row, even col), G at
(even, odd) and (odd, even), B at (odd, odd). Noise is seeded by
``numpy.random.default_rng([seed, sweep_index, frame])``.

Offers
------
SensorModel : bit depth, black level, gain, read noise (white level derived).
mosaic_rggb : (rows, cols, 3) RGB -> (rows, cols) RGGB mosaic.
electrons_per_unit_radiance : electrons per unit radiance placing a percentile of a reference at a target.
simulate_raw : radiance -> integer DN (mosaic or per-channel RGB), noisy or noise-free.
raw_to_linear : DN -> float32 normalised so that black = 0 and white level = 1.
"""

from dataclasses import dataclass

import numpy as np

from shadowcam._shared.validation import check_array, check_in_interval, check_positive


@dataclass(frozen=True)
class SensorModel:
    """A linear sensor.

    Parameters
    ----------
    bit_depth : int
        ADC bits (8..16); ``white_level = 2**bit_depth - 1``.
    black_level : int
        DN added to every photosite.
    gain : float
        DN per electron.
    read_noise : float
        Standard deviation of the Gaussian read noise, DN.
    """

    bit_depth: int = 12
    black_level: int = 256
    gain: float = 1.0
    read_noise: float = 6.0

    def __post_init__(self):
        if not 8 <= int(self.bit_depth) <= 16:
            raise ValueError(f"bit_depth must be in 8..16; got {self.bit_depth}")
        if not 0 <= int(self.black_level) < self.white_level:
            raise ValueError(f"black_level: must be in [0, {self.white_level}), "
                             f"got {self.black_level}")
        check_positive(self.gain, "gain")
        if not self.read_noise >= 0:
            raise ValueError(f"read_noise must be >= 0; got {self.read_noise}")

    @property
    def white_level(self):
        """Saturation DN, ``2**bit_depth - 1``."""
        return 2 ** int(self.bit_depth) - 1


def mosaic_rggb(image):
    """RGGB Bayer mosaic of an RGB image.

    Parameters
    ----------
    image : (rows, cols, 3) ndarray

    Returns
    -------
    (rows, cols) ndarray, same dtype
    """
    image = np.asarray(image)
    check_array(image, "image", shape=(None, None, 3))
    out = image[:, :, 1].copy()
    out[0::2, 0::2] = image[0::2, 0::2, 0]
    out[1::2, 1::2] = image[1::2, 1::2, 2]
    return out


def electrons_per_unit_radiance(reference, *, sensor, target_fraction=0.8, percentile=99.5):
    """Electrons per unit radiance so that a percentile of `reference` reaches a target.

    Parameters
    ----------
    reference : (rows, cols, 3) ndarray
        Linear radiance of the unshadowed scene.
    sensor : SensorModel
    target_fraction : float
        Fraction of the range ``white - black`` (in DN) that the `percentile` of the
        reference mosaic is exposed to.
    percentile : float

    Returns
    -------
    float
    """
    check_in_interval(target_fraction, "target_fraction", 0, 1)
    level = float(np.percentile(mosaic_rggb(reference), percentile))
    check_positive(level, "reference")
    span = sensor.white_level - sensor.black_level
    return target_fraction * span / sensor.gain / level


def simulate_raw(radiance, *, sensor, scale, seed=None, noise=True, mosaic=True):
    """Turn linear radiance into sensor DN.

    Parameters
    ----------
    radiance : (rows, cols, 3) ndarray
        Linear radiance (>= 0).
    sensor : SensorModel
    scale : float
        Electrons per unit radiance (``electrons_per_unit_radiance``).
    seed : int or sequence of int, optional
        Seed of ``numpy.random.default_rng``, e.g. ``[seed, sweep_index, frame]``;
        required when `noise` is True.
    noise : bool
        Add shot and read noise (False: round the mean).
    mosaic : bool
        Return the RGGB mosaic (rows, cols); else per-channel values (rows, cols, 3).

    Returns
    -------
    uint16 ndarray
        (rows, cols) or (rows, cols, 3) DN in ``[0, white_level]``.
    """
    radiance = np.asarray(radiance)
    check_array(radiance, "radiance", shape=(None, None, 3))
    check_positive(scale, "scale", finite=True)
    if noise and seed is None:
        raise ValueError("seed: required when noise is True")
    signal = mosaic_rggb(radiance) if mosaic else radiance
    electrons = np.clip(signal.astype(np.float64) * scale, 0.0, None)
    if noise:
        rng = np.random.default_rng(seed)
        electrons = rng.poisson(electrons).astype(np.float64)
        dn = sensor.black_level + sensor.gain * electrons
        dn += rng.normal(0.0, sensor.read_noise, size=dn.shape)
    else:
        dn = sensor.black_level + sensor.gain * electrons
    return np.clip(np.rint(dn), 0, sensor.white_level).astype(np.uint16)


def raw_to_linear(raw, *, sensor):
    """DN -> float32 linear values with black = 0 and white level = 1."""
    raw = np.asarray(raw)
    span = sensor.white_level - sensor.black_level
    return ((raw.astype(np.float32) - np.float32(sensor.black_level)) / np.float32(span))
