import numpy as np

from shadowcam.lightfield import hdr, rays
from shadowcam.synthetic.lightfield.capture import LightFieldCapture, sweep_frames


def test_sweep_mask_positions_match_the_rays_ground_truth():
    capture = LightFieldCapture(shape=(48, 48), n_frames=32, quadrature=500)
    q = capture.responsivity()
    truth = {}
    frames = sweep_frames(capture, 0, "x", responsivity=q, truth=truth)
    blocks = hdr.merge_stream(frames, capture.exposure_times, black_level=capture.sensor.black_level,
                              white_level=capture.sensor.white_level, gain=capture.sensor.gain,
                              read_noise=capture.sensor.read_noise, responsivity=q)
    result = rays.sweep_mask_positions(blocks, capture.shape, mask_start=capture.mask_start,
                                       mask_step=capture.step)
    ok = result["flags"] == 0
    beam = truth["irradiance"] > 0.2 * truth["irradiance"].max()
    assert ok[beam].mean() > 0.9
    error = np.abs(result["position"] - truth["mask_centre"])[ok & beam]
    assert np.median(error) < 0.15 * capture.step
    lit = result["lit_level"][ok & beam] / truth["irradiance"][ok & beam]
    assert np.median(np.abs(lit - 1)) < 0.01
