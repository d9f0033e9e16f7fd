import numpy as np
import pytest

from shadowcam.lightfield.screen import flux_centroids, homography_from_markers, screen_coordinates, screen_positions

H = np.array([[0.02, 1.3, -60.0], [1.25, -0.01, -58.0], [3e-4, -1e-4, 1.0]])


def _apply(h, rc):
    p = np.c_[rc, np.ones(len(rc))] @ h.T
    return p[:, :2] / p[:, 2:]


def test_homography_from_markers_maps_every_pixel():
    markers = np.array([[0, 0], [0, 95], [95, 0], [95, 95], [40, 60]], float)
    h = homography_from_markers(markers, _apply(H, markers))
    xy, area = screen_coordinates(h, (96, 96))
    rows, cols = np.meshgrid(np.arange(96), np.arange(96), indexing="ij")
    truth = _apply(H, np.c_[rows.ravel(), cols.ravel()]).reshape(96, 96, 2)
    assert np.abs(xy - truth).max() < 1e-6
    assert np.allclose(area[0, 0], abs(np.linalg.det(H[:2, :2]) - 0), rtol=0.05)


def test_collinear_markers_and_missing_positions_are_refused():
    with pytest.raises(ValueError, match="pixels must not be degenerate"):
        homography_from_markers([[0, 0], [1, 1], [2, 2], [3, 3]], [[0, 0], [1, 1], [2, 2], [3, 3]])
    screens = [{"name": "a", "position_mm": 250.0, "homography": H.tolist()},
               {"name": "b", "homography": H.tolist()}]
    with pytest.raises(ValueError, match=r"screens\[1\].position_mm must be given"):
        screen_positions({"screens": screens})
    with pytest.raises(ValueError, match="screens must list at least two"):
        screen_positions({"screens": screens[:1]})
    screens[1]["position_mm"] = 150.0
    assert [s["name"] for s in screen_positions({"screens": screens})] == ["b", "a"]


def test_flux_centroids_of_a_linear_irradiance_are_exact():
    # a symmetric footprint of variance s^2 over E = E0 + k u puts the flux centroid s^2 k / E0
    # off the centre (exact for a linear E); here along rows, on a 2 mm x 3 mm pixel grid
    xy = np.stack(np.meshgrid(3.0 * np.arange(8.0), 2.0 * np.arange(6.0), indexing="xy"), -1)
    irradiance = 10.0 + 0.5 * np.arange(6.0)[:, None] * np.ones((1, 8))
    got = flux_centroids(xy, irradiance, footprint_variance=1.0 / 6.0)
    assert np.allclose(got[..., 0], xy[..., 0], atol=1e-12)
    assert np.allclose(got[..., 1][1:-1], (xy[..., 1] + 2.0 * 0.5 / 6.0 / irradiance)[1:-1], rtol=1e-12)
    assert np.array_equal(flux_centroids(xy, irradiance, footprint_variance=0.0), xy)


def test_flux_centroids_match_a_tent_footprints_integral_and_stay_inside_it():
    # a ring-like irradiance E(u) = 1 + 0.6 cos(2 pi u / 9) (u in px), integrated with the tent
    # footprint (variance 1/6) numerically: the first-order centroid is within 0.02 px of the
    # integral's where the relative slope is moderate
    u = np.arange(40.0)
    t = np.linspace(-1, 1, 2001)
    w = 1 - np.abs(t)

    def e(x):
        return 1 + 0.6 * np.cos(2 * np.pi * x / 9.0)

    measured = np.array([np.sum(w * e(c + t)) / np.sum(w) for c in u])
    exact = np.array([np.sum(w * e(c + t) * t) / np.sum(w * e(c + t)) for c in u])
    xy = np.stack(np.meshgrid(u, np.arange(3.0), indexing="xy"), -1)
    got = flux_centroids(xy, np.tile(measured, (3, 1)), footprint_variance=1.0 / 6.0)[1, 1:-1, 0] - u[1:-1]
    assert np.max(np.abs(got - exact[1:-1])) < 0.02
    steep = np.tile(np.exp(3.0 * u), (3, 1))              # a centroid lies inside the footprint
    shift = flux_centroids(xy, steep, footprint_variance=1.0 / 6.0)[1, 1:-1, 0] - u[1:-1]
    assert np.allclose(shift, np.sqrt(0.5))
    with pytest.raises(ValueError, match="footprint_variance"):
        flux_centroids(xy, steep, footprint_variance=-1.0)
