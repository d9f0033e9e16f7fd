"""Tests of shadowcam.io.ground_truth: formats converted to the standard GT Dataset."""

from pathlib import Path

import numpy as np
import pytest

from shadowcam.io.ground_truth import REQUIRED, check_ground_truth, load_ground_truth, mitsuba_lab_npz_to_dataset

REPO = Path(__file__).resolve().parents[2]


def lab_arrays(height=6, width=7, n_v=4, n_u=5, seed=0):
    """gt.npz-like arrays with a non-square dual grid (catches u/v transposition)."""
    rng = np.random.default_rng(seed)
    return {
        "t_u": rng.uniform(0, n_u - 1, (height, width)).astype(np.float32),
        "t_v": rng.uniform(0, n_v - 1, (height, width)).astype(np.float32),
        "lit": rng.random((height, width)) > 0.3,
        "P": rng.normal(size=(height, width, 3)).astype(np.float32),
        "reference_linear": rng.random((height, width, 3), dtype=np.float32),
        "reciprocal": rng.random((n_v, n_u, 3), dtype=np.float32),
        "dual_cam_visible": rng.random((n_v, n_u)) > 0.5,
        "dual_cam_xy": rng.random((n_v, n_u, 2), dtype=np.float32),
        "some_future_key": np.zeros(3),
    }


def test_lab_npz_conversion_dims_and_values():
    arrays = lab_arrays()
    ds = mitsuba_lab_npz_to_dataset(arrays)
    for name, dims in REQUIRED.items():
        assert ds[name].dims == dims
    assert ds.sizes == {"row": 6, "col": 7, "v": 4, "u": 5, "channel": 3, "xyz": 3, "cam_axis": 2}
    # dual pixel (row j, col i) <-> v = j, u = i
    assert float(ds["reciprocal"].sel(v=3, u=1, channel="B")) == arrays["reciprocal"][3, 1, 2]
    assert bool(ds["dual_cam_visible"].sel(v=2, u=4)) == arrays["dual_cam_visible"][2, 4]
    assert float(ds["t_u"].sel(row=5, col=6)) == arrays["t_u"][5, 6]
    assert ds["t_u"].attrs["units"] == "frame" and ds["lit"].dtype == bool
    np.testing.assert_array_equal(ds["P"].values, arrays["P"])
    assert "some_future_key" not in ds
    del arrays["dual_cam_visible"]
    with pytest.raises(ValueError, match="dual_cam_visible"):
        mitsuba_lab_npz_to_dataset(arrays)


def _manifest(write_manifest, tmp_path, fmt, file):
    doc = {"name": "g", "kind": "lab", "light": "point", "root": ".", "sweeps": {"u": {"files": "u.png"}},
           "timing": {"source": "rate", "rate_hz": 1.0}, "ground_truth": {"format": fmt, "file": file}}
    (tmp_path / "u.png").write_bytes(b"")  # a sweep file (not decoded here)
    return write_manifest(tmp_path / "g.yaml", doc)


def test_load_lab_npz_via_manifest_verifies_checksum(tmp_path, write_manifest):
    arrays = lab_arrays()
    np.savez(tmp_path / "gt.npz", **arrays)
    path = _manifest(write_manifest, tmp_path, "mitsuba_lab_npz", "gt.npz")
    ds = load_ground_truth(path)
    np.testing.assert_array_equal(ds["t_v"].values, arrays["t_v"])
    assert ds.attrs["source_format"] == "mitsuba_lab_npz" and len(ds.attrs["source_sha256"]) == 64
    np.savez(tmp_path / "gt.npz", **lab_arrays(seed=1))  # changed after the manifest was written
    with pytest.raises(ValueError, match=r"gt\.npz.*expected"):
        load_ground_truth(path)


def test_load_shadowcam_nc_round_trip_and_missing_variable(tmp_path, write_manifest):
    standard = mitsuba_lab_npz_to_dataset(lab_arrays())
    standard[list(REQUIRED)].to_netcdf(tmp_path / "ground_truth.nc", engine="h5netcdf")
    ds = load_ground_truth(_manifest(write_manifest, tmp_path, "shadowcam_nc", "ground_truth.nc"))
    for name in REQUIRED:
        np.testing.assert_array_equal(ds[name].values, standard[name].values)
    standard[["t_u", "t_v", "lit"]].to_netcdf(tmp_path / "bad.nc", engine="h5netcdf")
    with pytest.raises(ValueError, match=r"bad\.nc.*reciprocal"):
        load_ground_truth(_manifest(write_manifest, tmp_path, "shadowcam_nc", "bad.nc"))


def test_check_ground_truth_rejects_transposed_dual():
    ds = mitsuba_lab_npz_to_dataset(lab_arrays())
    with pytest.raises(ValueError, match="dual_cam_visible"):
        check_ground_truth(ds.assign(dual_cam_visible=ds["dual_cam_visible"].transpose("u", "v")))


