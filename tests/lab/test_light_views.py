"""Per-light shadow cameras from a rendered several-lights capture (paper Fig. 11)."""

from dataclasses import replace

import numpy as np
import pytest

from shadowcam.io.cfa import demosaic_bilinear
from shadowcam.lab.light_views import (
    _gather_light, check_light_order, light_positions, light_set_accuracy, light_set_errors, light_set_views,
    match_sweep_lights, sweep_light_times,
)
from shadowcam.lab.minima import OK, find_minima
from shadowcam.lab.shadow_time_methods import _site_times
from shadowcam.lab.site_signal import cfa_site_colours
from shadowcam.synthetic.lab.light_set_capture import render_light_set_capture

BASE = {"scene": "tabletop", "seed": 2, "height": 32, "width": 32, "frames": 40, "supersample": 2}


def test_two_point_lights_apart_in_both_sweeps_get_two_shadow_cameras():
    lights = [{"kind": "point"}, {"kind": "point", "offset": [0.01, 0.01, 0.0]}]
    capture = render_light_set_capture({**BASE, "lights": lights})
    views = light_set_views(capture, method="dip_centroid")
    acc = light_set_accuracy(views, capture)
    assert views["dual_view"].dims == ("light", "v", "u", "channel")
    for entry in acc["lights"]:
        for sweep in ("u", "v"):
            figures = entry[sweep]
            assert figures["n_scored"] > 300
            assert figures["coverage"] > 0.95
            # the dip-centroid timing of thin dips on this render (outlines included)
            assert figures["p95_error"] < 0.35
            assert figures["contrast"] == pytest.approx(0.5, abs=0.05)
    # each light's dual view is covered where its two time maps are
    assert np.all(views["coverage"].values.mean(axis=(1, 2)) > 0.3)
    # ten timed pixels moved to the other light's time (+14 frames), confidence 0.25: the
    # false-time rate rises by exactly 10 / timed, their median confidence is 0.25
    before = acc["lights"][0]["u"]
    moved = views.copy(deep=True)
    error, scored = light_set_errors(views, capture)["u", 0]
    rows, cols = np.nonzero(scored & (error <= 1.0))
    moved["time"].values[0, 0, rows[:10], cols[:10]] += 14.0
    moved["confidence"].values[0, 0, rows[:10], cols[:10]] = 0.25
    after = light_set_accuracy(moved, capture)["lights"][0]["u"]
    timed = round(before["coverage"] * before["n_scored"])
    assert after["false_rate"] == pytest.approx(before["false_rate"] + 10 / timed, abs=1e-12)
    assert before["confidence_false"] is None or before["false_rate"] > 0
    if before["false_rate"] == 0:
        assert after["confidence_false"] == pytest.approx(0.25)


def test_a_tube_across_a_sweep_is_flagged_there_when_the_window_is_short():
    """A tube along e_v: sharp in the u sweep, spread across its projection in the v sweep
    (paper Fig. 11): with half_window 4 the v dips are wider than the window and are
    flagged; the few timed ones lie in the central half of the shadow's interval (the
    centroid of a tube's shadow is not exactly its centre's time under perspective)."""
    capture = render_light_set_capture({**BASE, "lights": [{"kind": "tube", "axis": "v", "length": 0.012}]})
    views = light_set_views(capture, half_window=4)
    acc = light_set_accuracy(views, capture)["lights"][0]
    assert acc["u"]["coverage"] > 0.95 and acc["u"]["contrast"] > 0.9
    assert acc["v"]["contrast"] < 0.3
    assert acc["v"]["reasons"]["wide_dip"] + acc["v"]["reasons"]["minima_count"] > 0.5 * acc["v"]["n_scored"]
    err = np.abs(views["time"].values[1, 0] - capture["t_center_v"].values[0])
    spread = capture["t_last_v"].values[0] - capture["t_first_v"].values[0]
    timed = np.isfinite(err)
    assert np.all(err[timed] < spread[timed] / 4)


