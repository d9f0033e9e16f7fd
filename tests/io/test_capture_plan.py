"""Tests of shadowcam.io.capture_plan: the facts the workflow plans jobs from."""

import glob
import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from shadowcam.cameras.dual_coords import choose_dual_model
from shadowcam.cli import main
from shadowcam.io.capture_plan import (
    PLANNED_SHIFT_COLUMNS,
    CapturePlan,
    capture_plan,
)
from shadowcam.io.manifest import checksums_for
from shadowcam.outdoor.strips import strip_halo

ROWS, COLS = 6, 10
IDENTITY = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]


@pytest.fixture
def write_frames(write_image):
    """Write seeded 16-bit RGB frames of ROWS x COLS under `folder` (subfolders allowed in names)."""

    def write(folder, names, seed):
        rng = np.random.default_rng(seed)
        for name in names:
            path = Path(folder) / name
            path.parent.mkdir(parents=True, exist_ok=True)
            write_image(path, rng.integers(0, 65536, (ROWS, COLS, 3)).astype(np.uint16))

    return write


def write_capture(tmp_path, doc, *, checksums=True):
    """Write manifest `doc` as tmp_path/manifests/<name>.yaml (root ../data) with its checksums."""
    path = tmp_path / "manifests" / f"{doc['name']}.yaml"
    path.parent.mkdir(exist_ok=True)
    path.write_text(yaml.safe_dump(doc))
    if checksums:
        path.write_text(yaml.safe_dump({**doc, "checksums": checksums_for(path)}))
    return path


def lab_doc(**overrides):
    doc = {
        "name": "cap",
        "kind": "lab",
        "light": "point",
        "root": "../data",
        "sweeps": {"u": {"files": "u/*.png", "axis": "u"}, "v": {"files": "v/*.png", "axis": "v"}},
        "reference": "ref.png",
        "timing": {"source": "rate", "rate_hz": 4.0},
    }
    doc.update(overrides)
    return doc


@pytest.fixture
def lab(tmp_path, write_frames):
    data = tmp_path / "data"
    write_frames(data / "u", [f"f{i}.png" for i in (8, 9, 10)], seed=1)
    write_frames(data / "v", [f"f{i}.png" for i in range(1, 5)], seed=2)
    write_frames(data, ["ref.png"], seed=3)
    return tmp_path


def test_lab_capture_facts(lab):
    plan = capture_plan(write_capture(lab, lab_doc()))
    assert isinstance(plan, CapturePlan)
    assert (plan.name, plan.kind, plan.rendered, plan.is_outdoor) == ("cap", "lab", False, False)
    assert list(plan.sweeps) == ["u", "v"]
    assert (plan.n_frames("u"), plan.n_frames("v")) == (3, 4)
    root = (lab / "data").resolve()
    # natural order: f9 before f10
    assert plan.sweep("u").files == tuple(str(root / "u" / f"f{i}.png") for i in (8, 9, 10))
    assert plan.sweep("u").times_s == (0.0, 0.25, 0.5)
    assert plan.sweep("u").axis == "u"
    assert plan.frame_shape == (ROWS, COLS)
    assert plan.megapixels == pytest.approx(ROWS * COLS / 1e6)
    assert plan.timing == {"source": "rate", "rate_hz": 4.0}
    assert plan.reference == (str(root / "ref.png"),) and plan.has_reference
    assert not plan.has_ground_truth and not plan.has_calibration
    # the simplest model the data support: no calibration sweeps -> uniform, u v timed
    assert plan.dual_model == "uniform" and not plan.uses_calibration
    assert plan.timed_sweeps == ("u", "v")
    assert plan.outdoor_sweep is None and plan.strip_halo == 0


def test_plan_is_frozen(lab):
    plan = capture_plan(write_capture(lab, lab_doc()))
    with pytest.raises(AttributeError):
        plan.kind = "outdoor"
    with pytest.raises(TypeError):
        plan.sweeps["w"] = plan.sweeps["u"]


