"""Camera models end to end: rendered sweeps -> lab.shadow_time -> camera model -> (u, v),
compared with the renderer's exact virtual coordinates; the model choice from a capture
description; degenerate geometry gives a clear ValueError or a reason code, never a
confident wrong coordinate."""

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from shadowcam.cameras.models import (
    frames_to_cross,
    CAMERA_MODELS,
    REASON_FLAGS,
    camera_coords_from_shadow_time,
    camera_linear,
    choose_camera_model,
    declared_sweeps,
    estimate_sweep,
    sweep_rows,
)
from shadowcam.lab.accuracy import dual_coord_errors

SIZE = {"scene": "tabletop", "seed": 3, "height": 40, "width": 40, "frames": 32}
STANDARD = [{"name": "u"}, {"name": "v", "angle_deg": 90}]
SLANTED = [*STANDARD, {"name": "w", "angle_deg": 30, "speed": 1.25}]
CROSS_SLIT = [{"name": "u"}, {"name": "v", "angle_deg": 90, "light_offset": [0.0, 0.0, -0.02],
                                "plane_offset": 0.01}]
ILL, INCONSISTENT = 3, 4


def _errors(gt, coords, names=("u", "v")):
    """Errors of the estimated coordinates against the exact times of sweeps `names` (lit
    pixels timed inside both sweeps)."""
    truth = [gt[f"t_{n}"].values for n in names]
    return dual_coord_errors(coords["u"].values, coords["v"].values, *truth)


@pytest.mark.parametrize("description, expected", [
    ({}, "perspective"),
    ({"light": "area"}, "perspective"),
    ({"light": "distant"}, "orthographic"),
    ({"camera": "orthographic"}, "perspective"),  # a telecentric primal keeps the dual projection
    ({"sweeps": [{"name": "u"}]}, "pushbroom"),
    ({"sweeps": SLANTED}, "linear"),
    ({"sweeps": [{"name": "u"}, {"name": "v", "angle_deg": 90, "speed": 2.0}]}, "linear"),
    ({"sweeps": CROSS_SLIT}, "cross_slit"),
    ({"light": "distant", "sweeps": [{"name": "u", "light_direction": [0, 0, -1]},
                                     {"name": "v", "angle_deg": 90,
                                      "light_direction": [0.1, 0, -1]}]}, "cross_slit"),
])
def test_the_description_decides_the_camera(description, expected):
    assert choose_camera_model(description) == expected
    assert choose_camera_model(description, expected) == expected


@pytest.mark.parametrize("description, model, message", [
    ({"sweeps": [{"name": "a"}, {"name": "b", "angle_deg": 5}, {"name": "c", "angle_deg": 179}]},
     "auto", r"all \(nearly\) parallel"),
    ({"sweeps": STANDARD}, "cross_slit", "each with its own light"),
    ({"light": "distant"}, "perspective", "contradicts description.light"),
    ({"sweeps": [*CROSS_SLIT, {"name": "w", "angle_deg": 45}]}, "auto", "exactly two sweeps"),
    ({"sweeps": [{"name": "u", "speed": 0}]}, "auto", "speed must be"),
    ({"sweeps": [{"name": "u"}, {"name": "u", "angle_deg": 90}]}, "auto", "unique"),
    ({"sweeps": [{"name": "u", "wire": 1}]}, "auto", "unknown keys"),
    ({"light": "laser"}, "auto", "description.light"),
    ({}, "fisheye", "model must be"),
])
def test_inconsistent_descriptions_are_refused(description, model, message):
    with pytest.raises(ValueError, match=message):
        choose_camera_model(description, model)


def test_entries_and_reason_codes():
    assert set(CAMERA_MODELS) == {"perspective", "orthographic", "linear", "cross_slit", "pushbroom"}
    assert REASON_FLAGS[ILL] == "ill_conditioned" and REASON_FLAGS[INCONSISTENT] == "inconsistent"


def test_dataset_names_every_reason_code(timed_capture):
    description = {**SIZE, "sweeps": SLANTED}
    _, _, shadow_time, _ = timed_capture(description)
    coords = camera_coords_from_shadow_time(shadow_time, description)
    assert list(coords["reason"].attrs["flag_values"]) == sorted(REASON_FLAGS)
    assert coords["reason"].attrs["flag_meanings"].split()[-1] == "inconsistent"


@pytest.mark.parametrize("extra, projection", [({}, "perspective"),
                                               ({"light": "distant"}, "orthographic"),
                                               ({"camera": "orthographic"}, "perspective")])
def test_uniform_cameras_end_to_end(timed_capture, extra, projection):
    description = {**SIZE, **extra}
    _, gt, shadow_time, _ = timed_capture(description)
    coords = camera_coords_from_shadow_time(shadow_time, description)
    assert coords.attrs["projection"] == projection
    err = _errors(gt, coords)
    assert err["coverage"] >= 0.95 and err["rmse"] <= 0.3, err


