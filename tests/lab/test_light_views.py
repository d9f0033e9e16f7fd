"""Per-light shadow cameras from a rendered several-lights capture (paper Fig. 11)."""

import numpy as np
import pytest

from shadowcam.lab.light_views import (
    check_light_order, light_positions, light_set_accuracy, light_set_errors, light_set_views,
)
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
