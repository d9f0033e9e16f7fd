"""Sensor noise on the several-lights renderer (``synthetic.noise``)."""

import numpy as np

from shadowcam.synthetic.lab.light_set_capture import render_light_set_capture
from shadowcam.synthetic.sensor import SensorModel, electrons_per_unit_radiance

BASE = {"scene": "tabletop", "seed": 2, "height": 16, "width": 16, "frames": 8, "supersample": 1,
        "lights": [{"kind": "point"}, {"kind": "point", "offset": [0.01, 0.01, 0.0]}]}


def test_noisy_frames_follow_the_poisson_gaussian_sensor_model_around_the_clean_render():
    clean = render_light_set_capture(BASE)
    noisy = render_light_set_capture({**BASE, "noise": True, "bit_depth": 12})
    sensor = SensorModel(bit_depth=12)
    scale = electrons_per_unit_radiance(clean["reference"].values, sensor=sensor)
    dn_per_radiance = sensor.gain * scale
    span = sensor.white_level - sensor.black_level
    z = []
    for key in ("reference", "frames_u", "frames_v"):
        mean = clean[key].values.astype(np.float64)
        signal_dn = mean * dn_per_radiance
        # variance in DN: shot (gain * DN signal) + read noise + rounding to an integer DN
        var_dn = sensor.gain * signal_dn + sensor.read_noise ** 2 + 1 / 12
        residual = (noisy[key].values - mean) * dn_per_radiance / np.sqrt(var_dn)
        # more than 6 sigma above the white level: clipped there, exactly
        saturated = signal_dn > span + 6 * np.sqrt(var_dn)
        np.testing.assert_allclose(noisy[key].values[saturated] * dn_per_radiance, span, rtol=1e-5)
        unclipped = signal_dn < span - 6 * np.sqrt(var_dn)
        z.append(residual[unclipped])
    z = np.concatenate(z)
    assert z.size > 10_000
    # standardised residuals: mean 0 and std 1 within 4 standard errors (n ~ 1.3e4)
    assert abs(z.mean()) < 4 / np.sqrt(z.size)
    assert abs(z.std() - 1) < 0.03
    # the ground truth is the renderer's, untouched by the sensor
    np.testing.assert_array_equal(noisy["t_center_u"].values, clean["t_center_u"].values)


def test_noise_is_seeded_and_absent_unless_asked():
    noisy = render_light_set_capture({**BASE, "noise": True})
    again = render_light_set_capture({**BASE, "noise": True})
    np.testing.assert_array_equal(noisy["frames_u"].values, again["frames_u"].values)
    clean = render_light_set_capture(BASE)
    off = render_light_set_capture({**BASE, "noise": False})
    np.testing.assert_array_equal(clean["frames_v"].values, off["frames_v"].values)
    assert not np.array_equal(noisy["frames_v"].values, clean["frames_v"].values)