@pytest.mark.usefixtures("shared_data")  # the repository manifest reads the shared dev data
@pytest.mark.parametrize("name", ["dev_spheres", "dev_spheres_raw"])
def test_shared_dev_ground_truth_counts(name):
    ds = load_ground_truth(REPO / "data_manifest" / f"{name}.yaml")
    assert ds.sizes["row"] == ds.sizes["col"] == 192 and ds.sizes["u"] == ds.sizes["v"] == 96
    # counts stated in shared/data/README.md section 1.5
    assert int(ds["lit"].sum()) == 34_582
    assert int(np.isfinite(ds["t_u"]).sum()) == 33_522
    assert int(np.isfinite(ds["t_v"]).sum()) == 34_582
    assert int(ds["dual_cam_visible"].sum()) == 5_346


def _outdoor_arrays(height=4, width=5, frames=3):
    arrays = {
        "shadow_class": np.full((height, width), 3, np.uint8),
        "sky_mask": np.zeros((height, width), bool),
        "arrival_time_s": np.full((height, width), 12.5),
        "arrival_frame": np.full((height, width), 1.25),
        "first_shadowed_frame": np.full((height, width), 2, np.int32),
        "relit_after_arrival": np.zeros((height, width), bool),
        "times_s": np.array([0.0, 10.0, 20.0])[:frames],
        "pb_edge_y": np.zeros((frames, width), np.float32),
        "reference_radiance": np.ones((height, width, 3), np.float32),
    }
    arrays["shadow_class"][0] = 0
    arrays["sky_mask"][0] = True
    return arrays


def test_outdoor_npz_and_netcdf_give_the_same_standard_form(tmp_path, write_manifest):
    from shadowcam.io.ground_truth import check_outdoor_ground_truth, mitsuba_outdoor_npz_to_dataset

    arrays = _outdoor_arrays()
    np.savez(tmp_path / "gt.npz", **arrays)
    from_npz = load_ground_truth(_manifest(write_manifest, tmp_path, "mitsuba_outdoor_npz", "gt.npz"))
    from_npz.drop_attrs().to_netcdf(tmp_path / "ground_truth.nc", engine="h5netcdf")
    from_nc = load_ground_truth(_manifest(write_manifest, tmp_path, "shadowcam_outdoor_nc", "ground_truth.nc"))
    for name in ("shadow_class", "sky_mask", "arrival_time_s", "times_s", "pb_edge_y"):
        np.testing.assert_array_equal(from_nc[name].values, from_npz[name].values)
        assert from_nc[name].dims == from_npz[name].dims
    assert from_nc["sky_mask"].dtype == bool and from_npz["times_s"].dims == ("time",)
    with pytest.raises(ValueError, match="arrival_time_s"):
        check_outdoor_ground_truth(from_npz.drop_vars("arrival_time_s"))
    broken = dict(arrays)
    del broken["times_s"]
    with pytest.raises(ValueError, match="times_s"):
        mitsuba_outdoor_npz_to_dataset(broken)


@pytest.mark.parametrize("fmt, name", [("shadowcam_outdoor_nc", "ground_truth.nc"), ("mitsuba_outdoor_npz", "gt.npz")])
def test_ground_truth_without_its_per_frame_maps(tmp_path, write_manifest, fmt, name):
    from shadowcam.io.ground_truth import mitsuba_outdoor_npz_to_dataset

    full = mitsuba_outdoor_npz_to_dataset(_outdoor_arrays())
    full["lit_center"] = (("time", "row", "col"), np.ones((3, 4, 5), np.float32))
    if fmt == "mitsuba_outdoor_npz":
        np.savez(tmp_path / name, **_outdoor_arrays())
    else:
        full.drop_attrs().to_netcdf(tmp_path / name, engine="h5netcdf")
    manifest = _manifest(write_manifest, tmp_path, fmt, name)
    lean = load_ground_truth(manifest, frame_maps=False)
    kept = load_ground_truth(manifest)
    assert "lit_center" not in lean and ("lit_center" in kept) == (fmt == "shadowcam_outdoor_nc")
    assert "pb_edge_y" in lean and "times_s" in lean  # (time, col) and (time,) are not per-pixel-frame maps
    for variable in ("shadow_class", "arrival_time_s", "pb_edge_y"):
        np.testing.assert_array_equal(lean[variable].values, kept[variable].values)


@pytest.mark.usefixtures("shared_data")  # the repository manifest reads the shared dev data
def test_dev_ridge_ground_truth_counts():
    ds = load_ground_truth(REPO / "data_manifest" / "dev_ridge.yaml")
    assert (ds.sizes["row"], ds.sizes["col"], ds.sizes["time"]) == (128, 192, 120)
    # counts stated in shared/data/README.md section 2.5
    counts = np.bincount(ds["shadow_class"].values.ravel(), minlength=4)
    assert counts.tolist()[0] == 4_921 and counts[1] == 3_775 and counts[3] == 10_429
    assert int(ds["relit_after_arrival"].sum()) == 131
