"""Pushbroom: colours along the edge, linear between the pixel centres; uniform-time resampling."""

import numpy as np
import pytest

from shadowcam.cameras.pushbroom import assemble_pushbroom, resample_uniform_time, sample_along_edge


def test_sample_along_edge_interpolates_between_centres():
    image = np.zeros((6, 3, 3), np.float32)
    image[:, :, 0] = np.arange(6)[:, None]  # red = row index
    edge = np.array([2.5, 3.0, np.nan])  # 2.5 = centre of row 2; 3.0 = halfway rows 2 and 3
    out = sample_along_edge(image, edge)
    assert out.dtype == np.float32
    np.testing.assert_allclose(out[:2, 0], [2.0, 2.5])
    assert np.isnan(out[2]).all()


def test_assemble_and_resample():
    image = np.random.default_rng(0).random((8, 4, 3)).astype(np.float32)
    edges = np.array([[4.5] * 4, [3.5] * 4])
    broom = assemble_pushbroom(image, edges)
    np.testing.assert_allclose(broom[0], image[4])
    np.testing.assert_allclose(broom[1], image[3])
    times, uniform = resample_uniform_time(broom, np.array([0.0, 20.0]), step_s=5.0)
    np.testing.assert_allclose(times, [0, 5, 10, 15, 20])
    np.testing.assert_allclose(uniform[2], 0.5 * (image[4] + image[3]), rtol=1e-6)
    with pytest.raises(ValueError, match="step_s"):
        resample_uniform_time(broom, np.array([0.0, 20.0]), step_s=0)


# ---- the lab pushbroom: one sweep, edge from the shadow-time map --------------------------


@pytest.mark.parametrize("along", ["row", "col"])
def test_edge_from_time_map_is_the_exact_crossing(along):
    from shadowcam.cameras.pushbroom import edge_from_time_map

    speed = 0.8  # pixels per frame
    t = (np.arange(20.0) - 3.0) / speed * np.ones((6, 1))  # time grows along the columns
    if along == "col":
        t = t.T
    t[2, :] = np.nan if along == "row" else t[2, :]
    edge = edge_from_time_map(t, np.arange(12), along=along)
    expected = 3.0 + 0.5 + speed * np.arange(12.0)
    rows = [0, 1, 3, 4, 5] if along == "row" else list(range(6))
    np.testing.assert_allclose(edge[:, rows], np.repeat(expected[:, None], len(rows), 1), atol=1e-12)
    if along == "row":
        assert np.all(np.isnan(edge[:, 2]))  # no crossing through untimed pixels


def test_lab_pushbroom_from_one_rendered_sweep(timed_capture):
    from shadowcam.cameras.models import camera_coords_from_shadow_time
    from shadowcam.cameras.pushbroom import pushbroom_from_shadow_time

    description = {"scene": "tabletop", "seed": 3, "height": 40, "width": 40, "frames": 32,
                   "sweeps": [{"name": "u"}]}
    _, gt, shadow_time, _ = timed_capture(description)
    coords = camera_coords_from_shadow_time(shadow_time, description)
    assert coords.attrs["method"] == "pushbroom" and coords.attrs["along"] == "row"
    broom = pushbroom_from_shadow_time(shadow_time, sweep="u")
    assert broom.attrs["along"] == "row" and broom["pushbroom"].shape == (32, 40, 3)
    # physical fact: at the edge found in frame k, the exact shadow time is k
    edge = broom["edge"].values
    truth = gt["t_u"].values
    k, row = np.nonzero(np.isfinite(edge))
    position = edge[k, row] - 0.5
    left = np.clip(np.floor(position).astype(int), 0, 38)
    frac = position - left
    exact = (1 - frac) * truth[row, left] + frac * truth[row, left + 1]
    ok = np.isfinite(exact) & (np.abs(truth[row, left + 1] - truth[row, left]) < 2)  # no depth jump
    assert ok.sum() > 0.5 * 32 * 40
    assert np.median(np.abs(exact[ok] - k[ok])) <= 0.1 and np.mean(np.abs(exact[ok] - k[ok]) <= 0.5) >= 0.95
    # colours are the lit scene's colours, finite where an edge was found
    assert np.all(np.isfinite(broom["pushbroom"].values[np.isfinite(edge)]))
