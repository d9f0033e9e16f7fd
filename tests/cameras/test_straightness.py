"""Tests of shadowcam.cameras.straightness: straight edges measure straight, bent ones do not."""

import numpy as np
import pytest

from shadowcam.cameras.straightness import edge_points_from_image, edge_straightness


def test_points_on_lines_are_straight_and_noise_sets_the_rms():
    s = np.linspace(0, 40, 200)
    line_a = np.stack([3 + 0.3 * s, 5 + s], axis=1)
    rng = np.random.default_rng(0)
    line_b = np.stack([s, 2 * s], axis=1)
    noisy = np.stack([10 + s, 20 - 0.3 * s], axis=1)
    noisy = noisy + rng.normal(0, 0.2, len(s))[:, None] * np.array([0.3, 1.0]) / np.hypot(0.3, 1)
    points = np.concatenate([line_a, line_b, noisy])
    labels = np.repeat([4, 7, 9], len(s))
    result = edge_straightness(points, labels=labels)
    assert list(result.labels) == [4, 7, 9] and list(result.n_points) == [200] * 3
    assert result.rms[0] < 1e-12 and result.rms[1] < 1e-12
    assert result.rms[2] == pytest.approx(0.2, rel=0.15)
    assert result.overall_rms == pytest.approx(result.rms[2] / np.sqrt(3), rel=1e-9)


def test_edges_with_too_few_points_are_not_measured():
    result = edge_straightness(np.array([[0.0, 0.0], [1.0, 1.0]]), labels=np.array([1, 1]))
    assert np.isnan(result.rms[0]) and np.isnan(result.overall_rms)


def _edge_image(signed_distance):
    """Antialiased step (linear ramp one pixel wide) across the zero level of the distance."""
    return np.clip(signed_distance + 0.5, 0.0, 1.0)


def test_image_edges_straight_versus_bent():
    rows, cols = np.mgrid[0:64, 0:64].astype(np.float64)
    a = np.radians(12)
    straight = (cols - 30) * np.cos(a) - (rows - 32) * np.sin(a)
    bent = np.hypot(rows - 32, cols + 10) - 45  # circle of radius 45 px
    results = []
    for distance in (straight, bent):
        image = np.repeat(_edge_image(distance)[..., None], 3, axis=2)
        labels = np.where(np.abs(distance) < 3, 1, 0)
        points, point_labels = edge_points_from_image(image, labels)
        assert len(points) > 50 and np.all(point_labels == 1)
        results.append(edge_straightness(image, labels=labels).overall_rms)
    assert results[0] < 0.02
    assert results[1] > 1.0


def test_invalid_inputs_name_the_parameter():
    with pytest.raises(ValueError, match="labels"):
        edge_straightness(np.zeros((5, 2)), labels=np.zeros(4, dtype=int))
    with pytest.raises(ValueError, match="data"):
        edge_straightness(np.zeros((5, 3)), labels=np.zeros(5, dtype=int))
    with pytest.raises(ValueError, match="min_points"):
        edge_straightness(np.zeros((5, 2)), labels=np.zeros(5, dtype=int), min_points=2)
    with pytest.raises(ValueError, match="labels"):
        edge_points_from_image(np.zeros((8, 8)), np.zeros((8, 7), dtype=int))
