"""Column edges: exact sub-pixel row for box-filtered steps, lowest transition, band preference."""

import numpy as np
import pytest

from shadowcam.outdoor.edge_tracking import column_edges


def _box_filtered(height, edges, ss=16, continuous=False):
    """Coverage of pixels (lit above the edge, pixel-edge rows) by ``ss`` sub-samples per side.

    The edge is constant over each column (``edges[c]``), or with `continuous` the
    straight line through ``(c + 0.5, edges[c])``."""
    sub = (np.arange(height)[:, None] + (np.arange(ss) + 0.5) / ss).ravel()
    width = len(edges)
    sub_c = (np.arange(width)[:, None] + (np.arange(ss) + 0.5) / ss).ravel()
    line = np.interp(sub_c, np.arange(width) + 0.5, edges) if continuous else np.repeat(edges, ss)
    lit = sub[:, None] < line[None, :]
    return lit.reshape(height, ss, width, ss).mean(axis=(1, 3))


def test_horizontal_steps_are_located_exactly():
    edges = np.array([5.5, 10.0, 10.25, 17.9, 3.01])
    cover = np.clip(edges[None, :] - np.arange(24)[:, None], 0, 1)  # exact box-filtered coverage
    row, confidence, n = column_edges(cover, valid=np.ones_like(cover, bool))
    np.testing.assert_allclose(row, edges, atol=1e-6)
    assert (confidence > 0.99).all() and (n == 1).all()


def test_slanted_edge_gives_the_row_at_the_column_centre():
    edges = 12.0 + 0.4 * (np.arange(30) + 0.5)  # slope 0.4 rows per column
    cover = _box_filtered(40, edges, continuous=True)
    row, _, _ = column_edges(cover, valid=np.ones_like(cover, bool))
    np.testing.assert_allclose(row[1:-1], edges[1:-1], atol=0.02)


def test_lowest_transition_and_no_edge_cases():
    cover = np.ones((20, 3), np.float32)
    cover[5:8, 0] = 0  # a shadowed patch high up ...
    cover[14:, 0] = 0  # ... and the main edge at row 14
    cover[:, 1] = 0  # fully shadowed column
    row, confidence, n = column_edges(cover, valid=np.ones_like(cover, bool))
    assert row[0] == pytest.approx(14.0) and n[0] == 2
    assert np.isnan(row[1]) and confidence[1] == 0 and np.isnan(row[2])


def test_sky_rows_never_hold_the_edge():
    cover = np.ones((10, 1), np.float32)
    cover[:3] = 0.1  # dark sky at the top
    cover[6:] = 0.0
    valid = np.ones_like(cover, bool)
    valid[:3] = False
    row, _, n = column_edges(cover, valid=valid)
    assert row[0] == pytest.approx(6.0) and n[0] == 1


def test_band_and_previous_edge_are_preferred_and_noisy_steps_score_lower():
    cover = np.ones((30, 2), np.float32)
    cover[8:11] = 0  # spurious dark feature
    cover[20:] = 0
    band = np.zeros_like(cover, bool)
    band[6:12] = True
    row, confidence, _ = column_edges(cover, valid=np.ones_like(cover, bool), band=band)
    assert row[0] == pytest.approx(8.0)
    rng = np.random.default_rng(3)
    noisy = np.clip(cover + rng.normal(0, 0.2, cover.shape), 0, 1)
    _, low, _ = column_edges(noisy, valid=np.ones_like(cover, bool), previous=np.array([20.0, 20.0]))
    assert (low < confidence).all()


def test_moving_edge_in_the_band_wins_over_a_static_transition_near_the_previous_edge():
    # a pixel shadowed from the start but taken for lit sits over a shadowed one near the bottom:
    # a lit-above / shadowed-below pair that never moves. The column's previous edge was put
    # there (frame 0 has no band); the shadow edge, moving in the band, must be found.
    cover = np.ones((40, 1), np.float32)
    cover[20:] = 0.0  # the ridge shadow's edge at row 20, moving (in the band)
    cover[34] = 1.0  # the static pair: rows 34 (lit) / 35 (shadowed)
    band = np.zeros_like(cover, bool)
    band[18:22] = True
    row, _, n = column_edges(cover, valid=np.ones_like(cover, bool), band=band, previous=np.array([35.0]))
    assert n[0] == 2
    assert row[0] == pytest.approx(20.0)