def test_recursive_glob_counts_what_decode_decodes(tmp_path, write_frames):
    """A `**` pattern over nested folders, with a folder whose name matches the pattern:
    the plan counts the files decode writes, not what a plain glob returns."""
    data = tmp_path / "data"
    write_frames(data / "u", ["a/f1.png", "a/f2.png", "b/f3.png", "f0.png"], seed=4)
    write_frames(data / "v", ["f1.png", "f2.png"], seed=5)
    (data / "u" / "c.png").mkdir()  # a folder matching the pattern is not a frame
    write_frames(data, ["ref.png"], seed=6)
    path = write_capture(tmp_path, lab_doc(sweeps={"u": {"files": "u/**/*.png"}, "v": {"files": "v/*.png"}}))
    plan = capture_plan(path)
    plain = glob.glob(str(path.parent / "../data/u/**/*.png"))
    assert len(plain) != 4  # a non-recursive glob miscounts this sweep
    assert plan.n_frames("u") == 4
    out = tmp_path / "u.zarr"
    assert main(["decode", "--manifest", str(path), "--sweep", "u", "--out", str(out)]) in (0, None)
    with xr.open_zarr(out, consolidated=False) as store:
        assert store.sizes["time"] == plan.n_frames("u")


def test_missing_timing_raises_the_schema_message(lab):
    path = write_capture(lab, lab_doc())
    doc = yaml.safe_load(path.read_text())
    del doc["timing"]
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ValueError, match=r"manifest .*cap\.yaml does not match the schema") as info:
        capture_plan(path)
    assert "'timing' is a dependency of 'sweeps'" in str(info.value)
    assert "key (top level)" in str(info.value)


def test_missing_checksums_raises_before_anything_runs(lab):
    with pytest.raises(ValueError, match="no checksums block"):
        capture_plan(write_capture(lab, lab_doc(), checksums=False))


def test_single_sweep_lab_capture_plans_the_pushbroom_only(lab):
    plan = capture_plan(write_capture(lab, lab_doc(sweeps={"u": {"files": "u/*.png"}})))
    assert plan.single_sweep and plan.scene_sweeps == ("u",)
    assert plan.stages == ("pushbroom",) and plan.timed_sweeps == ("u",)
    assert plan.dual_model is None


def test_two_sweep_lab_capture_plans_the_dual_stages(lab):
    plan = capture_plan(write_capture(lab, lab_doc()))
    assert not plan.single_sweep and plan.scene_sweeps == ("u", "v")
    assert plan.stages == ("dual_coords", "dual_view")


def test_lab_needs_a_scene_sweep(lab):
    path = write_capture(lab, lab_doc(sweeps={"w": {"files": "u/*.png"}}))
    with pytest.raises(ValueError, match=r"key 'sweeps' has no scene sweep"):
        capture_plan(path)


def test_calibration_sweeps_choose_the_calibration_model(lab, write_frames):
    data = lab / "data"
    write_frames(data / "cal_u", ["f1.png", "f2.png"], seed=7)
    write_frames(data / "cal_v", ["f1.png", "f2.png"], seed=8)
    sweeps = {name: {"files": f"{name}/*.png"} for name in ("u", "v", "cal_u", "cal_v")}
    path = write_capture(lab, lab_doc(sweeps=sweeps, calibration_plane={"homography": IDENTITY}))
    plan = capture_plan(path)
    assert plan.has_calibration and plan.dual_model == "calibration" and plan.uses_calibration
    assert plan.timed_sweeps == ("u", "v", "cal_u", "cal_v")
    uniform = capture_plan(path, dual_model="uniform")
    assert uniform.dual_model == "uniform" and uniform.timed_sweeps == ("u", "v")
    # sweeps without the plane: no calibration, and asking for it names what is missing
    path = write_capture(lab, lab_doc(sweeps=sweeps))
    assert capture_plan(path).dual_model == "uniform"
    with pytest.raises(ValueError, match=r"model 'calibration' needs .*calibration_plane in manifest"):
        capture_plan(path, dual_model="calibration")


def test_choose_dual_model():
    assert choose_dual_model("auto", calibration_available=True) == "calibration"
    assert choose_dual_model("auto", calibration_available=False) == "uniform"
    assert choose_dual_model("uniform", calibration_available=True) == "uniform"
    with pytest.raises(ValueError, match="needs the plane"):
        choose_dual_model("calibration", calibration_available=False, missing="the plane")
    with pytest.raises(ValueError, match="model must be .auto. or one of"):
        choose_dual_model("affine", calibration_available=True)


def outdoor_doc(sweeps):
    return {
        "name": "ridge",
        "kind": "outdoor",
        "light": "distant",
        "root": "../data",
        "sweeps": sweeps,
        "timing": {"source": "filename", "regex": r"f(?P<index>\d+)", "rate_hz": 0.5},
    }


