import numpy as np
import pytest

from shadowcam.lightfield.hdr import ALL_SATURATED, OK, merge_brackets, merge_stream

TIMES = np.array([8e-3, 1e-3, 1.25e-4])
BLACK, WHITE, GAIN, READ = 256, 4095, 1.0, 2.0


def _brackets(radiance, rng=None):
    out = []
    for t in TIMES:
        electrons = radiance * t
        if rng is not None:
            electrons = rng.poisson(electrons) + rng.normal(0, READ, radiance.shape)
        out.append(np.clip(np.rint(BLACK + GAIN * electrons), 0, WHITE))
    return np.array(out, np.uint16)


def test_exact_on_noise_free_brackets():
    radiance = np.geomspace(2e3, 2.5e7, 400)  # 4 decades, brightest saturates all but the shortest
    merged, std, flags = merge_brackets(_brackets(radiance), TIMES, black_level=BLACK, white_level=WHITE,
                                        gain=GAIN, read_noise=READ)
    assert np.all(flags == OK)
    # only rounding to whole DN remains: half a DN of the longest usable exposure
    assert np.all(np.abs(merged - radiance) <= 0.5 / TIMES[-1] + 1e-6 * radiance)
    assert np.median(np.abs(merged / radiance - 1)) < 1e-3


def test_noise_optimal_weighting():
    rng = np.random.default_rng(1)
    radiance = np.full(4000, 6.0e5)  # usable in the two shorter exposures (longest saturates)
    merged, std, flags = merge_brackets(_brackets(radiance, rng), TIMES, black_level=BLACK, white_level=WHITE,
                                        gain=GAIN, read_noise=READ)
    assert np.all(flags == OK)
    var = [(radiance[0] * t * GAIN + READ**2) / (GAIN * t) ** 2 for t in TIMES[1:]]
    optimal = 1 / np.sqrt(sum(1 / v for v in var))
    assert abs(np.std(merged) / optimal - 1) < 0.08
    assert abs(np.median(std) / optimal - 1) < 0.05
    assert abs(np.mean(merged) / radiance[0] - 1) < 3 * optimal / radiance[0] / np.sqrt(4000) + 2e-3
    # better than the plain mean of the usable estimates
    plain = np.mean([(b.astype(float) - BLACK) / (GAIN * t) for b, t in zip(_brackets(radiance, rng)[1:], TIMES[1:])],
                    axis=0)
    assert np.std(merged) < 0.85 * np.std(plain)


def test_every_bracket_saturated_is_flagged_not_guessed():
    radiance = np.array([1e3 * 1e5, 1e5])
    merged, std, flags = merge_brackets(_brackets(radiance), TIMES, black_level=BLACK, white_level=WHITE)
    assert flags[0] == ALL_SATURATED and np.isnan(merged[0])
    assert flags[1] == OK and np.isfinite(merged[1])


def test_bad_brackets_are_refused_with_the_parameter_named():
    with pytest.raises(ValueError, match="brackets must have one shape"):
        merge_brackets([np.zeros((4, 4)), np.zeros((4, 6))], TIMES[:2], black_level=0, white_level=10)
    with pytest.raises(ValueError, match="exposure_times must have one entry per bracket"):
        merge_brackets(np.zeros((3, 4, 4)), TIMES[:2], black_level=0, white_level=10)
    with pytest.raises(ValueError, match="exposure_times must be finite and > 0"):
        merge_brackets(np.zeros((3, 4, 4)), [1.0, 0.0, np.nan], black_level=0, white_level=10)
    frames = [np.zeros((3, 4, 4), np.uint16), np.zeros((3, 4, 6), np.uint16)]
    stream = merge_stream(frames, TIMES, black_level=0, white_level=10)
    assert next(stream).shape == (1, 4, 4, 1)
    with pytest.raises(ValueError, match=r"frames\[1\] must have brackets of shape"):
        next(stream)


@pytest.mark.parametrize("gain, read_noise, radiance", [(0.5, 12.0, 3e5), (2.0, 25.0, 1.2e5)])
def test_merge_is_inverse_variance_with_the_cameras_gain_and_read_noise(gain, read_noise, radiance):
    # two brackets of a camera whose gain (DN/e-) and read noise (DN) are not 1, both usable:
    # the optimum is 1 / sum(1 / var_e) with var_e = (g^2 L t + r^2) / (g t)^2
    rng = np.random.default_rng(3)
    n, times = 20000, TIMES[:2]
    brackets = np.array([np.clip(np.rint(BLACK + gain * rng.poisson(radiance * t, n) + rng.normal(0, read_noise, n)),
                                 0, WHITE) for t in times], np.uint16)
    assert np.all(brackets < WHITE) and np.all(brackets[-1] > BLACK + 3 * read_noise)
    optimum = 1 / np.sqrt(sum((gain * t) ** 2 / (gain**2 * radiance * t + read_noise**2) for t in times))
    merged, std, _ = merge_brackets(brackets, times, black_level=BLACK, white_level=WHITE, gain=gain,
                                    read_noise=read_noise)
    # std of a std estimate from n samples: 1 / sqrt(2 n) = 0.5 %; tolerance 3 %
    assert abs(np.std(merged) / optimum - 1) < 0.03
    assert abs(np.median(std) / optimum - 1) < 0.02
    assert abs(np.mean(merged) / radiance - 1) < 3 * optimum / radiance / np.sqrt(n) + 1e-3
    # the default camera (1 DN/e-, 1 DN) under-weighs the read-noise-limited short bracket
    # (measured 1.04-1.05 x the optimum on these brackets)
    default, _, _ = merge_brackets(brackets, times, black_level=BLACK, white_level=WHITE)
    assert np.std(default) / np.mean(default) > 1.02 * optimum / radiance
