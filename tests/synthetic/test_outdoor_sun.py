"""Tests of shadowcam.synthetic.outdoor.sun: ephemeris against known values, inverse, colour model."""

import numpy as np
import pytest

from shadowcam.synthetic.outdoor.sun import (SunPath, airmass_KastenYoung1989, elevation_azimuth,
                           hour_angle_at_elevation, solar_direction, sun_colour)


@pytest.mark.parametrize("lat, dec", [(35.0, -18.0), (47.5, 23.4), (10.0, 5.0), (-33.9, -20.0)])
def test_solar_noon_elevation_and_meridian(lat, dec):
    d = solar_direction(0.0, latitude_deg=lat, declination_deg=dec)
    elevation, azimuth = elevation_azimuth(d)
    assert np.linalg.norm(d) == pytest.approx(1.0, abs=1e-12)
    assert elevation == pytest.approx(90.0 - abs(lat - dec), abs=1e-9)
    # at noon the sun is due south when it culminates south of the zenith, else due north
    assert azimuth == pytest.approx(180.0 if lat > dec else 0.0, abs=1e-9)


def test_dev_ridge_frame0_direction_is_reproduced():
    # shared data README 2.3 / meta.json: lat 35 N, decl -18 deg, elevation 20 deg at t = 0
    path = SunPath.from_start_elevation(20.0, latitude_deg=35.0, declination_deg=-18.0)
    assert path.hour_angle0_deg == pytest.approx(48.200365, abs=1e-6)
    np.testing.assert_allclose(path.direction(0.0), [-0.708993849, -0.616725177, 0.342020143],
                               atol=1e-9)


def test_sun_path_sets_in_the_west_at_15_deg_per_hour():
    path = SunPath.from_start_elevation(20.0, latitude_deg=35.0, declination_deg=-18.0)
    t = np.linspace(0.0, path.time_at_elevation(1.5), 50)
    e, a = path.elevation_azimuth(t)
    assert np.all(np.diff(e) < 0)                       # setting
    assert np.all(np.diff(np.unwrap(a)) > 0)            # moving clockwise (toward the west)
    assert np.degrees(e[-1]) == pytest.approx(1.5, abs=1e-9)
    assert path.hour_angle(3600.0) - path.hour_angle(0.0) == pytest.approx(15.0)
    # the elevation formula: sin e = sin(lat) sin(dec) + cos(lat) cos(dec) cos(H)
    h = np.radians(path.hour_angle(t))
    sin_e = (np.sin(np.radians(35)) * np.sin(np.radians(-18))
             + np.cos(np.radians(35)) * np.cos(np.radians(-18)) * np.cos(h))
    np.testing.assert_allclose(np.sin(e), sin_e, atol=1e-12)


def test_hour_angle_inverse_and_unreachable_elevation():
    h = hour_angle_at_elevation(12.3, latitude_deg=50.0, declination_deg=10.0)
    d = solar_direction(h, latitude_deg=50.0, declination_deg=10.0)
    assert np.degrees(np.arcsin(d[2])) == pytest.approx(12.3, abs=1e-9)
    with pytest.raises(ValueError, match="elevation_deg"):
        hour_angle_at_elevation(80.0, latitude_deg=50.0, declination_deg=-20.0)
    with pytest.raises(ValueError, match="latitude_deg"):
        solar_direction(0.0, latitude_deg=95.0, declination_deg=0.0)


def test_airmass_and_sunset_colour():
    assert airmass_KastenYoung1989(90.0) == pytest.approx(1.0, abs=1e-3)
    assert airmass_KastenYoung1989(0.0) == pytest.approx(37.92, abs=0.01)  # published value
    np.testing.assert_allclose(sun_colour(20.0, reference_elevation_deg=20.0), [1.0, 0.97, 0.92])
    low = sun_colour(1.5, reference_elevation_deg=20.0)
    assert np.all(low < [1.0, 0.97, 0.92])
    assert low[0] / low[2] > 5.0  # blue is scattered most: the low sun is red
    # README 2.4: the mean of the sun colour drops to ~0.2 at 1.5 deg
    assert low.mean() == pytest.approx(0.2, abs=0.03)