def test_an_open_shutter_removes_the_staircase_of_thin_dips():
    """Exposure over the whole frame interval (``shutter: 1``, as the single-light lab
    renderer) integrates the moving wire, so a thin dip's centroid follows its sub-frame
    time; an instant exposure samples a boxcar (a staircase of times). Same render
    otherwise; 32 x 32, so outline pixels (two surfaces in one footprint) weigh more
    than at the workflow's 48 x 48."""
    lights = [{"kind": "point"}, {"kind": "point", "offset": [0.01, 0.01, 0.0]}]
    p95 = {}
    for shutter in (0.0, 1.0):
        capture = render_light_set_capture({**BASE, "lights": lights, "shutter": shutter})
        acc = light_set_accuracy(light_set_views(capture), capture)
        p95[shutter] = [entry[s]["p95_error"] for entry in acc["lights"] for s in ("u", "v")]
        assert all(entry[s]["coverage"] > 0.98 for entry in acc["lights"] for s in ("u", "v"))
    assert min(p95[0.0]) > 0.2
    assert max(p95[1.0]) < 0.15


def test_the_lights_positions_come_from_the_gaps_between_their_shadows():
    y, x = np.indices((20, 30))
    base = 5.0 + 0.4 * x + 0.1 * y
    times = np.stack([base, base + 10.0, base + 30.0])
    position, spread = light_positions(times)
    np.testing.assert_allclose(position, [0.0, 10.0, 30.0], atol=1e-12)
    np.testing.assert_allclose(spread, 0.0, atol=1e-12)
    # described in metres, in any light order: scaled to frames and sorted along the sweep
    np.testing.assert_allclose(check_light_order(position, spread, [0.02, -0.01, 0.0], sweep="u"),
                               [0.0, 10.0, 30.0], atol=1e-9)
    # a description with the middle light elsewhere: the error names the key
    with pytest.raises(ValueError, match="light_along_v"):
        check_light_order(position, spread, [0.0, 0.015, 0.03], sweep="v")
    # ... unless the first light is timed in few of its pixels: its gap is no evidence
    np.testing.assert_allclose(check_light_order(position, spread, [0.0, 0.015, 0.03], sweep="v",
                                                 seen=[0.02, 0.9, 0.9]), [0.0, 20.0, 40.0], atol=1e-9)
    # two lights: one gap, any description fits it
    np.testing.assert_allclose(check_light_order(position[:2], spread[:1], [0.0, -0.01], sweep="u"),
                               [0.0, 10.0], atol=1e-9)
    # a gap measured from scattered noise minima (spread above tolerance) is not checked
    rng = np.random.default_rng(0)
    noisy = times.copy()
    noisy[0] = times[1] - rng.uniform(2.0, 14.0, times[1].shape)
    position, spread = light_positions(noisy)
    assert spread[0] > 2.0 and spread[1] == 0.0
    expected = check_light_order(position, spread, [0.0, 0.015, 0.03], sweep="u")
    np.testing.assert_allclose(expected, [0.0, 20.0, 40.0], atol=1e-9)  # scaled on the one consistent gap


def test_edge_fit_over_each_lights_map_lowers_the_noisy_tail():
    """12-bit sensor noise, open shutter: each light's centroids weighed against its own
    neighbours' plane; the same pixels are timed, and the p95 error pooled over the lights
    and sweeps falls (per light and sweep it need not: 3 of 4 fall on this render)."""
    lights = [{"kind": "point"}, {"kind": "point", "offset": [0.01, 0.01, 0.0]}]
    capture = render_light_set_capture({**BASE, "lights": lights, "noise": True, "bit_depth": 12,
                                        "shutter": 1})
    centroid = light_set_views(capture, method="dip_centroid")
    refined = light_set_views(capture, method="edge_fit")
    np.testing.assert_array_equal(np.isfinite(refined["time"].values), np.isfinite(centroid["time"].values))

    def pooled(views):
        errors = [e[s] for e, s in light_set_errors(views, capture).values()]
        errors = np.concatenate(errors)
        return np.percentile(errors[np.isfinite(errors)], 95)

    assert pooled(refined) < pooled(centroid)  # 0.477 -> 0.464 frame on this render


