"""HDR merge of bracketed RAW exposures into linear radiance.

Each bracket ``e`` of a frame holds sensor values ``DN_e = black + gain * q * t_e * L
+ noise`` (``q`` electrons per second per unit radiance, ``t_e`` the exposure time).
Its radiance estimate is ``(DN_e - black) / (gain * t_e)`` (electrons per second) and
its variance is ``(gain * signal_e + read_noise**2) / (gain * t_e)**2``. The merge is
the inverse-variance weighted mean of the usable samples (maximum likelihood for
Poisson-Gaussian noise), where a sample is usable unless it is saturated (at or above
``white_level - saturation_margin``) or near black (below ``dark_sigmas`` read-noise
deviations above black while a longer usable exposure exists).

Offers
------
REASONS : flag code -> meaning, per merged photosite.
merge_brackets : (E, ...) DN brackets + exposure times -> linear radiance, its standard deviation, flags.
"""

import numpy as np

from shadowcam._shared.validation import check_array, check_positive

#: flag code -> meaning (0 = a merged value)
REASONS = {0: "ok", 1: "all_saturated", 2: "all_dark"}
OK, ALL_SATURATED, ALL_DARK = range(3)


def merge_brackets(brackets, exposure_times, *, black_level, white_level, gain=1.0, read_noise=1.0,
                   saturation_margin=0, dark_sigmas=3.0):
    """Merge exposure brackets of one frame into linear radiance.

    Parameters
    ----------
    brackets : (E, ...) integer or float ndarray, or sequence of E arrays
        Sensor values in DN of the same photosites, one array per exposure.
        All brackets must have one shape.
    exposure_times : (E,) array_like
        Seconds, > 0, one per bracket (from the files' metadata or the manifest).
    black_level, white_level : float, keyword-only
        DN of black and of saturation.
    gain : float, keyword-only
        DN per electron.
    read_noise : float, keyword-only
        Read-noise standard deviation in DN (> 0; sets the weights of dark samples).
    saturation_margin : float, keyword-only
        Samples at or above ``white_level - saturation_margin`` are saturated.
    dark_sigmas : float, keyword-only
        Samples below ``black_level + dark_sigmas * read_noise`` are near black and are
        used only where no exposure is above that level.

    Returns
    -------
    radiance : (...) float32 ndarray
        Electrons per second; NaN where every bracket is saturated.
    radiance_std : (...) float32 ndarray
        Standard deviation of `radiance` from the noise model.
    flags : (...) uint8 ndarray
        :data:`REASONS` codes: ``all_saturated`` (radiance NaN: above the range of the
        shortest exposure), ``all_dark`` (every sample near black: merged from all
        unsaturated samples, a low-confidence value).
    """
    if isinstance(brackets, (list, tuple)):
        shapes = {np.shape(b) for b in brackets}
        if len(shapes) > 1:
            raise ValueError(f"brackets must have one shape; got shapes {sorted(shapes)}")
    stack = check_array(brackets, "brackets", dtype_kind="uif")
    if stack.ndim < 2:
        raise ValueError(f"brackets must have at least 2 dimensions (exposure, ...); got shape {stack.shape}")
    times = check_array(exposure_times, "exposure_times", ndim=1, dtype_kind="iuf").astype(np.float64)
    if times.shape[0] != stack.shape[0]:
        raise ValueError(f"exposure_times must have one entry per bracket ({stack.shape[0]}); "
                         f"got {times.shape[0]}")
    if not np.all(np.isfinite(times) & (times > 0)):
        raise ValueError(f"exposure_times must be finite and > 0; got {times.tolist()}")
    check_positive(gain, "gain")
    check_positive(read_noise, "read_noise")
    if not white_level > black_level:
        raise ValueError(f"white_level must be > black_level ({black_level}); got {white_level}")

    shape = stack.shape[1:]
    out = np.zeros(shape, np.float64)
    weight_sum = np.zeros(shape, np.float64)
    dark_out = np.zeros(shape, np.float64)
    dark_weight = np.zeros(shape, np.float64)
    read_var = float(read_noise) ** 2
    for dn, t in zip(stack, times):
        signal = dn.astype(np.float64) - black_level
        unsaturated = dn < white_level - saturation_margin
        bright = signal >= dark_sigmas * read_noise
        scale = gain * t
        variance = (gain * np.maximum(signal, 0.0) + read_var) / scale**2
        weight = 1.0 / variance
        estimate = signal / scale
        use = unsaturated & bright
        out += np.where(use, weight * estimate, 0.0)
        weight_sum += np.where(use, weight, 0.0)
        dark = unsaturated & ~bright
        dark_out += np.where(dark, weight * estimate, 0.0)
        dark_weight += np.where(dark, weight, 0.0)
    flags = np.zeros(shape, np.uint8)
    merged = weight_sum > 0
    only_dark = ~merged & (dark_weight > 0)
    flags[only_dark] = ALL_DARK
    flags[~merged & ~only_dark] = ALL_SATURATED
    total_weight = np.where(merged, weight_sum, dark_weight)
    with np.errstate(invalid="ignore", divide="ignore"):
        radiance = np.where(merged, out, dark_out) / total_weight
        radiance_std = 1.0 / np.sqrt(total_weight)
    radiance[flags == ALL_SATURATED] = np.nan
    radiance_std[flags == ALL_SATURATED] = np.nan
    return radiance.astype(np.float32), radiance_std.astype(np.float32), flags


def merge_stream(frames, exposure_times, *, black_level, white_level, gain=1.0, read_noise=1.0,
                 responsivity=1.0, saturation_margin=0, dark_sigmas=3.0):
    """Merge the brackets of each frame of a sweep, one frame at a time.

    Parameters
    ----------
    frames : iterable of (E, H, W) ndarray
        The brackets of each frame in time order (DN).
    exposure_times : (E,) array_like
        Seconds per bracket.
    responsivity : float, keyword-only
        Electrons per second per unit of the output (e.g. per lux of screen irradiance).
    black_level, white_level, gain, read_noise, saturation_margin, dark_sigmas
        As :func:`merge_brackets`.

    Yields
    ------
    (1, H, W, 1) float32 ndarray
        Linear radiance in output units; NaN where every bracket is saturated.
    """
    check_positive(responsivity, "responsivity", finite=True)
    shape = None
    for index, brackets in enumerate(frames):
        brackets = np.asarray(brackets) if not isinstance(brackets, (list, tuple)) else brackets
        first = np.shape(brackets[0])
        if shape is None:
            shape = first
        elif first != shape:
            raise ValueError(f"frames[{index}] must have brackets of shape {shape} like frame 0; got {first}")
        radiance, _, _ = merge_brackets(brackets, exposure_times, black_level=black_level, white_level=white_level,
                                        gain=gain, read_noise=read_noise, saturation_margin=saturation_margin,
                                        dark_sigmas=dark_sigmas)
        yield (radiance / np.float32(responsivity))[None, ..., None]
