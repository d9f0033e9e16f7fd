"""The light-field renderer's exposure: a still or a moving wire over each bracket."""

import numpy as np
import pytest

from shadowcam.lightfield import hdr, rays
from shadowcam.synthetic.lightfield.capture import LightFieldCapture, sweep_frames, wire_cover


@pytest.mark.parametrize("blur", [0.0, 0.5, 3.0, 8.0])
def test_wire_cover_integrates_the_moving_wire_exactly(blur):
    cover = wire_cover(60, 20.0, blur=blur)
    assert np.all((cover >= 0) & (cover <= 1 + 1e-12))
    assert np.isclose(cover.sum(), 12.0)                                        # the wire's width, always
    assert np.isclose(cover @ (np.arange(60) + 0.5) / cover.sum(), 26.0)        # centred on the frame time
    # second moment: a 12-bin box convolved with a `blur`-bin box: (12^2 + blur^2) / 12
    var = cover @ (np.arange(60) + 0.5 - 26.0) ** 2 / cover.sum()
    assert np.isclose(var, (12.0**2 + blur**2) / 12.0, rtol=1e-3, atol=2 / 12)  # bins of width 1: +1/12 at most


def _time_error(shutter):
    capture = LightFieldCapture(shape=(48, 48), n_frames=48, quadrature=600, noise=False, shutter=shutter)
    q = capture.responsivity()
    truth = {}
    frames = sweep_frames(capture, 1, "x", responsivity=q, truth=truth)
    blocks = hdr.merge_stream(frames, capture.exposure_times, black_level=capture.sensor.black_level,
                              white_level=capture.sensor.white_level, gain=capture.sensor.gain,
                              read_noise=capture.sensor.read_noise, responsivity=q)
    found = rays.sweep_mask_positions(blocks, capture.shape, mask_start=capture.mask_start, mask_step=capture.step,
                                      method="dip_centroid")
    error = (found["position"] - truth["mask_centre"]) / capture.step
    time = (truth["mask_centre"] - capture.mask_start) / capture.step
    ok = np.isfinite(error) & np.isfinite(time)
    phase = 2 * np.pi * (time[ok] % 1.0)
    basis = np.c_[np.cos(phase), np.sin(phase), np.ones(ok.sum())]
    coef, *_ = np.linalg.lstsq(basis, error[ok], rcond=None)
    return error[ok].std(), float(np.hypot(coef[0], coef[1]))


def test_a_still_wire_leaves_a_frame_phase_bias_that_an_open_shutter_removes():
    # a still wire sampled at whole frames: the dip centroid's error is periodic in the
    # shadow's phase between frames; exposing over the frame interval integrates it away
    still_std, still_ripple = _time_error(0.0)
    open_std, open_ripple = _time_error(1.0)
    # measured at 48 x 48: ripple amplitude 0.029 -> 0.008 frame, error std 0.032 -> 0.010
    assert still_ripple > 0.02
    assert open_ripple < 0.4 * still_ripple
    assert open_std < 0.5 * still_std


def test_shutter_outside_the_frame_interval_is_refused():
    with pytest.raises(ValueError, match="shutter"):
        LightFieldCapture(shutter=1.5)