def test_a_description_whose_spacing_the_shadows_contradict_is_an_error_naming_the_key():
    lights = [{"kind": "point"}, {"kind": "point", "offset": [0.008, 0.008, 0.0]},
              {"kind": "point", "offset": [-0.008, -0.008, 0.0]}]
    capture = render_light_set_capture({**BASE, "lights": lights, "frames": 48})
    views = light_set_views(capture, method="dip_centroid")
    # equally spaced lights: equal gaps along both sweeps (frames from the first light)
    for s in range(2):
        position = views["position"].values[s][np.argsort(capture[f"light_along_{'uv'[s]}"].values)]
        assert abs((position[2] - position[1]) - (position[1] - position[0])) < 1.0
    wrong = capture.copy()
    along = capture["light_along_u"].values
    wrong["light_along_u"] = ("light", np.array([along[0], along[1], along[0] - 3 * (along[1] - along[0])]))
    with pytest.raises(ValueError, match="light_along_u"):
        light_set_views(wrong, method="dip_centroid")
    unchecked = light_set_views(wrong, method="dip_centroid", check_order=False)
    assert unchecked.attrs["order_checked"] == 0


# ------------------------------------------------------------- RAW: each pixel's own mosaic site

RAW_SHAPE = (24, 32)


def _raw_two_shadow_sweep(wire_sweep, *, electrons=None, seed=3):
    """Demosaiced 12-bit RGGB frames of a textured plane crossed by two shadows 24 frames apart.

    Each shadow is ``wire_sweep``'s (centre line at ``t0 + x + 0.3 y`` frames); a pixel's
    light is its texture times both shadows' transmissions. With `electrons` (per unit
    signal, 1 DN each) Poisson and 6 DN read noise. Returns frames ``(T, H, W, 3)`` and the
    two true time maps ``(2, H, W)`` in sweep order.
    """
    white, black = 4095, 256
    first, t_first = wire_sweep(shape=RAW_SHAPE, level=1.0, n_frames=72, px_per_frame=1.0, t0=4.0, tilt=0.3)
    second, t_second = wire_sweep(shape=RAW_SHAPE, level=1.0, n_frames=72, px_per_frame=1.0, t0=28.0, tilt=0.3)
    rng = np.random.default_rng(seed)
    site = cfa_site_colours(RAW_SHAPE, "RGGB").astype(np.intp)
    own = np.take_along_axis(0.3 + 0.6 * rng.random(RAW_SHAPE + (3,)), site[..., None], axis=2)[..., 0]
    frames = np.empty(first.shape + (3,), np.float32)
    for k in range(first.shape[0]):
        signal = own * first[k] * second[k]
        dn = signal * (white - black)
        if electrons is not None:
            dn = rng.poisson(signal * electrons) + rng.normal(0.0, 6.0, signal.shape)
        raw = np.clip(np.round(black + dn), 0, white).astype(np.uint16)
        frames[k] = (demosaic_bilinear(raw, pattern="RGGB", max_value=white) - black) / (white - black)
    return frames, np.stack([t_first, t_second])


def _raw_errors(times, truth):
    """|time - truth| of each light over the inner pixels (the mirrored border taps are not the scene's)."""
    inner = np.zeros(RAW_SHAPE, bool)
    inner[1:-1, 1:-1] = True
    return [np.abs(times["time"][k] - truth[k])[inner] for k in range(truth.shape[0])]


def test_raw_lights_are_timed_from_the_own_site_to_the_quantisation(wire_sweep):
    frames, truth = _raw_two_shadow_sweep(wire_sweep)
    new, _ = sweep_light_times(frames, 2, sweep="u", cfa_pattern="RGGB")
    old, _ = sweep_light_times(frames, 2, sweep="u")  # the channel sum's times
    np.testing.assert_array_equal(new["reason"], old["reason"])
    for err_new, err_old in zip(_raw_errors(new, truth), _raw_errors(old, truth)):
        assert np.isfinite(err_new).mean() > 0.95
        # 12-bit quantisation: 1 DN in >= 1150 (the darkest site) on each of the ~3 covered
        # samples moves the centroid by < 3 * (4 frames) / 1150 / 2 = 0.005 frame
        assert np.nanpercentile(err_new, 95) < 0.01
        # the channel sum blends the neighbours' sites, shadowed up to 1.3 frames apart
        assert np.nanpercentile(err_old, 95) > 0.05


