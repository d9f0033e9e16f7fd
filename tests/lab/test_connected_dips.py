"""A thin wire under an area light wider than it: one shallow dip with several minima, timed at
its removed light's centroid (``connected_dips.support_intervals``), against exact ground truth."""

import numpy as np
import pytest

from shadowcam.lab.dip_tracker import track_intervals, without_interval
from shadowcam.lab.connected_dips import support_intervals, support_threshold
from shadowcam.lab.dip_classification import OK, SEVERAL_MINIMA, WIDE_DIP, classify_dips
from shadowcam.lab.shadow_time import summary_shadow_times, track_sweep

#: the renderer's 4 x 4 disc samples (equal-area polar strata) projected on the sweep direction,
#: as fractions of the disc's radius: two groups either side of the centre, none at it
_A, _B = np.meshgrid((np.arange(4) + 0.5) / 4, (np.arange(4) + 0.5) / 4, indexing="ij")
DISC_OFFSETS = (np.sqrt(_A) * np.cos(2 * np.pi * _B)).ravel()


def _disc_sweep(wire_sweep, *, diameter=10.0, noise=0.0, seed=0, second=None):
    """A 2-frame wire under a disc `diameter` frames wide (16 samples), each sample's shadow
    a trapezoid (1-frame ramps: the pixel's width), over a 24 x 24 plane; truth = the time
    the wire passes the disc's centre. `second` adds another wire's shadow that many frames
    later (a second event), removing half the light: deeper than the disc's lobes."""
    h, w = 24, 24
    truth = 14.0 + (np.arange(w)[None] + 0.3 * np.arange(h)[:, None]) / 2.0
    centres = [truth + 0.5 * diameter * o for o in DISC_OFFSETS]
    depth = [1.0 / len(centres)] * len(centres)
    if second is not None:
        centres, depth = centres + [truth + second], depth + [0.5]
    frames, _ = wire_sweep(n_frames=64, shape=(h, w), centres=centres, depth=depth, width=2.0, ramp=1.0,
                           level=1.0, noise=noise, seed=seed)
    return frames[..., None], truth


def _times(frames, *, with_support=True):
    """As ``shadow_time_of_stores`` runs a sweep."""
    summary, _, _ = track_sweep([frames], frames.shape[1:3], half_window=4)
    summary, interval = without_interval(summary, track_intervals([frames], summary))
    return summary_shadow_times(summary, interval=interval, read=(lambda: [frames]) if with_support else None,
                                method="edge_fit")


def test_a_thin_wire_under_a_sampled_disc_is_one_dip_timed_at_the_discs_centre(wire_sweep):
    frames, truth = _disc_sweep(wire_sweep)
    before = _times(frames, with_support=False)
    # the two sample groups make two lobes: the half-depth interval holds one of them
    assert np.mean(np.isin(before["reason"], [SEVERAL_MINIMA, WIDE_DIP])) > 0.5
    after = _times(frames)
    assert np.mean(after["reason"] == OK) >= 0.98
    error = np.abs(after["shadow_time"] - truth)[after["reason"] == OK]
    # noise free: each sample's dip is a 2-frame box swept over a 1-frame pixel; sampled at
    # whole frames its removed light's first moment is the box's exactly (the sampling's
    # sawtooth integrates to zero over a whole number of frames), so the centroid is the
    # disc's centre up to the float32 samples' rounding
    assert error.max() < 1e-3
    # the removed light over the lit level is the wire's width (2 frames), whatever the
    # light's shape: the wire's edges pass the light's centre 1 frame either side (to the
    # same float32 rounding)
    timed = after["reason"] == OK
    np.testing.assert_allclose(after["interval_entry"][timed], (truth - 1.0)[timed], atol=1e-3)
    np.testing.assert_allclose(after["interval_exit"][timed], (truth + 1.0)[timed], atol=1e-3)


@pytest.mark.parametrize("seed", [0, 1])
def test_noisy_thin_wire_dips_are_timed_within_their_stated_uncertainty(wire_sweep, seed):
    # depth 0.25 of the lit level; noise 0.01 per sample
    frames, truth = _disc_sweep(wire_sweep, noise=0.01, seed=seed)
    result = _times(frames)
    timed = result["reason"] == OK
    assert timed.mean() >= 0.9
    z = (result["shadow_time"] - truth)[timed] / result["time_std"][timed]
    # the centroid's standard deviation from the noise of the samples inside the support:
    # the normalised errors are of unit spread (the discretisation is below 0.1 std)
    assert 0.6 < np.std(z) < 1.5
    assert np.mean(np.abs(z) < 4) > 0.99


def test_a_second_shadow_after_a_return_to_the_lit_level_stays_several_minima(wire_sweep):
    # a second wire 16 frames later: the signal is lit between the two dips
    frames, truth = _disc_sweep(wire_sweep, second=16.0)
    result = _times(frames)
    inside = (truth + 16 + 6 < 63)
    assert np.mean(result["reason"][inside] == SEVERAL_MINIMA) > 0.95


def test_the_support_threshold_is_the_lit_level_less_what_noise_reaches(wire_sweep):
    from shadowcam.lab.dip_classification import _SMOOTHED_NOISE, detection_threshold

    frames, _ = _disc_sweep(wire_sweep, noise=0.01)
    summary, _, _ = track_sweep([frames], frames.shape[1:3], half_window=4)
    threshold = support_threshold(summary)
    z = detection_threshold(summary.n_frames, false_alarm=1e-2)
    margin = np.minimum(z * summary.noise * _SMOOTHED_NOISE, 0.5 * (summary.lit_level - summary.minimum_value))
    np.testing.assert_allclose(threshold, summary.lit_level - margin)
    with pytest.raises(ValueError, match="noise_floor"):
        support_threshold(summary, noise_floor=0.0)


def test_the_frames_are_not_read_again_when_no_dip_has_several_minima(wire_sweep):
    # a thin wire under a point light: every dip fits its window, none needs the support
    frames, _ = wire_sweep(n_frames=40, shape=(16, 16), level=1.0)
    frames = frames[..., None]
    summary, _, _ = track_sweep([frames], frames.shape[1:3], half_window=4)
    summary, interval = without_interval(summary, track_intervals([frames], summary))

    def read():  # lazy, as the workflow's reader: calling it reads nothing
        raise AssertionError("the frames were read")
        yield frames

    reason, _ = classify_dips(summary, interval=interval)
    support = support_intervals(read, summary, interval, reason)
    assert not np.isfinite(support.centroid).any()
    before = summary_shadow_times(summary, interval=interval)
    after = summary_shadow_times(summary, interval=interval, read=read)
    for name in ("shadow_time", "reason", "interval_entry", "time_std"):
        np.testing.assert_array_equal(after[name], before[name])


def test_a_sweep_with_connected_dips_is_classified_once(wire_sweep, monkeypatch):
    # the support of the several-minima pixels is measured on the sweep's one classification
    import shadowcam.lab.shadow_time as shadow_time

    frames, _ = _disc_sweep(wire_sweep)
    calls = []

    def counted(*args, **kwargs):
        calls.append(1)
        return classify_dips(*args, **kwargs)

    monkeypatch.setattr(shadow_time, "classify_dips", counted)
    result = _times(frames)
    assert len(calls) == 1
    assert np.mean(result["reason"] == OK) >= 0.98  # the connected dips were measured and timed