def test_cross_slit_end_to_end(timed_capture):
    description = {**SIZE, "sweeps": CROSS_SLIT}
    _, gt, shadow_time, _ = timed_capture(description)
    coords = camera_coords_from_shadow_time(shadow_time, description)
    assert coords.attrs["method"] == "cross_slit" and coords.attrs["projection"] == "cross-slit"
    err = _errors(gt, coords)
    assert err["coverage"] >= 0.95 and err["rmse"] <= 0.3, err  # the 0.3 dual px RMS


@pytest.mark.parametrize("names", [("u", "v", "w"), ("u", "w"), ("v", "w")])
def test_linear_camera_from_any_two_or_more_sweeps(timed_capture, names):
    description = {**SIZE, "sweeps": SLANTED}
    _, gt, shadow_time, _ = timed_capture(description)
    chosen = {**SIZE, "sweeps": [s for s in SLANTED if s["name"] in names]}
    coords = camera_coords_from_shadow_time(shadow_time, chosen, model="linear")
    assert coords.attrs["method"] == "linear" and coords.attrs["projection"] == "perspective"
    err = _errors(gt, coords)  # truth: the standard pair's exact (u, v)
    assert err["coverage"] >= 0.95 and err["rmse"] <= 0.3, err


def test_estimated_sweep_declaration(timed_capture):
    _, gt, shadow_time, _ = timed_capture({**SIZE, "sweeps": SLANTED})
    times = {n: shadow_time["shadow_time"].sel(sweep=n).values for n in ("u", "v", "w")}
    found = estimate_sweep(times["w"], times["u"], times["v"])
    assert abs(found["angle_deg"] - 30.0) < 0.5 and abs(found["speed"] / 1.25 - 1) < 0.01, found


def _exact_times(sweeps, u, v, dual_shape=(32, 32)):
    rows = sweep_rows(declared_sweeps({"sweeps": sweeps}), dual_shape=dual_shape)
    return {s["name"]: r[0] * u + r[1] * v + r[2] for s, r in zip(sweeps, rows)}


GRID_V, GRID_U = np.mgrid[0:32:4, 0:32:4].astype(np.float64)


@settings(max_examples=40, deadline=None)
@given(angle=st.floats(0.0, 180.0), speed=st.floats(0.05, 20.0), ratio=st.floats(0.01, 100.0))
@example(angle=15.0, speed=1.0, ratio=3.0)  # exactly at min_sweep_angle_deg
def test_exact_times_give_exact_coordinates_or_a_reason(angle, speed, ratio):
    """Any slant (near 0 or 90 deg too) and speeds differing up to 100x: the exact times of
    two sweeps give back (u, v), or the pixels are marked ill_conditioned (never wrong)."""
    sweeps = [{"name": "a", "angle_deg": 0.0, "speed": speed, "frames": 40},
              {"name": "b", "angle_deg": angle, "speed": speed * ratio, "frames": 40}]
    times = _exact_times(sweeps, GRID_U, GRID_V)
    declared = declared_sweeps({"sweeps": sweeps})
    crossing = abs(math.sin(math.radians(angle)))
    if crossing < math.sin(math.radians(15.0)):
        with pytest.raises(ValueError, match="parallel"):
            camera_linear(times, declared, dual_shape=(32, 32))
        return
    u, v, valid, reason, _ = camera_linear(times, declared, dual_shape=(32, 32))
    assert valid.all() and not reason.any()
    np.testing.assert_allclose(u, GRID_U, atol=1e-3 * max(1.0, 1.0 / crossing))
    np.testing.assert_allclose(v, GRID_V, atol=1e-3 * max(1.0, 1.0 / crossing))


def test_nearly_parallel_timed_sweeps_are_ill_conditioned_per_pixel():
    sweeps = [{"name": "a", "frames": 40}, {"name": "b", "angle_deg": 90, "frames": 40},
              {"name": "c", "angle_deg": 5, "frames": 40}]
    times = _exact_times(sweeps, GRID_U, GRID_V)
    times["b"][:2] = np.nan  # there only a and c (5 deg apart) timed the pixels
    u, v, valid, reason, _ = camera_linear(times, declared_sweeps({"sweeps": sweeps}),
                                           dual_shape=(32, 32))
    assert np.all(reason[:2] == ILL) and np.all(np.isnan(u[:2])) and not valid[:2].any()
    assert valid[2:].all()
    np.testing.assert_allclose(u[2:], GRID_U[2:], atol=1e-9)


@settings(max_examples=25, deadline=None)
@given(shift=st.floats(1.5, 30.0), rows=st.integers(1, 7))
def test_times_no_single_point_explains_are_inconsistent(shift, rows):
    """A sweep whose times do not follow its declaration (a light nearly on the wire path
    stretches them) is caught by the redundancy of three sweeps."""
    sweeps = [{"name": "a", "frames": 40}, {"name": "b", "angle_deg": 90, "frames": 40},
              {"name": "c", "angle_deg": 45, "frames": 40}]
    times = _exact_times(sweeps, GRID_U, GRID_V)
    times["c"][:rows] += shift
    u, v, valid, reason, _ = camera_linear(times, declared_sweeps({"sweeps": sweeps}),
                                           dual_shape=(32, 32))
    assert np.all(reason[:rows] == INCONSISTENT) and not valid[:rows].any()
    assert valid[rows:].all()


