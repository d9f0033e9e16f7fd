"""Several lights from a capture's files: a user's manifest over files the renderer wrote (u and
v sweeps, reference), against the renderer's per-light ground truth."""

import json

import numpy as np
import pytest
import xarray as xr
import yaml

from shadowcam.io.capture_plan import capture_plan
from shadowcam.lab.light_files import light_set_capture_of_plan, light_set_views_of_plan
from shadowcam.lab.light_views import light_set_accuracy, light_set_errors, light_set_views
from shadowcam.synthetic.capture_options import capture_options
from shadowcam.synthetic.lab.light_set_capture import render_light_set_capture, write_light_set_capture

LIGHTS = [{"kind": "point"}, {"kind": "point", "offset": [0.012, 0.012, 0.0]},
          {"kind": "tube", "axis": "v", "length": 0.012, "offset": [-0.012, -0.012, 0.0]}]
SYNTHETIC = {"scene": "tabletop", "seed": 2, "height": 32, "width": 32, "frames": 40, "supersample": 2,
             "shutter": 1, "format": "tiff", "bit_depth": 16, "noise": False, "lights": LIGHTS}
POINT_SWEEPS = ((0, "u"), (0, "v"), (1, "u"), (1, "v"), (2, "u"))  # the tube is sharp across the u wire only


def _render_manifest(path, **synthetic):
    path.write_text(yaml.safe_dump({"name": "lights_small", "kind": "lab", "light": "point",
                                    "synthetic": {**SYNTHETIC, **synthetic}}))
    return path


def _render(folder, **synthetic):
    return write_light_set_capture(capture_options(_render_manifest(folder / "render.yaml", **synthetic)),
                                   folder / "capture")


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    """A rendered several-lights capture folder (16-bit TIFF, noise-free)."""
    return _render(tmp_path_factory.mktemp("lights"))


def _user_doc(capture, *, lights=None, sweeps=("u", "v"), reference=True):
    """A user's manifest over the rendered files: lights positions in mm, as one would measure them."""
    described = json.loads((capture / "capture.json").read_text())["lights"]
    if lights is None:
        lights = {"kinds": described["kinds"],
                  **{f"light_along_{s}": [1e3 * x for x in described[f"light_along_{s}"]] for s in "uv"}}
    doc = {"name": "my_lights", "kind": "lab", "light": "point", "root": str(capture),
           "sweeps": {s: {"files": f"frames_{s}/*.tiff"} for s in sweeps},
           "timing": {"source": "rate", "rate_hz": 2.0}, "lights": lights,
           "ground_truth": {"format": "shadowcam_lights_nc", "file": "ground_truth.nc"}}
    if reference:
        doc["reference"] = "reference.tiff"
    return doc


@pytest.fixture(scope="module")
def truth(rendered):
    return xr.load_dataset(rendered / "ground_truth.nc")


@pytest.fixture(scope="module")
def user_views(rendered, tmp_path_factory, write_manifest):
    path = write_manifest(tmp_path_factory.mktemp("user") / "my_lights.yaml", _user_doc(rendered))
    return light_set_views_of_plan(capture_plan(path))


def test_user_manifest_gives_the_renderers_per_light_times_within_the_tolerances(user_views, truth):
    assert user_views["dual_view"].dims == ("light", "v", "u", "channel")
    assert user_views["dual_view"].shape[:3] == (3, 40, 40)
    assert user_views.attrs["kinds"] == ["point", "point", "tube"]
    assert user_views.attrs["light_order"] == "described" and user_views.attrs["order_checked"] == 1
    acc = light_set_accuracy(user_views, truth)["lights"]
    for k, sweep in POINT_SWEEPS:
        entry = acc[k][sweep]
        assert entry["n_scored"] > 300
        assert entry["coverage"] > 0.97          # noise-free: every scored pixel but the borders
        assert entry["p95_error"] < 0.2          # frames, open shutter, 32 x 32 and 40 frames
        assert entry["false_rate"] < 0.01        # times further than one frame
    # the tube across the v sweep's wire casts a wide, weak dip: flagged, not guessed
    assert acc[2]["v"]["coverage"] < 0.05 and acc[2]["v"]["contrast"] < 0.1
    assert np.isfinite(user_views["dual_view"].values[0]).all(-1).mean() > 0.4  # the scene's share of the grid


