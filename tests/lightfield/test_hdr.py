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