def test_outdoor_capture_facts(tmp_path, write_frames):
    write_frames(tmp_path / "data" / "seq", [f"f{i}.png" for i in range(5)], seed=9)
    path = write_capture(tmp_path, outdoor_doc({"seq": {"files": "seq/*.png"}}))
    plan = capture_plan(path, edge_margin=3)
    assert plan.is_outdoor and plan.outdoor_sweep == "seq"  # the only sweep, whatever its name
    assert plan.n_frames("seq") == 5 and plan.sweep("seq").times_s == (0.0, 2.0, 4.0, 6.0, 8.0)
    assert plan.dual_model is None and plan.timed_sweeps == ()
    shift = np.array([[0.0, PLANNED_SHIFT_COLUMNS]])
    assert plan.strip_halo == strip_halo(shift, margin=3)
    assert capture_plan(path).strip_halo == strip_halo(shift)  # the tracker's own margin


def test_outdoor_needs_one_timelapse_sweep(tmp_path, write_frames):
    for name in ("a", "b"):
        write_frames(tmp_path / "data" / name, ["f1.png"], seed=10)
    path = write_capture(tmp_path, outdoor_doc({"a": {"files": "a/*.png"}, "b": {"files": "b/*.png"}}))
    with pytest.raises(ValueError, match=r"needs one sweep \(preferably named 'timelapse'\)"):
        capture_plan(path)


def test_rendered_capture_plans_from_the_synthetic_block(tmp_path):
    doc = {
        "name": "tiny",
        "kind": "lab",
        "light": "point",
        "synthetic": {"scene": "tabletop", "seed": 2, "height": 12, "width": 16, "frames": 9,
                      "calibration": True},
    }
    plan = capture_plan(write_capture(tmp_path, doc, checksums=False))
    assert plan.rendered and plan.has_ground_truth and plan.has_reference
    assert {name: sweep.n_frames for name, sweep in plan.sweeps.items()} == dict.fromkeys(
        ("u", "v", "cal_u", "cal_v"), 9)
    assert plan.frame_shape == (12, 16) and plan.sweep("u").files == ()
    assert plan.dual_model == "calibration"
    with pytest.raises(ValueError, match="sweep 'w' is not a sweep"):
        plan.sweep("w")


def test_repository_manifests_plan(repo, shared_data):
    """Every manifest shipped in data_manifest/ gives a plan (the dev ones read the shared data)."""
    for path in sorted((repo / "data_manifest").glob("*.yaml")):
        plan = capture_plan(path)
        assert plan.name == path.stem
        assert all(sweep.n_frames >= 2 for sweep in plan.sweeps.values())


def camera_doc(sweeps, *, light="point", frames=16, **camera):
    return {
        "name": "cam",
        "kind": "lab",
        "light": light,
        "synthetic": {"scene": "tabletop", "seed": 0, "height": 24, "width": 24,
                      "frames": frames, "camera": {"sweeps": sweeps, **camera}},
    }


def plan_of(tmp_path, doc):
    return capture_plan(write_capture(tmp_path, doc, checksums=False))


@pytest.mark.parametrize(("light", "primal", "optics", "model"), [
    ("point", "perspective", "none", "perspective"),
    ("distant", "perspective", "none", "orthographic"),
    ("point", "orthographic", "none", "perspective"),
    ("area", "perspective", "mirror", "perspective"),
    ("point", "perspective", "glass", "perspective"),
])
def test_camera_block_standard_pair_decides_the_projection(tmp_path, light, primal, optics, model):
    """The light decides the dual projection; primal camera and optics do not (Fig. 7, 8)."""
    sweeps = [{"name": "u"}, {"name": "v", "direction_deg": 90}]
    plan = plan_of(tmp_path, camera_doc(sweeps, light=light, primal=primal, optics=optics))
    assert plan.camera_model == model
    assert plan.scene_sweeps == ("u", "v") and plan.stages == ("dual_coords", "dual_view")
    assert {n: s.n_frames for n, s in plan.sweeps.items()} == {"u": 16, "v": 16}
    assert (plan.sweep("v").direction_deg, plan.sweep("v").speed) == (90.0, 1.0)
    assert dict(plan.camera)["primal"] == primal and dict(plan.camera)["optics"] == optics


def test_camera_block_slanted_stretched_sweeps_are_the_linear_camera(tmp_path):
    """Frame counts come from the renderer's geometry: enough frames to cross the dual field."""
    sweeps = [{"name": "u", "speed": 2.0}, {"name": "s", "direction_deg": 60, "speed": 0.5},
              {"name": "v", "direction_deg": 90}]
    plan = plan_of(tmp_path, camera_doc(sweeps, frames=16))
    assert plan.camera_model == "linear"
    assert plan.scene_sweeps == ("u", "v", "s")  # u, v first, then the others in order
    n = 16  # mask grid of the tabletop preset = frames
    expected_s = math.ceil(n * (math.cos(math.radians(60)) + math.sin(math.radians(60))) / 0.5)
    assert plan.n_frames("u") == n // 2 and plan.n_frames("v") == n
    assert plan.n_frames("s") == expected_s
    declared = {d["name"]: d for d in plan.camera["sweeps"]}
    assert declared["s"] == {"name": "s", "angle_deg": 60.0, "speed": 0.5, "frames": expected_s}