def test_files_and_the_in_memory_render_give_the_same_times(user_views):
    direct = light_set_views(render_light_set_capture(SYNTHETIC))
    a, b = user_views["time"].values, direct["time"].values
    both = np.isfinite(a) & np.isfinite(b)
    assert both.sum() >= 0.99 * max(np.isfinite(a).sum(), np.isfinite(b).sum())
    # 16-bit files quantise the frames: a dip centroid moves by far less than a frame
    assert np.percentile(np.abs(a - b)[both], 95) < 0.01
    assert np.mean(np.abs(a - b)[both] > 0.1) < 0.002


def test_without_positions_the_lights_are_numbered_by_their_shadows(rendered, user_views, tmp_path, write_manifest):
    doc = _user_doc(rendered, lights={"kinds": ["point", "point", "tube"]})
    views = light_set_views_of_plan(capture_plan(write_manifest(tmp_path / "m.yaml", doc)))
    assert views.attrs["light_order"] == "shadows" and views.attrs["order_checked"] == 0
    # the tube's shadows pass first in both sweeps, then point 0, then point 1
    order = [2, 0, 1]
    np.testing.assert_array_equal(views["time"].values, user_views["time"].values[:, order])
    assert np.all(np.diff(views["position"].sel(sweep="u").values) > 0)  # the tube is untimed in v


def test_the_capture_in_memory_holds_the_decoded_frames_and_the_truth(rendered, truth, tmp_path, write_manifest):
    capture = light_set_capture_of_plan(capture_plan(write_manifest(tmp_path / "m.yaml", _user_doc(rendered))))
    assert capture["frames_u"].shape == (40, 32, 32, 3) and capture["reference"].shape == (32, 32, 3)
    np.testing.assert_array_equal(capture["t_center_v"].values, truth["t_center_v"].values)
    # decoded white is 1 (highlights clip there): radiance x electrons per unit radiance x gain / (white - black)
    a = truth.attrs
    gain = a["electrons_per_unit_radiance"] * a["gain_dn_per_electron"] / (a["white_level"] - a["black_level"])
    np.testing.assert_allclose(capture["reference"].values, np.minimum(gain * truth["reference"].values, 1.0),
                               atol=1.0 / 65535)  # within a 16-bit step
    np.testing.assert_allclose(capture["light_along_u"].values, 1e3 * truth["light_along_u"].values)


@pytest.fixture(scope="module")
def rendered_raw(tmp_path_factory):
    """A rendered several-lights capture folder (noisy 12-bit RGGB DNG)."""
    return _render(tmp_path_factory.mktemp("lights_raw"), format="dng", bit_depth=12, noise=True)


def test_a_noisy_12_bit_dng_capture_is_a_mosaic_read_through_the_files(rendered_raw):
    from shadowcam.io.raw_mosaic import read_mosaic

    capture = rendered_raw
    mosaic, levels = read_mosaic(capture / "frames_u/000000.dng")
    assert mosaic.shape == (32, 32) and levels["cfa_pattern"] == "RGGB"  # one CFA site per pixel
    described = json.loads((capture / "capture.json").read_text())
    assert described["ground_truth"]["noise"] == "raw12" and described["reference"] == "reference.dng"
    views = light_set_views_of_plan(capture_plan(capture / "capture.json"))
    acc = light_set_accuracy(views, xr.load_dataset(capture / "ground_truth.nc"))["lights"]
    for k, sweep in POINT_SWEEPS:
        entry = acc[k][sweep]
        assert entry["coverage"] > 0.97 and entry["false_rate"] < 0.03 and entry["dip_shown"]
        assert entry["p95_error"] < 0.8   # frames: shot and read noise on a demosaiced mosaic
    # the tube lies along the v wire: its shadow is too shallow and long to be placed
    assert not acc[2]["v"]["dip_shown"] and acc[2]["v"]["coverage"] == 0


