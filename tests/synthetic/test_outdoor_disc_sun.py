"""The disc sun: visible fraction of a uniform 0.53 deg disc above the terrain horizon.

Exact references: the area of a disc cut by a line (Monte Carlo over the disc), and a
straight ridge crest (an infinite horizontal line at height h above flat ground), whose
horizon seen from a ground point is the great circle through the point and the crest; the
penumbra on the ground, measured perpendicular to the crest, is
``2 sin(r) L / sin(e)`` wide (``L`` the distance from the point to the crest line, ``e``
the sun's elevation, ``r`` its angular radius), whatever the sun's azimuth.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from shadowcam.synthetic.outdoor.render import (SUN_DIAMETER_DEG, SampleGeometry, disc_fraction_above,
                                                sun_lit, sun_lit_fraction)
from shadowcam.synthetic.outdoor.sun import SunPath

R = np.radians(SUN_DIAMETER_DEG / 2)


@settings(max_examples=20, deadline=None)
@given(st.floats(-1.2, 1.2))
def test_disc_fraction_matches_monte_carlo_area(d):
    rng = np.random.default_rng(0)
    n = 400_000
    rho, phi = np.sqrt(rng.random(n)), 2 * np.pi * rng.random(n)
    y = rho * np.sin(phi)
    expected = np.mean(y > -d)  # centre at height d above the line
    assert abs(float(disc_fraction_above(d)) - expected) < 0.003  # ~ 4 sigma of the estimate


def test_disc_fraction_limits():
    assert disc_fraction_above([-1.0, -5.0, 0.0, 1.0, 3.0]).tolist() == [0.0, 0.0, 0.5, 1.0, 1.0]


def _straight_crest(sun, t, *, height=300.0, oblique_deg=25.0, distances):
    """Ground points at perpendicular distances from a crest line; exact horizon tables."""
    elev, az = sun.elevation_azimuth(t)
    a0 = az + np.radians(oblique_deg)  # azimuth from the points toward the crest, normal to it
    toward = np.array([np.sin(a0), np.cos(a0), 0.0])
    along = np.array([np.cos(a0), -np.sin(a0), 0.0])
    nodes = az + np.radians(0.25) * np.arange(-40, 41)
    D = np.asarray(distances, dtype=np.float64)
    horizon = np.arctan(height * np.cos(nodes - a0)[None, :] / D[:, None]).astype(np.float32)
    n = len(D)
    pos = -D[:, None] * toward
    geometry = SampleGeometry(
        sky=np.zeros(n, bool), position=pos, normal=np.tile([0.0, 0.0, 1.0], (n, 1)),
        albedo=np.full((n, 3), 0.5), ambient=np.full((n, 3), 0.5),
        view_dir=np.tile([0.0, 1.0, 0.0], (n, 1)), depth_z=np.ones(n), horizon=horizon,
        node_azimuth=nodes)
    # exact: the crest's great circle has normal u x w (w: point -> crest foot, up)
    w = D[:, None] * toward + height * np.array([0.0, 0.0, 1.0])
    normal = np.cross(w, along)
    normal *= np.sign(normal[:, 2:3]) / np.linalg.norm(normal, axis=1, keepdims=True)
    exact = disc_fraction_above(np.arcsin(normal @ sun.direction(t)) / R)
    return geometry, exact, np.linalg.norm(w, axis=1), elev, np.radians(oblique_deg)


@pytest.mark.parametrize("oblique_deg", [0.0, 25.0, 50.0])
def test_straight_crest_penumbra_fraction_width_and_centre(oblique_deg):
    sun = SunPath.from_start_elevation(20.0, latitude_deg=35.0, declination_deg=-18.0)
    t = sun.time_at_elevation(9.0)
    height = 300.0
    elev = np.radians(9.0)
    centre = height * np.cos(np.radians(oblique_deg)) / np.tan(elev)  # point-sun edge
    D = centre + np.arange(-150.0, 150.0, 0.05)
    geometry, exact, L, e, _ = _straight_crest(sun, t, height=height, oblique_deg=oblique_deg,
                                               distances=D)
    frac = sun_lit_fraction(geometry, sun, t)
    assert np.max(np.abs(frac - exact)) < 0.005
    partial = D[(frac > 0) & (frac < 1)]
    width = partial.max() - partial.min()
    L_c = np.hypot(centre, height)
    expected = 2 * np.sin(R) * L_c / np.sin(e)  # ~ L x 0.53 deg / sin(e)
    assert width == pytest.approx(expected, rel=0.01)
    half = D[np.argmin(np.abs(frac - 0.5))]
    assert half == pytest.approx(centre, abs=0.2)  # the penumbra's centre is the point sun's edge
    # the point sun (and the GT 'lit') switches there too; start/end offsets bound the penumbra
    lit = sun_lit(geometry, sun, t)
    assert D[lit].min() == pytest.approx(centre, abs=0.2)
    assert D[sun_lit(geometry, sun, t, offset_rad=R)].min() == pytest.approx(partial.max(), abs=0.1)
    assert D[sun_lit(geometry, sun, t, offset_rad=-R)].min() == pytest.approx(partial.min(), abs=0.1)


def test_zero_diameter_is_the_point_sun_and_bad_diameter_is_refused():
    sun = SunPath.from_start_elevation(20.0, latitude_deg=35.0, declination_deg=-18.0)
    t = sun.time_at_elevation(9.0)
    geometry, *_ = _straight_crest(sun, t, distances=np.linspace(1000, 2500, 200))
    np.testing.assert_array_equal(sun_lit_fraction(geometry, sun, t, diameter_deg=0.0),
                                  sun_lit(geometry, sun, t).astype(float))
    with pytest.raises(ValueError, match="diameter_deg"):
        sun_lit_fraction(geometry, sun, t, diameter_deg=-0.1)


def test_disc_sun_render_ground_truth_and_frames():
    """A small disc-sun render: the arrival times are the point sun's (penumbra centres), the
    penumbra starts before and ends after them, and a pixel differs from the point-sun frame
    exactly while its penumbra is passing (no nuisances, one sample per pixel)."""
    from shadowcam.synthetic.outdoor.capture import render_outdoor_capture
    from shadowcam.synthetic.outdoor.render import make_outdoor_scene

    scene = make_outdoor_scene(height=24, width=32, start_elevation_deg=12.0,
                               end_elevation_deg=6.0)
    off = dict(auto_exposure=False, shake_px=0.0, cloud=False, irregular_timing=False,
               dropped_frames=0)
    point = render_outdoor_capture(scene, frames=10, supersample=1, **off)
    disc = render_outdoor_capture(scene, frames=10, supersample=1,
                                  sun_diameter_deg=SUN_DIAMETER_DEG, **off)
    gp, gd = point.ground_truth, disc.ground_truth
    assert "penumbra_start_time_s" not in gp and gd.attrs["sun_diameter_deg"] == SUN_DIAMETER_DEG
    np.testing.assert_array_equal(gp["arrival_time_s"].values, gd["arrival_time_s"].values)
    cls3 = (gd["shadow_class"].values == 3) & ~gd["relit_after_arrival"].values
    assert cls3.sum() > 20
    T = gd["arrival_time_s"].values[cls3]
    start = gd["penumbra_start_time_s"].values[cls3]
    end = gd["penumbra_end_time_s"].values[cls3]
    assert np.all(start[np.isfinite(start)] < T[np.isfinite(start)])
    assert np.all(end[np.isfinite(end)] > T[np.isfinite(end)])
    times = disc.times_s
    diff = np.abs(disc.frames - point.frames).max(axis=-1)  # (K, rows, cols)
    for k, t in enumerate(times):
        outside = (np.nan_to_num(start, nan=np.inf) >= t) | (np.nan_to_num(end, nan=np.inf) <= t)
        assert np.all(diff[k][cls3][outside & np.isfinite(start)] < 1e-6)
        inside = (start < t) & (end > t) & (np.abs(t - T) > 0.1 * (end - start))
        assert np.all(diff[k][cls3][inside] > 1e-6)
