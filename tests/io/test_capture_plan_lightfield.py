"""Capture plans of kind: lightfield manifests: screens, sweeps, brackets and plan-time errors."""

import pytest
import yaml

from shadowcam.io.capture_plan import capture_plan

RENDERED = {
    "name": "lf", "kind": "lightfield", "light": "area",
    "synthetic": {"scene": "reflector", "seed": 0, "height": 16, "width": 16, "frames": 8},
    "lightfield": {"screens": [{"id": "far", "position_m": 0.45}, {"id": "near", "position_m": 0.25}],
                   "exposure_times_s": [4e-3, 5e-4]},
}


def _write(tmp_path, doc):
    path = tmp_path / f"{doc['name']}.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def _with(**lightfield):
    return {**RENDERED, "lightfield": {**RENDERED["lightfield"], **lightfield}}


def test_rendered_lightfield_plan_orders_screens_and_names_sweeps(tmp_path):
    plan = capture_plan(_write(tmp_path, RENDERED))
    assert plan.is_lightfield and plan.rendered and plan.has_ground_truth
    assert [s["id"] for s in plan.lightfield["screens"]] == ["near", "far"]
    assert [s["position_mm"] for s in plan.lightfield["screens"]] == pytest.approx([250.0, 450.0])
    assert list(plan.sweeps) == ["near_h", "near_v", "far_h", "far_v"]
    assert all(s.n_frames == 8 for s in plan.sweeps.values())
    assert plan.lightfield["brackets"] == 2 and plan.frame_shape == (16, 16)


def test_missing_screen_position_names_the_key(tmp_path):
    doc = _with(screens=[{"id": "near", "position_m": 0.25}, {"id": "far"}])
    with pytest.raises(ValueError, match=r"lightfield\.screens\[1\]\.position_m.*metres"):
        capture_plan(_write(tmp_path, doc))


def test_one_screen_is_not_a_light_field(tmp_path):
    with pytest.raises(ValueError, match=r"lightfield\.screens.*two screen positions"):
        capture_plan(_write(tmp_path, _with(screens=[{"id": "near", "position_m": 0.25}])))


def test_missing_exposure_times_names_the_key_and_the_metadata_option(tmp_path):
    doc = {**RENDERED, "lightfield": {"screens": RENDERED["lightfield"]["screens"]}}
    with pytest.raises(ValueError, match=r"exposure_times_s.*missing.*source: metadata"):
        capture_plan(_write(tmp_path, doc))


def test_brackets_of_different_sizes_are_refused(tmp_path):
    doc = _with(screens=[{"id": "near", "position_m": 0.25, "exposure_times_s": [1e-3, 1e-4, 1e-5]},
                         {"id": "far", "position_m": 0.45}])
    with pytest.raises(ValueError, match=r"brackets of different sizes \{'near': 3, 'far': 2\}"):
        capture_plan(_write(tmp_path, doc))


def test_repeated_screen_position_is_refused(tmp_path):
    doc = _with(screens=[{"id": "a", "position_m": 0.25}, {"id": "b", "position_m": 0.25}])
    with pytest.raises(ValueError, match="repeats a position"):
        capture_plan(_write(tmp_path, doc))


def test_captured_sweep_with_a_broken_bracket_is_refused(tmp_path):
    root = tmp_path / "data"
    files = {}
    for sweep, count in [("near_h", 6), ("near_v", 6), ("far_h", 5), ("far_v", 6)]:
        (root / sweep).mkdir(parents=True)
        for i in range(count):
            (root / sweep / f"f{i}.png").write_bytes(b"x")
        files[sweep] = {"files": f"{sweep}/*.png"}
    import hashlib
    checksums = {p.relative_to(root).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
                 for p in root.rglob("*.png")}
    h = [[0, 1, 0], [1, 0, 0], [0, 0, 1]]
    doc = {"name": "cap", "kind": "lightfield", "light": "area", "root": "data", "sweeps": files,
           "timing": {"source": "rate", "rate_hz": 1.0}, "checksums": checksums,
           "lightfield": {"screens": [{"id": "near", "position_m": 0.25, "homography": h},
                                      {"id": "far", "position_m": 0.45, "homography": h}],
                          "mask": {"position_m": 0.05, "start_m": -0.01, "step_m": 0.001},
                          "exposure_times_s": [1e-3, 1e-4]}}
    with pytest.raises(ValueError, match=r"sweeps\.far_h.*5 files.*multiple of the 2 brackets"):
        capture_plan(_write(tmp_path, doc))
