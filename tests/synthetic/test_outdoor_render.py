"""Tests of the outdoor time-lapse renderer (shadowcam.synthetic.outdoor.render, outdoor_capture and the
outdoor branch of ``shadowcam render``) against its exact ground truth."""

import json
from pathlib import Path

import numpy as np
import pytest
import rawpy
import xarray as xr

from shadowcam.io.manifest import frame_times, load_manifest, verify_checksums
from shadowcam.synthetic.outdoor.capture import render_outdoor_capture
from shadowcam.synthetic.outdoor.nuisance import apply_shake
from shadowcam.synthetic.outdoor.render import (frame_radiance, make_outdoor_scene, sample_grid, sun_lit,
                                      trace_samples)
from shadowcam.synthetic.outdoor.terrain import intersect_heightfield

REPO = Path(__file__).resolve().parents[2]
ROWS, COLS, FRAMES, SS = 48, 64, 40, 2
CLEAN = dict(auto_exposure=False, shake_px=0.0, cloud=False, irregular_timing=False,
             dropped_frames=0)


@pytest.fixture(scope="module")
def scene():
    return make_outdoor_scene(seed=1, height=ROWS, width=COLS)


@pytest.fixture(scope="module")
def clean(scene):
    return render_outdoor_capture(scene, frames=FRAMES, supersample=SS, seed=1, **CLEAN)


@pytest.fixture(scope="module")
def samples(scene):
    return trace_samples(scene, *sample_grid(ROWS, COLS, SS))


def test_scene_has_sky_and_every_shadow_class(clean):
    gt = clean.ground_truth
    counts = {c: int((gt.shadow_class == c).sum()) for c in range(4)}
    assert all(n > 0.05 * ROWS * COLS for n in counts.values()), counts
    assert sum(counts.values()) == ROWS * COLS
    np.testing.assert_array_equal(gt.sky_mask, gt.shadow_class == 0)
    np.testing.assert_array_equal(gt.never_shadowed, gt.shadow_class == 1)
    np.testing.assert_array_equal(gt.shadowed_at_start, gt.shadow_class == 2)
    assert not np.any(gt.always_shadowed & ~gt.shadowed_at_start)
    # sky pixels are in the top rows only (the cliff fills the lower image)
    assert gt.sky_mask[-5:].sum() == 0 and gt.sky_mask[0].mean() > 0.5
    assert set(gt.dims) >= {"time", "row", "col", "channel", "subpixel"}
    for name in ("arrival_time_s", "pb_front", "cloud_attenuation", "exposure_gain"):
        assert gt[name].attrs["units"] and gt[name].attrs["long_name"]
    assert "pb_front" in json.loads(gt.attrs["definitions"])


def test_arrival_times_are_bracketed_by_frames(clean):
    gt = clean.ground_truth
    t = gt.times_s.values
    arrives = (gt.shadow_class == 3).values
    T = gt.arrival_time_s.values[arrives]
    k = gt.first_shadowed_frame.values[arrives]
    assert np.all(k >= 1)
    assert np.all((t[k - 1] < T) & (T <= t[k]))
    np.testing.assert_array_equal(np.ceil(gt.arrival_frame.values[arrives]), k)
    lit = gt.lit_center.values
    rows, cols = np.nonzero(arrives)
    assert np.all(lit[k - 1, rows, cols]) and not np.any(lit[k, rows, cols])
    assert np.all(np.isnan(gt.arrival_time_s.values[~arrives]))


def test_shadow_climbs_the_cliff(clean):
    # the sun sets behind the ridge: lower points of a column lose it first
    gt = clean.ground_truth
    T = gt.arrival_time_s.values
    both = (gt.shadow_class.values[:-1] == 3) & (gt.shadow_class.values[1:] == 3)
    assert both.sum() > 500
    assert (T[:-1][both] >= T[1:][both]).mean() > 0.97


def test_arrival_agrees_with_direct_ray_casting(scene, clean):
    # independent check of the horizon table: march the ray toward the sun through the terrain
    gt = clean.ground_truth
    arrives = (gt.shadow_class == 3).values
    points = gt.position_world.values[arrives].astype(np.float64) + [0.0, 0.0, 0.5]
    T = gt.arrival_time_s.values[arrives]
    dt = np.median(np.diff(gt.times_s.values))
    blocked = {}
    for sign in (-1, 1):
        d = scene.sun.direction(T + sign * 0.5 * dt)
        blocked[sign] = ~np.isnan(intersect_heightfield(scene.terrain, points, d))
    assert (~blocked[-1]).mean() > 0.97  # lit half a frame before the GT arrival
    assert blocked[1].mean() > 0.97      # shadowed half a frame after