def test_dim_raw_lights_fall_back_to_the_channel_sum_without_losing_coverage(wire_sweep):
    # 60 electrons at full scale: some own-site dips are not significant on their own
    frames, truth = _raw_two_shadow_sweep(wire_sweep, electrons=60.0)
    colour = cfa_site_colours(RAW_SHAPE, "RGGB")
    new, _ = sweep_light_times(frames, 2, sweep="u", cfa_pattern="RGGB")
    old, _ = sweep_light_times(frames, 2, sweep="u")
    for key in ("reason", "minimum", "shown"):  # the same minima, lights and timed pixels
        np.testing.assert_array_equal(new[key], old[key])
    minima = find_minima(frames, RAW_SHAPE, count=2, site_colour=colour)
    ok = minima.reason == OK
    fallen_back = 0
    for k in range(2):  # minimum k, each sweep's k-th shadow
        index = np.full((1,) + RAW_SHAPE, k)
        light = replace(minima.summary, **_gather_light(minima.summary, index, ok[k]))
        own_time, _, _ = _site_times(light, replace(minima.summary.site,
                                                    **_gather_light(minima.summary.site, index, ok[k])))
        fallen_back += (ok[k] & ~np.isfinite(own_time)).sum()
    assert fallen_back > 0.05 * ok.sum()  # the fallback is exercised (11-12 % here)
    for err_new, err_old in zip(_raw_errors(new, truth), _raw_errors(old, truth)):
        assert np.isfinite(err_new).mean() == np.isfinite(err_old).mean() > 0.8
        # no worse than the channel sum's beyond the p95's sampling error (n ~ 580: ~4 % of it)
        assert np.nanpercentile(err_new, 95) <= 1.1 * np.nanpercentile(err_old, 95)


def test_the_own_site_window_is_the_sites_channel_over_the_channel_sums_level():
    # a flat grey plane, one dip of depth 1/2 per pixel at frame 10: the demosaic's channels are
    # all the site's value, so each site is a third of the channel sum, lit or shadowed
    frames = np.ones((24, 6, 8, 3), np.float32)
    frames[9:12] *= np.array([0.75, 0.5, 0.75], np.float32)[:, None, None, None]
    colour = cfa_site_colours((6, 8), "RGGB")
    minima = find_minima(frames, (6, 8), count=1, half_window=2, site_colour=colour)
    site = minima.summary.site
    np.testing.assert_allclose(site.level, 1.0 / 3.0, rtol=1e-6)
    np.testing.assert_allclose(site.neighbour_level, 2.0 / 3.0, rtol=1e-6)
    assert np.array_equal(site.colour, colour)
    finite = np.isfinite(site.window)
    np.testing.assert_allclose(site.window[finite], minima.summary.window[finite] / 3.0, rtol=1e-6)
    plain = find_minima(frames, (6, 8), count=1, half_window=2)
    for name in ("time", "reason", "frame", "depth"):
        np.testing.assert_array_equal(getattr(plain, name), getattr(minima, name))
    with pytest.raises(ValueError, match="site_colour"):
        find_minima(frames, (6, 8), count=1, site_colour=colour[:5])


# ------------------------------------------------- which u light is which v light (no description)

#: two point lights whose shadows pass in one order in the u sweep and in the other in the v sweep
CROSSED = [{"kind": "point", "offset": [0.012, -0.012, 0.0]}, {"kind": "point", "offset": [-0.012, 0.012, 0.0]}]


def _undescribed(capture):
    """The capture without ``light_along_*``, and its truth relabelled as the stage numbers the
    lights then: light k is the k-th shadow to pass in the u sweep."""
    order = np.argsort(capture["light_along_u"].values, kind="stable")
    truth = capture.isel(light=order).assign_coords(light=np.arange(capture.sizes["light"]))
    return capture.drop_vars(["light_along_u", "light_along_v"]), truth


@pytest.mark.parametrize("noise, p95_target", [(False, 0.35), (True, 1.0)])
def test_lights_in_another_order_in_each_sweep_are_paired_by_their_contrast_maps(noise, p95_target):
    """Light A's shadow passes first in u and second in v: without ``light_along_*`` the
    contrast maps pair the sweeps' lights, exactly as the description does. Targets: the
    dip-centroid target of the noise-free render (0.35 frame); with 12-bit noise (no mosaic,
    32 x 32) below the false-time distance, 1 frame (the wrong pairing is 23-24 frames off)."""
    extra = {"noise": True, "bit_depth": 12} if noise else {}
    capture = render_light_set_capture({**BASE, "lights": CROSSED, "shutter": 1, **extra})
    assert np.argmax(capture["light_along_u"].values) != np.argmax(capture["light_along_v"].values)
    plain, truth = _undescribed(capture)
    measured = light_set_views(plain)
    assert measured.attrs["pairing"] == "measured" and measured.attrs["pairing_decided"] == 1
    assert measured.attrs["pairing_z"] > 3.09
    described = light_set_views(capture)
    assert described.attrs["pairing"] == "described"
    # the same times as the description's, the lights numbered in the u sweep's order
    order = np.argsort(capture["light_along_u"].values, kind="stable")
    np.testing.assert_array_equal(measured["time"].values, described["time"].values[:, order])
    accuracy = light_set_accuracy(measured, truth)
    assert accuracy["pairing"] == {"how": "measured", "z": measured.attrs["pairing_z"], "decided": True}
    for entry in accuracy["lights"]:
        for sweep in ("u", "v"):
            assert entry[sweep]["n_scored"] > 300 and entry[sweep]["coverage"] > 0.95
            assert entry[sweep]["p95_error"] < p95_target


