"""Methods comparison: Pareto front, and every method measured against exact truth."""

import numpy as np
import pytest

from shadowcam.lab.accuracy import shadow_time_errors
from shadowcam.evaluate.speed_benchmark import WireScene
from shadowcam.evaluate.methods_comparison import (
    compare_dual_view_methods, compare_shadow_time_methods, methods_dataset, pareto_front,
    speed_error_figure,
)
from shadowcam.lab.shadow_time import SHADOW_TIME_METHODS


def test_pareto_front_keeps_only_undominated_rows():
    speed = [10, 20, 5, 20, 1]
    error = [0.5, 0.4, 0.1, 0.6, np.nan]
    np.testing.assert_array_equal(pareto_front(speed, error), [False, True, True, False, False])
    with pytest.raises(ValueError, match="throughput and error"):
        pareto_front([1, 2], [1])


def _scene_sweep():
    # the library's WireScene, not the wire_sweep fixture: the comparison is measured on the benchmark's own scene
    scene = WireScene(height=32, width_px=48, n_frames=36, px_per_frame=2.0, t0=4.0, seed=1)
    albedo = scene.albedo()
    frames = np.stack([scene.frame(k, albedo) for k in range(scene.n_frames)])

    def blocks():
        return (frames[i:i + 8] for i in range(0, len(frames), 8))

    truth = scene.truth()
    return blocks, truth, np.ones(truth.shape, bool)


def test_every_shadow_time_method_is_measured_against_the_truth():
    blocks, truth, lit = _scene_sweep()
    rows = compare_shadow_time_methods({"u": (blocks, truth, lit)})
    assert [r["method"] for r in rows] == list(SHADOW_TIME_METHODS)
    by_name = {r["method"]: r for r in rows}
    for row in rows:
        assert row["throughput"] > 0 and row["seconds"] > 0 and row["peak_mib"] > 0
        assert row["coverage"] > 0.9
    # noise-free, two pixels per frame: the edge-aware fit is sub-tenth-frame, a purely
    # temporal estimate is limited by the on/off profile
    assert by_name["edge_fit"]["p95"] < 0.1 < by_name["midpoint_crossing_BouguetPerona1998"]["p95"]
    # the pooled p95 of one sweep is the accuracy module's p95
    from shadowcam.lab.shadow_time import summary_shadow_times, track_sweep

    summary, _, _ = track_sweep(blocks(), truth.shape)
    expected = shadow_time_errors(summary_shadow_times(summary)["shadow_time"], truth, lit=lit)
    assert by_name["edge_fit"]["p95"] == pytest.approx(expected["p95"], rel=1e-12)


def test_dual_view_methods_reproduce_a_smooth_reciprocal_image():
    rows_, cols_ = np.mgrid[0:64, 0:64].astype(float)
    u, v = 0.5 * cols_ + 0.1 * rows_, 0.45 * rows_  # affine camera -> dual map
    def texture(a, b):
        return np.stack([1 + 0.3 * np.sin(a / 5), 1 + 0.3 * np.cos(b / 7), 1 + 0.01 * a], axis=-1)
    colours = texture(u, v).astype(np.float32)
    grid_v, grid_u = np.mgrid[0:28, 0:30].astype(float)
    reciprocal = texture(grid_u, grid_v)
    visible = np.ones((28, 30), bool)
    rows = compare_dual_view_methods(colours, u, v, shape=(28, 30), valid=np.ones(u.shape, bool),
                                     reciprocal=reciprocal, dual_cam_visible=visible)
    assert {r["method"] for r in rows} == {"mesh", "idw"}
    for row in rows:
        assert row["p95"] < 0.02, row  # relative RMSE inside the covered mask
        assert row["coverage"] > 0.8


def test_dataset_marks_the_front_per_stage_and_the_figure_has_a_panel_per_stage():
    rows = [
        {"stage": "shadow_time", "method": "a", "seconds": 1.0, "throughput": 10.0, "peak_mib": 1.0,
         "p50": 0.1, "p95": 0.2, "coverage": 1.0},
        {"stage": "shadow_time", "method": "b", "seconds": 2.0, "throughput": 5.0, "peak_mib": 1.0,
         "p50": 0.1, "p95": 0.3, "coverage": 1.0},
        {"stage": "dual_view", "method": "mesh", "seconds": 1.0, "throughput": 1.0, "peak_mib": 1.0,
         "p50": np.nan, "p95": 0.05, "coverage": 0.9},
    ]
    ds = methods_dataset(rows)
    np.testing.assert_array_equal(ds["pareto"].values, [True, False, True])
    assert ds["p95"].attrs["units"]
    figure = speed_error_figure(ds)
    assert len(figure.axes) == 2


def test_every_minima_method_is_scored_on_a_two_light_capture():
    from shadowcam.evaluate.methods_comparison import MINIMA_METHODS, compare_minima_methods
    from shadowcam.lab.light_views import light_set_accuracy, light_set_views
    from shadowcam.synthetic.lab.light_set_capture import render_light_set_capture

    capture = render_light_set_capture({
        "scene": "tabletop", "seed": 2, "height": 24, "width": 24, "frames": 32, "supersample": 1,
        "lights": [{"kind": "point"}, {"kind": "point", "offset": [0.01, 0.01, 0.0]}]})
    rows = compare_minima_methods(capture, methods=["dip_centroid", "argmin_parabolic"])
    assert [r["method"] for r in rows] == ["dip_centroid", "argmin_parabolic"]
    assert "edge_fit" in MINIMA_METHODS  # the stage's method, over each light's own map
    for row in rows:
        assert row["stage"] == "several_minima" and row["throughput"] > 0 and row["peak_mib"] > 0
        assert 0.9 < row["coverage"] <= 1.0
        assert row["p50"] <= row["p95"] < 1.0  # frames, against the renderer's per-light times
    # the pooled figures are those of the per-light accuracy: the worst light-sweep p95
    # bounds the pooled p95 from above, the best from below
    acc = light_set_accuracy(light_set_views(capture, method="dip_centroid"), capture)["lights"]
    per_light = [entry[s]["p95_error"] for entry in acc for s in ("u", "v")]
    assert min(per_light) <= rows[0]["p95"] <= max(per_light)
    with pytest.raises(ValueError, match="cannot time several minima"):
        compare_minima_methods(capture, methods=["edge_plane"])