def test_intensity_drops_between_the_frames_bracketing_arrival(clean):
    gt = clean.ground_truth
    t = gt.times_s.values
    k = gt.first_shadowed_frame.values
    sub = gt.subpixel_arrival_time_s.values
    cls = gt.shadow_class.values
    # pixels whose whole footprint loses the sun between frames k-1 and k
    kk = np.clip(k, 2, FRAMES - 1)
    whole = ((cls == 3) & (k >= 2) & np.all(sub > t[kk - 1][..., None], axis=2)
             & np.all(sub <= t[kk][..., None], axis=2) & ~gt.relit_after_arrival.values)
    assert whole.sum() > 100
    rows, cols = np.nonzero(whole)
    level = clean.frames.mean(axis=3)
    before, at, earlier = (level[kk[whole] - 1, rows, cols], level[kk[whole], rows, cols],
                           level[kk[whole] - 2, rows, cols])
    assert np.all(at < 0.6 * before)          # the sun term goes
    # while lit, the sunset dims it much more slowly than the shadow does
    assert np.all(before - at > 3.0 * np.abs(earlier - before))


def test_lit_fraction_of_the_footprint_matches_subpixel_gt(scene, clean, samples):
    gt = clean.ground_truth
    t = gt.times_s.values
    sub = gt.subpixel_arrival_time_s.values
    n = len(samples.sky)
    # samples that get the sun back after losing it are not described by one arrival time
    lit_all = np.stack([sun_lit(samples, scene.sun, tk) for tk in t])
    first = np.where((~lit_all).any(axis=0), np.argmax(~lit_all, axis=0), FRAMES)
    relit = (lit_all & (np.arange(FRAMES)[:, None] > first)).any(axis=0)
    ok = ~relit.reshape(ROWS, COLS, SS * SS).any(axis=2) & (gt.sky_fraction.values == 0)
    assert ok.mean() > 0.6
    for k in (5, 20, 35):
        covered = (sub > t[k]).mean(axis=2)  # lit fraction of the render samples (GT)
        shown, _ = frame_radiance(samples, scene, t[k], shape=(ROWS, COLS), supersample=SS)
        np.testing.assert_array_equal(shown, clean.frames[k])
        dark, _ = frame_radiance(samples, scene, t[k], shape=(ROWS, COLS), supersample=SS,
                                 lit=np.zeros(n, bool))
        bright, _ = frame_radiance(samples, scene, t[k], shape=(ROWS, COLS), supersample=SS,
                                   lit=np.ones(n, bool))
        span = (bright - dark).sum(axis=2)
        sel = ok & (span > 1e-3)
        image = ((shown - dark).sum(axis=2) / np.where(span > 0, span, 1))[sel]
        c = covered[sel]
        np.testing.assert_allclose(image[c == 0], 0.0, atol=1e-5)
        np.testing.assert_allclose(image[c == 1], 1.0, atol=1e-5)
        part = (c > 0) & (c < 1)
        assert np.all((image[part] > 0) & (image[part] < 1))
        assert np.corrcoef(image[part], c[part])[0, 1] > 0.8
        # the renderer's own sample visibility is the GT's
        lit = sun_lit(samples, scene.sun, t[k]).reshape(ROWS, COLS, SS * SS)
        np.testing.assert_array_equal(lit[ok], (sub > t[k])[ok])


def test_reference_and_pushbroom_follow_their_definitions(clean):
    gt = clean.ground_truth
    np.testing.assert_array_equal(gt.reference_radiance.values, clean.frames[0])
    t = gt.times_s.values
    T = np.where(gt.shadow_class == 1, np.inf,
                 np.where(gt.shadow_class == 2, -np.inf, gt.arrival_time_s)).astype(float)
    y = gt.pb_edge_y.values
    k, u = np.nonzero(np.isfinite(y))
    assert len(k) > FRAMES * COLS * 0.5
    v = np.floor(y[k, u] - 0.5).astype(int)
    assert np.all(T[v, u] > t[k]) and np.all(T[v + 1, u] <= t[k])
    assert np.all(gt.pb_n_transitions.values[k, u] >= 1)
    # single-transition columns: the edge is the only lit-above/shadowed-below pair
    assert (gt.pb_n_transitions.values[k, u] == 1).mean() > 0.9
    front = gt.pb_front.values[k, u]
    ref = gt.reference_radiance.values
    lo = np.minimum(ref[v, u], ref[v + 1, u]) - 1e-6
    hi = np.maximum(ref[v, u], ref[v + 1, u]) + 1e-6
    assert np.all((front >= lo) & (front <= hi))
    counts = gt.pb_bin_count.values
    assert counts.sum() == int((gt.shadow_class == 3).sum())  # every arrival in one bin


