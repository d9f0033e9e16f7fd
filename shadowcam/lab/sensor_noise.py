"""The temporal noise of a pixel's signal: a Poisson-Gaussian model fitted to the sweep itself.

A sensor's raw value is shot noise (variance proportional to the signal) plus read noise
(a constant variance): ``variance = gain * level + floor``. Summing channels of one gain
keeps that form. Each pixel's own noise estimate comes from a few tens of lit frames and
scatters by tens of percent; the model pools every pixel of the sweep, so that a dip's
significance is judged against the noise its level implies, not against the pixel's luck.
A pixel whose own variance exceeds the model's beyond chance (a chi-square test at
`false_alarm`) is noisier than the sensor (flicker, a moving texture) and keeps its own.

Offers
------
fit_noise_model : per-pixel variance estimates -> ``(gain, floor)``.
pixel_noise : per-pixel noise standard deviation from the model and the pixel's own estimate.
"""

import numpy as np
from scipy.stats import chi2

from shadowcam._shared.validation import check_in_interval


def _as_vectors(level, variance, count):
    level, variance, count = (np.asarray(a, dtype=np.float64).ravel() for a in (level, variance, count))
    if not level.shape == variance.shape == count.shape:
        raise ValueError(f"level, variance and count must have one shape; got {level.shape}, "
                         f"{variance.shape} and {count.shape}")
    return level, variance, count


def _non_negative_fit(design, v, weight):
    """Weighted least squares of ``v`` on the two columns with both coefficients >= 0."""
    root = np.sqrt(weight)
    a, b = design * root[:, None], v * root
    best, best_cost = (0.0, 0.0), float(np.sum(b ** 2))
    candidates = [np.linalg.lstsq(a, b, rcond=None)[0]]
    for column in range(2):  # one coefficient at zero, the other fitted alone
        only = np.zeros(2)
        norm = float(np.sum(a[:, column] ** 2))
        only[column] = float(np.sum(a[:, column] * b)) / norm if norm > 0 else 0.0
        candidates.append(only)
    for coefficients in candidates:
        if np.all(coefficients >= 0):
            cost = float(np.sum((a @ coefficients - b) ** 2))
            if cost < best_cost:
                best, best_cost = (float(coefficients[0]), float(coefficients[1])), cost
    return best


def fit_noise_model(level, variance, count, *, iterations=3):
    """Least-squares ``variance = gain * level + floor`` over the pixels.

    Parameters
    ----------
    level : (...) array_like
        Each pixel's lit level.
    variance : (...) array_like
        Each pixel's variance estimate of one sample (NaN where none).
    count : (...) array_like
        Degrees of freedom of each estimate (0 = none).
    iterations : int
        Reweighting passes: a sample variance with ``n`` degrees of freedom has variance
        ``2 variance**2 / n``, so each pixel is weighted by ``n / model**2``.

    Returns
    -------
    gain, floor : float
        Both >= 0 (0, 0 for a noise-free sweep); NaN, NaN where fewer than two pixels
        have an estimate.
    """
    level, variance, count = _as_vectors(level, variance, count)
    use = np.isfinite(level) & np.isfinite(variance) & (count > 0)
    if use.sum() < 2:
        return float("nan"), float("nan")
    x, v, n = level[use], variance[use], count[use]
    design = np.stack([x, np.ones_like(x)], axis=1)
    weight = n.copy()
    gain = floor = 0.0
    for _ in range(int(iterations)):
        gain, floor = _non_negative_fit(design, v, weight)
        model = gain * x + floor
        if not np.any(model > 0):
            return 0.0, 0.0
        weight = n / np.maximum(model, model[model > 0].min()) ** 2
    return gain, floor


def pixel_noise(level, variance, count, *, model, false_alarm=1e-3):
    """Each pixel's noise standard deviation of one sample.

    Parameters
    ----------
    level, variance, count : (...) array_like
        As for :func:`fit_noise_model`.
    model : (float, float)
        ``(gain, floor)`` of :func:`fit_noise_model`, or a sensor's declared values in
        the same units; NaN entries: every pixel keeps its own estimate.
    false_alarm : float
        Probability that a pixel following the model is judged noisier than it.

    Returns
    -------
    (...) float64 ndarray
        ``sqrt(gain * level + floor)``, or the pixel's own ``sqrt(variance)`` where that
        exceeds the model's upper `false_alarm` chi-square bound; NaN where neither exists.
    """
    check_in_interval(false_alarm, "false_alarm", 0, 1, closed="neither")
    shape = np.shape(level)
    level, variance, count = _as_vectors(level, variance, count)
    gain, floor = model
    with np.errstate(invalid="ignore"):
        modelled = gain * level + floor
        bound = np.where(count > 0, chi2.isf(false_alarm, np.maximum(count, 1)) / np.maximum(count, 1), np.inf)
        own = np.where(count > 0, variance, np.nan)
        noisier = ~np.isfinite(modelled) | (own > modelled * bound)
    return np.sqrt(np.where(noisier, own, modelled)).reshape(shape)