def test_lights_at_nearly_one_place_are_flagged_not_paired_by_chance():
    """Two lights 0.007 scene units apart (offsets +-0.0025 along e_u and e_v; the crossed pair
    above is 0.034 apart), 12-bit noise: their contrast maps
    differ by less than the noise, so the pairing is flagged (attrs and a warning naming the
    reason) and the sweeps keep their shadow order."""
    lights = [{"kind": "point", "offset": [0.0025, -0.0025, 0.0]}, {"kind": "point", "offset": [-0.0025, 0.0025, 0.0]}]
    capture = render_light_set_capture({**BASE, "lights": lights, "shutter": 1, "noise": True, "bit_depth": 12})
    plain, _ = _undescribed(capture)
    with pytest.warns(UserWarning, match="do not tell them apart"):
        views = light_set_views(plain)
    assert views.attrs["pairing"] == "shadow_order" and views.attrs["pairing_decided"] == 0
    assert views.attrs["pairing_z"] <= 3.09


def test_a_description_the_contrast_maps_contradict_is_an_error_naming_the_key():
    """Two lights: one gap fits any spacing (``check_light_order`` cannot see a swap), but the
    contrast maps pair the sweeps' lights and see the v description swapped."""
    capture = render_light_set_capture({**BASE, "lights": CROSSED, "shutter": 1})
    swapped = capture.copy()
    swapped["light_along_v"] = ("light", capture["light_along_v"].values[::-1].copy())
    with pytest.raises(ValueError, match="light_along_u / light_along_v"):
        light_set_views(swapped, method="dip_centroid")
    with pytest.warns(UserWarning, match="light_along_u / light_along_v"):
        light_set_views(swapped, method="dip_centroid", check_order=False)


def test_the_match_of_equal_maps_is_undecided_and_of_distinct_maps_decided():
    """Unit case: contrast maps that differ in their spatial pattern pair whatever the order,
    equal maps (up to noise) cannot be told apart."""
    rng = np.random.default_rng(5)
    y, x = np.indices((30, 40))
    maps = np.stack([0.3 + 0.2 * x / 40, 0.5 - 0.2 * y / 30])
    times = np.ones_like(maps)
    noisy = maps + rng.normal(0, 0.01, maps.shape)
    match = match_sweep_lights(maps, times, [True, True], noisy[::-1], times, [True, True])
    np.testing.assert_array_equal(match["order"], [1, 0])
    assert match["decided"] and match["z"] > 20
    equal = np.stack([maps[0], maps[0]])
    match = match_sweep_lights(equal, times, [True, True], equal + rng.normal(0, 0.01, equal.shape), times,
                               [True, True])
    assert not match["decided"] and "do not tell them apart" in match["reason"]
    # a light one sweep does not show gives no evidence: with two lights nothing is left to
    # compare the per-pixel ratio with; with three the two others decide
    match = match_sweep_lights(maps, times, [True, True], noisy[::-1], times, [True, False])
    assert not match["decided"] and "fewer than two lights" in match["reason"]
    three = np.concatenate([maps, [0.2 + 0.3 * (x + y) / 70]])
    times3 = np.ones_like(three)
    v_maps = three[[1, 0, 2]] + rng.normal(0, 0.01, three.shape)
    match = match_sweep_lights(three, times3, [True] * 3, v_maps, times3, [True, True, False])
    np.testing.assert_array_equal(match["order"], [1, 0, 2])
    assert match["decided"]