def test_raw_in_memory_and_from_the_files_is_timed_on_one_path(rendered_raw):
    """The capture in memory (what the methods comparison reads) carries the CFA pattern, and
    its views are those of the stage: each pixel timed from its own mosaic site, bit for bit."""
    from shadowcam.evaluate.methods_comparison import compare_minima_methods

    plan = capture_plan(rendered_raw / "capture.json")
    capture = light_set_capture_of_plan(plan)
    assert capture.attrs["cfa_pattern"] == "RGGB"
    staged, in_memory = light_set_views_of_plan(plan), light_set_views(capture)
    for name in ("time", "time_std", "confidence", "reason"):
        np.testing.assert_array_equal(in_memory[name].values, staged[name].values)
    # the channel sum times them otherwise: the pattern is what makes the two paths one
    summed = light_set_views(capture.assign_attrs(cfa_pattern=""))
    assert not np.array_equal(summed["time"].values, staged["time"].values, equal_nan=True)
    # and the methods comparison's edge_fit row scores exactly the stage's times
    errors = light_set_errors(staged, capture)
    err = np.concatenate([error[scored] for error, scored in errors.values()])
    row, = compare_minima_methods(capture, methods=["edge_fit"])
    assert row["p95"] == pytest.approx(np.percentile(err[np.isfinite(err)], 95), rel=1e-12)
    assert row["coverage"] == pytest.approx(np.isfinite(err).mean(), rel=1e-12)


def _plan_error(tmp_path, write_manifest, doc):
    path = write_manifest(tmp_path / "bad.yaml", doc)
    with pytest.raises(ValueError) as info:
        capture_plan(path)
    assert str(path) in str(info.value)
    return str(info.value)


@pytest.mark.parametrize("kinds, said", [([], "no light"), (["point"], "one light")])
def test_fewer_than_two_lights_are_refused_and_one_points_to_the_standard_lab_path(
        rendered, tmp_path, write_manifest, kinds, said):
    text = _plan_error(tmp_path, write_manifest, _user_doc(rendered, lights={"kinds": kinds}))
    assert "'lights.kinds'" in text and said in text and "standard lab capture" in text


@pytest.mark.parametrize("lights, key, words", [
    ({"kinds": ["point", "point", "tube"], "light_along_u": [0, 1, 2]}, "lights.light_along_u", "give both"),
    ({"kinds": ["point", "point", "tube"], "light_along_u": [0, 1], "light_along_v": [0, 1, 2]},
     "lights.light_along_u", "2 positions"),
    ({"kinds": ["point", "point", "tube"], "light_along_u": [0, 1, 2], "light_along_v": [0, 1, 1]},
     "lights.light_along_v", "one position"),
])
def test_inconsistent_positions_are_refused_naming_the_key(rendered, tmp_path, write_manifest, lights, key, words):
    text = _plan_error(tmp_path, write_manifest, _user_doc(rendered, lights=lights))
    assert f"'{key}'" in text and words in text


def test_a_missing_sweep_or_reference_is_refused_naming_the_key(rendered, tmp_path, write_manifest):
    text = _plan_error(tmp_path, write_manifest, _user_doc(rendered, sweeps=("u",)))
    assert "'sweeps'" in text and "'v'" in text
    text = _plan_error(tmp_path, write_manifest, _user_doc(rendered, reference=False))
    assert "'reference'" in text


def test_a_sweeps_missing_files_are_refused_naming_the_key(rendered, tmp_path, write_manifest):
    path = write_manifest(tmp_path / "bad.yaml", _user_doc(rendered))
    doc = yaml.safe_load(path.read_text())
    doc["sweeps"]["v"]["files"] = "frames_w/*.tiff"
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ValueError, match=r"sweeps\.v\.files 'frames_w/\*\.tiff' matches no file"):
        capture_plan(path)


def test_described_positions_the_shadows_contradict_are_refused_naming_the_key(
        rendered, tmp_path, write_manifest):
    lights = {"kinds": ["point", "point", "tube"], "light_along_u": [0.0, 12.0, -24.0],
              "light_along_v": [0.0, 12.0, -12.0]}  # the tube described twice as far along u as it is
    plan = capture_plan(write_manifest(tmp_path / "m.yaml", _user_doc(rendered, lights=lights)))
    with pytest.raises(ValueError, match="light_along_u"):
        light_set_views_of_plan(plan)
    unchecked = light_set_views_of_plan(plan, check_order=False)
    assert unchecked.attrs["order_checked"] == 0


def test_a_rendered_manifest_is_not_read_as_files(tmp_path):
    path = _render_manifest(tmp_path / "render.yaml")
    with pytest.raises(ValueError, match="render-lights"):
        light_set_views_of_plan(capture_plan(path))