def test_camera_block_cross_slit_needs_a_light_per_sweep(tmp_path):
    sweeps = [{"name": "u", "light_offset": [0.01, 0.0, 0.0]},
              {"name": "v", "direction_deg": 90, "light_offset": [0.0, 0.02, 0.0]}]
    plan = plan_of(tmp_path, camera_doc(sweeps, model="cross_slit"))
    assert plan.camera_model == "cross_slit"
    assert plan.sweep("v").light == (0.0, 0.02, 0.0)
    no_lights = [{"name": "u"}, {"name": "v", "direction_deg": 90}]
    with pytest.raises(ValueError, match=r"key 'synthetic.camera.sweeps': model 'cross_slit' "
                                         r"needs two sweeps, each with its own light"):
        plan_of(tmp_path, camera_doc(no_lights, model="cross_slit"))


def test_camera_block_parallel_sweeps_are_refused_at_plan_time(tmp_path):
    sweeps = [{"name": "u"}, {"name": "a", "direction_deg": 180.0}, {"name": "b", "speed": 3.0,
                                                                      "direction_deg": 5.0}]
    with pytest.raises(ValueError, match=r"cam.yaml: key 'synthetic.camera.sweeps': sweeps "
                                         r"\['u', 'a', 'b'\] are all \(nearly\) parallel"):
        plan_of(tmp_path, camera_doc(sweeps))


def test_camera_block_light_offset_needs_a_near_light(tmp_path):
    sweeps = [{"name": "u"}, {"name": "v", "direction_deg": 90, "light_offset": [0.01, 0, 0]}]
    with pytest.raises(ValueError, match=r"key 'synthetic.camera.sweeps\[1\].light_offset' "
                                         r"shifts a point or area light, but 'light' is distant"):
        plan_of(tmp_path, camera_doc(sweeps, light="distant"))
    with pytest.raises(ValueError, match=r"sweeps\[1\].name': duplicate sweep name 'u'"):
        plan_of(tmp_path, camera_doc([{"name": "u"}, {"name": "u", "direction_deg": 90}]))


def test_camera_block_schema_names_the_key(tmp_path):
    with pytest.raises(ValueError, match="optics"):
        plan_of(tmp_path, camera_doc([{"name": "u"}], optics="prism"))
    with pytest.raises(ValueError, match="name"):
        plan_of(tmp_path, camera_doc([{"name": "cal_u"}]))


def test_camera_block_single_sweep_is_the_pushbroom(tmp_path):
    plan = plan_of(tmp_path, camera_doc([{"name": "w", "direction_deg": 90}]))
    assert plan.camera_model == "pushbroom" and plan.stages == ("pushbroom",)
    assert plan.scene_sweeps == ("w",)


def test_manifest_sweeps_declare_their_geometry(lab, write_frames):
    write_frames(lab / "data" / "w", [f"f{i}.png" for i in range(5)], seed=4)
    sweeps = {"u": {"files": "u/*.png"}, "v": {"files": "v/*.png", "speed": 2.0},
              "w": {"files": "w/*.png", "direction_deg": 45.0}}
    plan = capture_plan(write_capture(lab, lab_doc(sweeps=sweeps)))
    assert plan.camera_model == "linear" and plan.scene_sweeps == ("u", "v", "w")
    assert plan.camera["sweeps"][2] == {"name": "w", "angle_deg": 45.0, "speed": 1.0,
                                        "frames": 5}
    assert plan.timed_sweeps == ("u", "v", "w")
    standard = capture_plan(write_capture(lab, lab_doc(name="std")))
    assert standard.camera_model == "perspective"


def test_manifest_sweep_lights_all_or_none(lab):
    sweeps = {"u": {"files": "u/*.png", "light_position": [0, 0, 1]},
              "v": {"files": "v/*.png", "direction_deg": 90.0}}
    with pytest.raises(ValueError, match=r"key 'sweeps.<name>.light_position' is given for "
                                         r"sweeps \['u'\] but not for \['v'\]"):
        capture_plan(write_capture(lab, lab_doc(sweeps=sweeps)))
    sweeps["v"]["light_position"] = [0.1, 0, 1]
    assert capture_plan(write_capture(lab, lab_doc(sweeps=sweeps))).camera_model == "cross_slit"


