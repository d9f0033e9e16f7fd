"""Tests of shadowcam.outdoor.edges: one job and column strips give the same edges dataset."""

import numpy as np
import pytest
import xarray as xr

from shadowcam.outdoor.datasets import photometry_dataset
from shadowcam.outdoor.edges import edges_from_strips, track_column_strip, track_edges
from shadowcam.outdoor.normalise import normalise_frames
from shadowcam.outdoor.strips import load_strip, save_strip


@pytest.fixture(scope="module")
def capture(make_timelapse):
    scene = make_timelapse(width=60, n_frames=24, shake=1.5, noise=True, slope=0.3, seed=3)
    frames = xr.Dataset({"image": (("time", "row", "col", "channel"), np.asarray(scene["frames"]))},
                        coords={"time_s": ("time", scene["time_s"])})
    photometry = photometry_dataset(normalise_frames(iter(scene["frames"])), scene["time_s"])
    return scene, frames, photometry


def test_edges_follow_the_moving_shadow(capture):
    scene, frames, photometry = capture
    edges = track_edges(frames, photometry)
    rows = edges["edge_row"].values
    assert rows.shape == (24, 60)
    assert np.isfinite(rows).mean() > 0.8
    # the shadow edge climbs (smaller row) as the sun sets
    assert np.nanmedian(rows[-1]) < np.nanmedian(rows[0])
    assert edges.attrs["median_interval_s"] == pytest.approx(np.median(np.diff(scene["time_s"])))


def test_strips_saved_and_merged_equal_one_job(capture, tmp_path):
    scene, frames, photometry = capture
    single = track_edges(frames, photometry, min_confidence=0.5)
    paths = []
    for index in range(3):
        path = tmp_path / f"strip{index}.npz"
        save_strip(track_column_strip(frames, photometry, index=index, count=3, min_confidence=0.5), path)
        paths.append(path)
    merged = edges_from_strips([load_strip(p) for p in reversed(paths)], photometry, scene["time_s"],
                               width=60, min_confidence=0.5)
    xr.testing.assert_identical(merged, single)


def test_wrong_strips_and_options_are_refused(capture, tmp_path):
    scene, frames, photometry = capture
    strip = track_column_strip(frames, photometry, index=0, count=2)
    with pytest.raises(ValueError, match="strips"):
        edges_from_strips([strip, strip], photometry, scene["time_s"], width=60)
    with pytest.raises(ValueError, match="unknown option"):
        track_edges(frames, photometry, half_windw=3)
    with pytest.raises(ValueError, match="index"):
        track_column_strip(frames, photometry, index=2, count=2)
    with pytest.raises(ValueError, match=".npz"):
        save_strip(strip, tmp_path / "strip.txt")
    np.savez(tmp_path / "other.npz", a=np.zeros(2))
    with pytest.raises(ValueError, match="missing"):
        load_strip(tmp_path / "other.npz")


def test_a_first_pass_without_the_shade_field_divides_its_uniform_cloud_shade(capture):
    # a photometry.nc written before the field carries one cloud shade per frame: tracked as
    # the same shade given as a uniform field over the frame
    scene, frames, photometry = capture
    shade = np.ones(photometry.sizes["time"])
    shade[8:14] = 0.6
    old = photometry.drop_vars([name for name in ("shade_field", "shade_levels", "shade_rows", "shade_cols")
                                if name in photometry]).assign(cloud_shade=("time", shade))
    uniform = old.assign(shade_field=(("time", "block_row", "block_col"), shade[:, None, None].astype(np.float32)),
                         shade_rows=("block_row", [0.0]), shade_cols=("block_col", [0.0]))
    tracked_old, tracked_uniform = track_edges(frames, old), track_edges(frames, uniform)
    np.testing.assert_array_equal(tracked_old["edge_row"].values, tracked_uniform["edge_row"].values)
    # and the shade is divided out: the tracked edge differs from a pass with no shade at all
    plain = track_edges(frames, old.assign(cloud_shade=("time", np.ones_like(shade))))
    assert not np.array_equal(np.nan_to_num(plain["edge_row"].values), np.nan_to_num(tracked_old["edge_row"].values))
