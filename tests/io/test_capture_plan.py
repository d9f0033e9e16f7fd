"""Tests of shadowcam.io.capture_plan: the facts the workflow plans jobs from."""

import glob
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

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