def _plan_or_error(doc):
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        try:
            return plan_of(Path(folder), doc), None
        except ValueError as err:
            return None, str(err)


@settings(max_examples=40, deadline=None)
@given(angle=st.floats(-360, 360), delta=st.floats(0.0, 30.0), speed_a=st.floats(0.01, 100.0),
       speed_b=st.floats(0.01, 100.0))
def test_camera_block_geometry_gives_a_camera_or_names_the_key(angle, delta, speed_a, speed_b):
    """Nearly parallel pairs, slants near 0/90, speeds 100x apart: a model or a clear error."""
    sweeps = [{"name": "a", "direction_deg": angle, "speed": speed_a},
              {"name": "b", "direction_deg": angle + delta, "speed": speed_b}]
    plan, error = _plan_or_error(camera_doc(sweeps))
    sine = abs(math.sin(math.radians(delta)))
    if sine < math.sin(math.radians(15.0)) - 1e-9:
        assert plan is None and "key 'synthetic.camera.sweeps'" in error and "parallel" in error
        return
    if sine > math.sin(math.radians(15.0)) + 1e-9:
        assert error is None, error
        assert plan.camera_model in ("linear", "perspective")
        for name, speed, theta in (("a", speed_a, angle), ("b", speed_b, angle + delta)):
            extent = 16 * (abs(math.cos(math.radians(theta))) + abs(math.sin(math.radians(theta))))
            assert plan.n_frames(name) == max(2, math.ceil(extent / speed - 1e-9))


@settings(max_examples=25, deadline=None)
@given(delta=st.floats(0.0, 90.0), offset=st.floats(-0.05, 0.05))
def test_cross_slit_request_is_a_camera_or_a_clear_error(delta, offset):
    """Degenerate cross-slit set-ups (parallel wires, one light) are refused by key."""
    sweeps = [{"name": "a"}, {"name": "b", "direction_deg": delta,
                              "light_offset": [offset, 0.0, 0.0]}]
    plan, error = _plan_or_error(camera_doc(sweeps, model="cross_slit"))
    if abs(math.sin(math.radians(delta))) < math.sin(math.radians(15.0)) - 1e-9:
        assert plan is None and "parallel" in error
    elif offset == 0.0:
        assert plan is None and "needs two sweeps, each with its own light" in error
    elif abs(math.sin(math.radians(delta))) > math.sin(math.radians(15.0)) + 1e-9:
        assert error is None and plan.camera_model == "cross_slit"


def _array_manifest(tmp_path, **array):
    doc = {"name": "arr", "kind": "lab", "light": "point",
           "synthetic": {"scene": "tabletop", "seed": 1, "height": 16, "width": 20, "frames": 12,
                         "camera_array": array}}
    path = tmp_path / "arr.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def test_camera_array_plan_has_only_its_stage(tmp_path):
    plan = capture_plan(_array_manifest(tmp_path, rows=2, cols=3, spacing_frames=5))
    assert plan.stages == ("camera_array",) and plan.rendered and plan.has_ground_truth
    # images: both experiments at most frames + spacing x (3 - 1) + 1 each, and 6 crossings
    assert dict(plan.camera_array) == {"rows": 2, "cols": 3, "spacing_frames": 5, "radius_frames": 0.6,
                                       "frames": 12, "images": 2 * (12 + 11) + 6}
    assert plan.frame_shape == (16, 20) and plan.sweeps == {}


def test_camera_array_block_needs_its_spacing(tmp_path):
    with pytest.raises(ValueError, match="spacing_frames"):
        capture_plan(_array_manifest(tmp_path, rows=2, cols=3))


def test_light_set_plan_has_only_its_stage(tmp_path):
    doc = {"name": "lit", "kind": "lab", "light": "point",
           "synthetic": {"scene": "tabletop", "seed": 1, "height": 16, "width": 20, "frames": 12,
                         "lights": [{"kind": "point"}, {"kind": "tube", "axis": "u", "length": 0.01}]}}
    path = tmp_path / "lit.yaml"
    path.write_text(yaml.safe_dump(doc))
    plan = capture_plan(path)
    assert plan.stages == ("light_views",) and plan.camera_array is None
    assert len(plan.light_set["lights"]) == 2 and plan.light_set["frames"] == 12
    doc["synthetic"]["lights"][1]["kind"] = "strip"
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ValueError, match="kind"):
        capture_plan(path)