@pytest.mark.parametrize("switch, value", [("auto_exposure", True), ("shake_px", 1.0),
                                           ("cloud", True), ("irregular_timing", True)])
def test_nuisance_switches_change_only_what_they_say(scene, clean, switch, value):
    other = render_outdoor_capture(scene, frames=FRAMES, supersample=SS, seed=1,
                                   **dict(CLEAN, **{switch: value}))
    g0, g1 = clean.ground_truth, other.ground_truth
    np.testing.assert_array_equal(g1.shadow_class, g0.shadow_class)
    np.testing.assert_array_equal(g1.reference_radiance, g0.reference_radiance)
    if switch == "irregular_timing":
        t0, t1 = g0.times_s.values, g1.times_s.values
        assert t1[0] == 0 and t1[-1] == pytest.approx(t0[-1], abs=1e-3)
        assert np.ptp(np.diff(t1)) > 0.2 * np.median(np.diff(t1)) > np.ptp(np.diff(t0))
        both = (g0.shadow_class == 3).values
        np.testing.assert_allclose(g1.arrival_time_s.values[both],
                                   g0.arrival_time_s.values[both], atol=1e-3)
        np.testing.assert_array_equal(g1.exposure_gain, 1.0)
        return
    np.testing.assert_array_equal(g1.times_s, g0.times_s)
    np.testing.assert_array_equal(g1.arrival_time_s, g0.arrival_time_s)
    gain, dx, dy = g1.exposure_gain.values, g1.shake_dx_px.values, g1.shake_dy_px.values
    if switch == "auto_exposure":
        assert np.all(dx == 0) and np.all(dy == 0)
        assert gain[-1] > 2.0  # the sunset is compensated
        np.testing.assert_allclose(other.frames, gain[:, None, None, None] * clean.frames,
                                   rtol=1e-6)
    elif switch == "shake_px":
        np.testing.assert_array_equal(gain, 1.0)
        r = np.hypot(dx, dy)
        assert r.max() <= 1.0 + 1e-9 and r.max() > 0.5 and 0.1 < np.sqrt(np.mean(r**2)) < 0.6
        for k in (3, 17):
            np.testing.assert_allclose(other.frames[k],
                                       apply_shake(clean.frames[k], dx[k], dy[k]), atol=1e-6)
    else:
        np.testing.assert_array_equal(gain, 1.0)
        att = g1.cloud_attenuation.values
        assert att.min() < 0.8 and np.all(att <= 1.0)
        assert np.all(other.frames <= clean.frames + 1e-6)
        free = np.broadcast_to((att == 1.0)[..., None], other.frames.shape)
        np.testing.assert_allclose(other.frames[free], clean.frames[free], rtol=1e-6)


def test_outdoor_manifests_validate():
    full = load_manifest(REPO / "data_manifest" / "synthetic_ridge.yaml")
    clean = load_manifest(REPO / "data_manifest" / "synthetic_ridge_clean.yaml")
    assert full["kind"] == clean["kind"] == "outdoor" and full["light"] == "distant"
    off = clean["synthetic"]["outdoor"]
    assert not (off["auto_exposure"] or off["cloud"] or off["irregular_timing"])
    assert off["shake_px"] == 0 and off["dropped_frames"] == 0 and not clean["synthetic"]["noise"]
    on = full["synthetic"]["outdoor"]
    assert on["auto_exposure"] and on["cloud"] and on["shake_px"] > 0 and on["dropped_frames"]


def test_accuracy_condition_is_clean_only_without_any_nuisance():
    from shadowcam.synthetic.capture_options import OUTDOOR_OPTIONS, accuracy_condition

    clean = dict(OUTDOOR_OPTIONS, auto_exposure=False, shake_px=0, cloud=False,
                 irregular_timing=False, dropped_frames=0)
    assert accuracy_condition(False, clean) == "clean"
    assert accuracy_condition(True, clean) == "nuisances"
    for key, value in (("auto_exposure", True), ("shake_px", 0.5), ("cloud", True),
                       ("irregular_timing", True), ("dropped_frames", 2)):
        assert accuracy_condition(False, dict(clean, **{key: value})) == "nuisances"


