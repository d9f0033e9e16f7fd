import numpy as np
import pytest

from shadowcam.lightfield.screen import homography_from_markers, screen_coordinates, screen_positions

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