def test_cross_slit_degenerate_geometry_is_refused():
    parallel = [{"name": "a", "frames": 20, "light_offset": [0, 0, 0.1]},
                {"name": "b", "angle_deg": 2, "frames": 20, "light_offset": [0, 0, -0.1]}]
    times = {"a": np.zeros((4, 4)), "b": np.zeros((4, 4))}
    with pytest.raises(ValueError, match="parallel"):
        CAMERA_MODELS["cross_slit"](times, declared_sweeps({"sweeps": parallel}))
    one_light = [{"name": "a", "frames": 20}, {"name": "b", "angle_deg": 90, "frames": 20}]
    with pytest.raises(ValueError, match="share one light"):
        CAMERA_MODELS["cross_slit"](times, declared_sweeps({"sweeps": one_light}))


def test_front_function_checks_the_data_against_the_description(timed_capture):
    _, _, shadow_time, _ = timed_capture({**SIZE})
    with pytest.raises(ValueError, match="has no sweep"):
        camera_coords_from_shadow_time(shadow_time, {"sweeps": SLANTED})
    with pytest.raises(ValueError, match="must match the 32 frames"):
        camera_coords_from_shadow_time(shadow_time, {"sweeps": [{"name": "u", "frames": 30},
                                                                {"name": "v", "angle_deg": 90}]})


@pytest.mark.parametrize(("shape", "angle", "speed", "expected"), [
    ((48, 48), 0.0, 1.0, 48), ((48, 48), 90.0, 2.0, 24), ((30, 40), 0.0, 3.0, 14),
    ((30, 40), 90.0, 1.0, 30), ((48, 48), 45.0, 1.0, math.ceil(48 * math.sqrt(2))),
    ((4, 4), 0.0, 100.0, 2),
])
def test_frames_to_cross_the_dual_field(shape, angle, speed, expected):
    assert frames_to_cross(shape, angle, speed) == expected



def test_frames_to_cross_needs_a_positive_speed():
    with pytest.raises(ValueError, match="speed"):
        frames_to_cross((20, 20), 0.0, 0.0)


def test_capture_front_runs_the_plans_camera_model(timed_capture):
    from shadowcam.cameras.dual_coords import dual_coords_from_shadow_time
    from shadowcam.cameras.models import capture_dual_coords

    _, gt, shadow_time, _ = timed_capture({**SIZE, "sweeps": SLANTED})
    description = {"light": "point", "sweeps": SLANTED}
    linear = capture_dual_coords(shadow_time, description, camera_model="linear")
    assert linear.attrs["method"] == "linear" and "linear camera" in linear.attrs["model_choice"]
    direct = camera_coords_from_shadow_time(shadow_time, description, model="linear")
    np.testing.assert_array_equal(linear["u"].values, direct["u"].values)
    # the standard pair keeps the dual-coordinate model (frame index = dual coordinate)
    standard = capture_dual_coords(shadow_time, {"sweeps": STANDARD}, camera_model="perspective")
    uniform = dual_coords_from_shadow_time(shadow_time, method="uniform")
    assert standard.attrs["method"] == "uniform"
    np.testing.assert_array_equal(standard["v"].values, uniform["v"].values)
    with pytest.raises(ValueError, match="camera_model"):
        capture_dual_coords(shadow_time, description, camera_model="fisheye")
    with pytest.raises(ValueError, match="min_coverage"):
        capture_dual_coords(shadow_time, description, camera_model="linear", min_coverage=1.0)


@pytest.mark.parametrize("camera", ["orthographic", "ortho_primal", "cross_slit", "mirror", "glass"])
def test_raw_variant_plans_the_same_camera_as_its_noise_free_manifest(camera):
    """data_manifest/synthetic_<camera>_raw.yaml: the same scene, camera and sweeps as the
    noise-free manifest, rendered as noisy 12-bit DNGs."""
    from pathlib import Path

    import yaml

    from shadowcam.io.capture_plan import capture_plan

    root = Path(__file__).resolve().parents[2] / "data_manifest"
    clean, raw = (root / f"synthetic_{camera}.yaml", root / f"synthetic_{camera}_raw.yaml")
    a, b = capture_plan(clean), capture_plan(raw)
    assert b.name == f"synthetic_{camera}_raw"
    assert (a.camera_model, dict(a.camera)) == (b.camera_model, dict(b.camera))
    ya, yb = (yaml.safe_load(p.read_text())["synthetic"] for p in (clean, raw))
    assert (yb["format"], yb["bit_depth"], yb["noise"]) == ("dng", 12, True)
    assert {k: v for k, v in ya.items() if k not in ("format", "noise")} == \
        {k: v for k, v in yb.items() if k not in ("format", "noise")}