def test_render_cli_writes_an_outdoor_capture(tmp_path):
    from shadowcam.cli import main
    from shadowcam.synthetic.sensor import mosaic_rggb

    manifest = tmp_path / "tiny_ridge.yaml"
    manifest.write_text(
        "name: tiny_ridge\nkind: outdoor\nlight: distant\n"
        "synthetic: {scene: ridge, seed: 2, height: 32, width: 48, frames: 14, format: dng,"
        " bit_depth: 14, noise: false, supersample: 1, exposure: 0.5,"
        " outdoor: {auto_exposure: true, shake_px: 0, cloud: false, dropped_frames: 1}}\n")
    out = tmp_path / "capture"
    assert main(["render", "--manifest", str(manifest), "--out", str(out)]) == 0
    cap = load_manifest(out / "capture.json")
    verify_checksums(cap)
    assert cap["kind"] == "outdoor" and cap["light"] == "distant"
    # auto-exposure steps and a dropped frame are nuisances: the nuisance targets apply
    assert cap["ground_truth"] == {"format": "shadowcam_outdoor_nc", "file": "ground_truth.nc",
                                   "noise": "nuisances"}
    paths = [Path(p) for p in cap["sweeps"]["timelapse"]["paths"]]
    assert len(paths) == 14
    gt = xr.open_dataset(out / "ground_truth.nc", engine="h5netcdf")
    side = np.array(cap["sweeps"]["timelapse"]["times_s"])
    meta = np.array(frame_times(paths, {"source": "metadata"}, root=out, sweep="timelapse"))
    np.testing.assert_allclose(side, gt.times_s.values, atol=1e-9)
    np.testing.assert_allclose(meta, gt.times_s.values, atol=1e-5)  # ms in SubsecTimeOriginal
    stamps = json.loads((out / "timestamps.json").read_text())
    assert len(stamps["dropped_nominal_indices"]) == 1
    from shadowcam.io.decode import header_metadata

    exposure = [header_metadata(p)["exposure_s"] for p in paths]
    np.testing.assert_allclose(exposure, gt.exposure_time_s.values, rtol=1e-6)
    np.testing.assert_allclose(exposure, 0.004 * 2.0 ** gt.ae_ev.values, rtol=2e-4)
    # frame 0 (gain = 1 x flicker, no shake, noise-free) is the reference radiance, exposed
    with rawpy.imread(str(paths[0])) as raw:
        dn = raw.raw_image_visible.astype(float)
        black = raw.black_level_per_channel[0]
    expected = black + gt.attrs["electrons_per_unit_radiance"] * gt.exposure_gain.values[0] * \
        mosaic_rggb(gt.reference_radiance.values.astype(float))
    np.testing.assert_allclose(dn, np.round(expected), atol=1.0)
    assert gt.attrs["step"] == "render" and json.loads(gt.attrs["input_checksums"])
    gt.close()


def test_state_gains_are_the_median_ratios_of_whole_sun_and_no_sun_pixels():
    from shadowcam.synthetic.outdoor.truth import state_gains

    rng = np.random.default_rng(3)
    first = rng.uniform(0.2, 1.0, (6, 8, 3))
    seen = np.zeros((3, 6, 8))
    seen[:, :2] = 1.0      # whole sun in every frame: x 0.8 of the light
    seen[:, 2] = 0.5       # partly: left out
    seen[2, 1] = 0.7       # row 1 loses part of the sun in frame 2: left out there
    sky = np.zeros((6, 8), bool)
    sky[5] = True
    clear = np.stack([first, first * np.where(seen[1][..., None] == 1, 0.8, 0.9),
                      first * np.where(seen[2][..., None] == 1, 0.8, 0.9)])
    clear[:, 5] = 7.0  # sky pixels: left out
    lit_gain, sky_gain = state_gains(clear, seen, sky, exposure_gain=np.array([1.0, 2.0, 4.0]))
    np.testing.assert_allclose(lit_gain, [1.0, 1.6, 3.2], rtol=1e-12)
    np.testing.assert_allclose(sky_gain, [1.0, 1.8, 3.6], rtol=1e-12)
    _, none = state_gains(clear, np.ones_like(seen), sky, exposure_gain=np.ones(3))
    assert np.isnan(none).all()


def test_capture_truth_holds_the_lit_and_sky_gains(clean):
    truth = clean.ground_truth
    # no nuisance: exposure 1, so the gains are the light's own change (the sun and the sky fading)
    assert truth["lit_gain"].values[0] == 1.0 and truth["sky_gain"].values[0] == 1.0
    assert np.all(np.diff(truth["sky_gain"].values) < 0)  # the sky dims as the sun sets
    assert np.all(truth["lit_gain"].values[1:] < 1)
