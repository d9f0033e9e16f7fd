"""Keyframes: unreliable frames are detected and their edges interpolated in seconds."""

import numpy as np
import pytest

from shadowcam.outdoor.keyframes import interpolate_edges, select_keyframes


def _edges():
    time_s = np.array([0.0, 50.0, 110.0, 160.0, 300.0, 350.0])  # irregular, with a gap
    edge = 40.0 - 0.02 * time_s[:, None] + np.zeros((1, 8))
    confidence = np.full(edge.shape, 0.95)
    return time_s, edge, confidence


def test_cloud_frame_is_not_a_keyframe_and_is_interpolated_in_seconds():
    time_s, edge, confidence = _edges()
    measured = edge.copy()
    measured[3] = 10.0  # a cloud: wrong edge, low confidence
    confidence[3] = 0.2
    key = select_keyframes(confidence, measured)
    assert key.tolist() == [True, True, True, False, True, True]
    filled, interpolated = interpolate_edges(measured, confidence, time_s, is_keyframe=key)
    np.testing.assert_allclose(filled, edge, atol=1e-5)  # linear in time: exact
    assert interpolated[3].all() and interpolated.sum() == 8


def test_low_confidence_column_of_a_keyframe_and_edges_at_the_ends():
    time_s, edge, confidence = _edges()
    confidence[4, 2] = 0.1
    confidence[0, 5] = 0.1  # no reliable edge before: cannot interpolate
    filled, interpolated = interpolate_edges(edge, confidence, time_s, is_keyframe=np.ones(6, bool))
    assert filled[4, 2] == pytest.approx(edge[4, 2]) and interpolated[4, 2]
    assert np.isnan(filled[0, 5])


def test_time_must_increase():
    time_s, edge, confidence = _edges()
    with pytest.raises(ValueError, match="increase"):
        interpolate_edges(edge, confidence, time_s[::-1], is_keyframe=np.ones(6, bool))
