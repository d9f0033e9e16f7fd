"""The sun: ephemeris (direction toward the sun at any time) and its sunset colour.

Spherical astronomy without refraction: at latitude ``phi``, solar declination ``delta``
and hour angle ``H`` (0 at local apparent noon, +15 deg per hour, positive afternoon), the
unit vector toward the sun in world coordinates (x east, y north, z up) is::

    east  = -cos(delta) sin(H)
    north =  cos(phi) sin(delta) - sin(phi) cos(delta) cos(H)
    up    =  sin(phi) sin(delta) + cos(phi) cos(delta) cos(H)      (= sin(elevation))

Compass azimuth = ``atan2(east, north)``, clockwise from north. The sun's colour follows
Kasten-Young air mass with per-channel optical depths (as the shared dev_ridge data).

Offers
------
solar_direction : unit vector(s) toward the sun from hour angle, latitude, declination.
hour_angle_at_elevation : afternoon hour angle (deg) at which the sun has a given elevation.
elevation_azimuth : (elevation, compass azimuth) in degrees of direction vectors.
SunPath : a continuous ephemeris ``t (s since frame 0) -> direction``.
airmass_KastenYoung1989 : relative optical air mass at an elevation.
sun_colour : linear RGB tint of the sun relative to a reference elevation.
"""

from dataclasses import dataclass

import numpy as np

#: hour angle rate, degrees per second (15 deg per hour)
DEG_PER_S = 15.0 / 3600.0


def solar_direction(hour_angle_deg, *, latitude_deg, declination_deg):
    """Unit vector(s) toward the sun.

    Parameters
    ----------
    hour_angle_deg : float or (...,) ndarray
        Hour angle, degrees (0 at apparent noon, positive afternoon).
    latitude_deg, declination_deg : float, keyword-only
        Observer latitude (north positive) and solar declination, degrees.

    Returns
    -------
    (..., 3) ndarray
        (east, north, up) components.
    """
    if not -90.0 <= latitude_deg <= 90.0:
        raise ValueError(f"latitude_deg must be in [-90, 90]; got {latitude_deg}")
    if not -23.5 <= declination_deg <= 23.5:
        raise ValueError(f"declination_deg must be in [-23.5, 23.5]; got {declination_deg}")
    h = np.radians(np.asarray(hour_angle_deg, dtype=np.float64))
    phi, delta = np.radians(latitude_deg), np.radians(declination_deg)
    east = -np.cos(delta) * np.sin(h)
    north = np.cos(phi) * np.sin(delta) - np.sin(phi) * np.cos(delta) * np.cos(h)
    up = np.sin(phi) * np.sin(delta) + np.cos(phi) * np.cos(delta) * np.cos(h)
    return np.stack([east, north, up], axis=-1)


def hour_angle_at_elevation(elevation_deg, *, latitude_deg, declination_deg):
    """Afternoon hour angle (deg, >= 0) at which the sun stands at `elevation_deg`.

    Raises ``ValueError`` if the sun never reaches that elevation on that day.
    """
    phi, delta = np.radians(latitude_deg), np.radians(declination_deg)
    cos_h = ((np.sin(np.radians(elevation_deg)) - np.sin(phi) * np.sin(delta))
             / (np.cos(phi) * np.cos(delta)))
    if not -1.0 <= cos_h <= 1.0:
        raise ValueError(f"elevation_deg: the sun does not reach {elevation_deg} deg at latitude "
                         f"{latitude_deg}, declination {declination_deg}")
    return float(np.degrees(np.arccos(cos_h)))


def elevation_azimuth(directions):
    """Elevation and compass azimuth (degrees) of (..., 3) unit vectors (east, north, up)."""
    d = np.asarray(directions, dtype=np.float64)
    if d.shape[-1] != 3:
        raise ValueError(f"directions must be (..., 3); got {d.shape}")
    elevation = np.degrees(np.arcsin(np.clip(d[..., 2], -1.0, 1.0)))
    azimuth = np.degrees(np.arctan2(d[..., 0], d[..., 1])) % 360.0
    return elevation, azimuth


@dataclass(frozen=True)
class SunPath:
    """Continuous ephemeris of one afternoon.

    Parameters
    ----------
    latitude_deg, declination_deg : float
    hour_angle0_deg : float
        Hour angle at ``t = 0`` (frame 0).
    """

    latitude_deg: float
    declination_deg: float
    hour_angle0_deg: float

    @classmethod
    def from_start_elevation(cls, start_elevation_deg, *, latitude_deg, declination_deg):
        """The afternoon path whose elevation at ``t = 0`` is `start_elevation_deg`."""
        h0 = hour_angle_at_elevation(start_elevation_deg, latitude_deg=latitude_deg,
                                     declination_deg=declination_deg)
        return cls(float(latitude_deg), float(declination_deg), h0)

    def hour_angle(self, t_s):
        """Hour angle (deg) at times `t_s` (seconds since frame 0)."""
        return self.hour_angle0_deg + DEG_PER_S * np.asarray(t_s, dtype=np.float64)

    def direction(self, t_s):
        """(..., 3) unit vector toward the sun at times `t_s` (seconds)."""
        return solar_direction(self.hour_angle(t_s), latitude_deg=self.latitude_deg,
                               declination_deg=self.declination_deg)

    def elevation_azimuth(self, t_s):
        """Elevation and compass azimuth (radians) at times `t_s`; both continuous in t."""
        d = self.direction(t_s)
        return (np.arcsin(np.clip(d[..., 2], -1.0, 1.0)), np.arctan2(d[..., 0], d[..., 1]))

    def time_at_elevation(self, elevation_deg):
        """Seconds after ``t = 0`` at which the (setting) sun reaches `elevation_deg`."""
        h = hour_angle_at_elevation(elevation_deg, latitude_deg=self.latitude_deg,
                                    declination_deg=self.declination_deg)
        return (h - self.hour_angle0_deg) / DEG_PER_S


def airmass_KastenYoung1989(elevation_deg):
    """Relative optical air mass (Kasten & Young 1989) at `elevation_deg` (> -6 deg)."""
    e = np.asarray(elevation_deg, dtype=np.float64)
    if np.any(e <= -6.0):
        raise ValueError("elevation_deg: the Kasten-Young formula needs elevations above -6 deg")
    return 1.0 / (np.sin(np.radians(e)) + 0.50572 * (e + 6.07995) ** -1.6364)


#: per-channel (R, G, B) optical depths and the sun's tint at the reference elevation
SUN_OPTICAL_DEPTH = (0.05, 0.085, 0.16)
SUN_TINT_REFERENCE = (1.0, 0.97, 0.92)


def sun_colour(elevation_deg, *, reference_elevation_deg, optical_depth=SUN_OPTICAL_DEPTH,
               tint=SUN_TINT_REFERENCE):
    """Linear RGB sun colour ``tint * exp(-tau (m(e) - m(e_ref)))``.

    Parameters
    ----------
    elevation_deg : float or (K,) ndarray
    reference_elevation_deg : float, keyword-only
        Elevation at which the colour equals `tint`.
    optical_depth, tint : 3-sequences, keyword-only

    Returns
    -------
    (..., 3) ndarray
    """
    dm = (airmass_KastenYoung1989(elevation_deg)
          - airmass_KastenYoung1989(reference_elevation_deg))
    tau = np.asarray(optical_depth, dtype=np.float64)
    return np.asarray(tint, dtype=np.float64) * np.exp(-np.multiply.outer(dm, tau))
