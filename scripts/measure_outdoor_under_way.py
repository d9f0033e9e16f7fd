"""The outdoor arrival by pixel group: penumbra inside the record, under way at the first frame, cut by the end.

Usage::

    python scripts/measure_outdoor_under_way.py [render options of measure_outdoor_gain.py]
        [--capture RESULTS_DIR] [--rows A B] [--gains-from-rows A B] [--truth-gain] [--field-error]
        [--save MAPS.npz]

Renders (or reads from ``--cache``) the ridge sunset of ``scripts/measure_outdoor_gain.py``
(seed 3, every nuisance, 14-bit Poisson-Gaussian noise on linear RGB), or with ``--capture`` reads
a workflow dataset's decoded frame store and rendered truth (``RESULTS_DIR/frames/timelapse.zarr``,
``RESULTS_DIR/capture/ground_truth.nc``: the DNG path), optionally keeps rows ``A:B`` of both
(``--rows``), runs the outdoor passes in process (photometry, edge tracking, arrival map; with
``--gains-from-rows`` the first pass's per-frame curves, ``gain``, ``gain_sky``, ``gain_source``
and ``cloud_shade``, are those of the first pass run on rows ``A:B`` alone; with ``--truth-gain``
the lit gain is the renderer's ``lit_gain`` and the cloud's shade field is recomputed from the
blocks' levels with it: what the arrival reaches when the lit gain is exact) and reports the
combined arrival error against the pixel-centre truth (class-3 pixels, median intervals:
median / p95 / beyond 5 (coverage), signed median), overall and, with the disc sun, by the
pixel's penumbra in the truth (``penumbra_start_time_s``, ``penumbra_end_time_s``, NaN outside
the record): whole penumbra inside the record, under way at the first frame, not ended by the
last frame; for the pixels under way at the first frame the arrival reasons and the ramp states;
the lit pixels under a cloud in the first frame (transmittance < 0.95), and the events by kind;
and, for every class-3 pixel, the error by ramp state and by the cloud's transmittance of the
pixel at its true arrival (the nearest frame; where the truth has the cloud), signed medians
included: where a median error comes from. With ``--field-error``, the first pass's cloud shade
field against the truth's transmittance (``cloud_attenuation``) averaged over each block: the
frames where a block is off by more than :data:`FIELD_OFF` and their worst blocks (the field is
relative to the reference: under a clouded reference it is not the truth's transmittance).
Also the CPU time (``time.process_time``, every thread) of each pass and of the step that times
descents under way at their start from the neighbours' lit-to-shadow ratio
(``outdoor.descent._neighbours_lit``, where the installed package has it) with the number of
pixels it reads.

Run it with ``PYTHONPATH`` on a source tree to measure that tree (before -> after of a change).
"""

import argparse
import os
import time

import numpy as np
import xarray as xr

import shadowcam.outdoor.descent as descent
from measure_outdoor_gain import add_render_arguments, load
from shadowcam.outdoor.accuracy import arrival_errors, map_to_truth_camera
from shadowcam.io.frame_store import open_frames
from shadowcam.outdoor.arrival import ARRIVAL_REASONS, EVENT_KINDS, arrival_map
from shadowcam.outdoor.edges import track_edges
from shadowcam.outdoor.normalise import cloud_shades
from shadowcam.outdoor.photometry import photometry_from_frames

#: options of this script that are not the render's (left out of the cache key)
OWN_OPTIONS = ("save", "capture", "rows", "gains_from_rows", "truth_gain", "field_error")
#: a block's field this far from the truth's mean transmittance over it is reported (``--field-error``)
FIELD_OFF = 0.08
#: bins of the cloud's transmittance at a pixel's true arrival
TRANSMITTANCE_BINS = (0.0, 0.6, 0.8, 0.95, 1.01)
#: the first pass's per-frame curves that ``--gains-from-rows`` takes from a band of rows
FRAME_CURVES = ("gain", "gain_sky", "gain_source", "cloud_shade")


class _StepClock:
    """Wraps a function: CPU seconds spent in it and the pixels it was given (finite ``shadow``)."""

    def __init__(self, function):
        self.function, self.seconds, self.pixels = function, 0.0, 0

    def __call__(self, *args, **kwargs):
        self.pixels += int(np.isfinite(kwargs["shadow"]).sum())
        start = time.process_time()
        try:
            return self.function(*args, **kwargs)
        finally:
            self.seconds += time.process_time() - start


def _line(errors):
    if not errors["n_evaluated"]:
        return "none"
    return (f"{errors['median_abs']:.3f} / {errors['p95_abs']:.2f} / {100 * errors['frac_over_5']:.2f} % "
            f"({100 * errors['coverage']:.1f} %), signed {errors['median_signed']:+.2f}")


def _counts(names, values):
    keys, counts = np.unique(values, return_counts=True)
    return ", ".join(f"{names.get(int(k), int(k))} {int(c)}" for k, c in zip(keys, counts))


def _nearest(values, shift_row, shift_col):
    """A label map of the first frame's grid in the truth camera's (nearest pixel)."""
    rows, cols = values.shape
    r = np.clip(np.rint(np.arange(rows) + shift_row).astype(int), 0, rows - 1)
    c = np.clip(np.rint(np.arange(cols) + shift_col).astype(int), 0, cols - 1)
    return values[np.ix_(r, c)]


def _rows(dataset, rows):
    return dataset if rows is None else dataset.isel(row=slice(*rows))


def _with_curves(photometry, source):
    """`photometry` with the per-frame curves (:data:`FRAME_CURVES`) of `source` (its cloud shade: a uniform field)."""
    out = photometry.copy()
    for name in FRAME_CURVES:
        if name in out.coords:
            out = out.assign_coords({name: source[name]})
        else:
            out[name] = source[name]
    if "shade_field" in out:  # the band's median cloud shade over the whole frame, as before the field
        shade = np.asarray(source["cloud_shade"].values, dtype=np.float32)[:, None, None]
        out["shade_field"] = out["shade_field"].dims, np.broadcast_to(shade, out["shade_field"].shape).copy()
    return out


def _with_truth_gain(photometry, truth):
    """`photometry` with the renderer's lit gain and the shade field recomputed from the blocks' levels with it."""
    out = photometry.assign_coords(gain=("time", truth["lit_gain"].values.astype(np.float64)))
    if "shade_levels" in out:
        shade, field = cloud_shades(out["gain_median"].values, out["gain"].values, out["gain_source"].values,
                                    out["shade_levels"].values, shadow_ratio=float(out.attrs["shadow_ratio"]))
        out["shade_field"] = out["shade_field"].dims, field
        out["cloud_shade"] = out["cloud_shade"].dims, shade
    return out


def _field_error(photometry, truth):
    """Print the frames whose shade field is off the truth's block-mean transmittance, worst blocks first."""
    field = photometry["shade_field"].values
    rows, cols = photometry["shade_rows"].values, photometry["shade_cols"].values
    attenuation = truth["cloud_attenuation"].values
    height, width = attenuation.shape[1:]
    row_edges = np.r_[0, 0.5 * (rows[1:] + rows[:-1]), height].astype(int)
    col_edges = np.r_[0, 0.5 * (cols[1:] + cols[:-1]), width].astype(int)
    means = np.add.reduceat(np.add.reduceat(attenuation, row_edges[:-1], axis=1), col_edges[:-1], axis=2)
    means /= np.outer(np.diff(row_edges), np.diff(col_edges))[None]
    error = field - means
    print(f"  shade field - truth's block mean ({field.shape[1]}x{field.shape[2]} blocks): "
          f"{np.min(error):+.3f} .. {np.max(error):+.3f}; frames with a block off by more than {FIELD_OFF}:")
    gain = photometry["gain"].values / truth["lit_gain"].values
    for k in np.flatnonzero((np.abs(error) > FIELD_OFF).any(axis=(1, 2))):
        worst = np.argsort(-np.abs(error[k]), axis=None)[:4]
        blocks = ", ".join(f"({i}, {j}) {field[k, i, j]:.2f} vs {means[k, i, j]:.2f}"
                           for i, j in zip(*np.unravel_index(worst, error[k].shape)))
        print(f"    frame {k}: gain / truth's {gain[k]:.3f}, source {int(photometry['gain_source'].values[k])}; {blocks}")


def main():
    parser = add_render_arguments(argparse.ArgumentParser(description=__doc__.splitlines()[0]))
    parser.add_argument("--save", default=None, help="write the maps (estimate, reason, state, truth) here")
    parser.add_argument("--capture", default=None,
                        help="a workflow dataset's results dir: its frame store and rendered truth, not a render")
    parser.add_argument("--rows", type=int, nargs=2, default=None, metavar=("A", "B"), help="keep rows A:B")
    parser.add_argument("--gains-from-rows", type=int, nargs=2, default=None, metavar=("A", "B"),
                        help="per-frame gains and cloud shade from the first pass on rows A:B alone")
    parser.add_argument("--truth-gain", action="store_true",
                        help="the renderer's lit gain in place of the first pass's (the shade field recomputed)")
    parser.add_argument("--field-error", action="store_true",
                        help="the shade field against the truth's transmittance averaged over each block")
    args = parser.parse_args()
    render_args = argparse.Namespace(**{k: v for k, v in vars(args).items() if k not in OWN_OPTIONS})
    if args.capture:
        store = open_frames(os.path.join(args.capture, "frames", "timelapse.zarr"))
        truth = xr.load_dataset(os.path.join(args.capture, "capture", "ground_truth.nc"))
        render_args = argparse.Namespace(capture=args.capture)
    else:
        store, truth = load(render_args)
    store, truth = _rows(store, args.rows), _rows(truth, args.rows)
    clock = None
    if hasattr(descent, "_neighbours_lit"):
        clock = descent._neighbours_lit = _StepClock(descent._neighbours_lit)
    cpu = [time.process_time()]
    wall = time.perf_counter()
    photometry = photometry_from_frames(store)
    if args.gains_from_rows:
        photometry = _with_curves(photometry, photometry_from_frames(_rows(store, args.gains_from_rows)))
    if args.truth_gain:
        photometry = _with_truth_gain(photometry, truth)
    cpu.append(time.process_time())
    edges = track_edges(store, photometry)
    cpu.append(time.process_time())
    arrival = arrival_map(photometry, edges)
    cpu.append(time.process_time())
    wall = time.perf_counter() - wall
    shift = float(truth["shake_dy_px"][0]), float(truth["shake_dx_px"][0])
    estimate = map_to_truth_camera(arrival["arrival_time_s"].values, shift_row=shift[0], shift_col=shift[1])
    reason = _nearest(arrival["reason"].values, *shift)
    state = _nearest(edges["ramp_state"].values, *shift)
    times = truth["times_s"].values
    interval = float(np.median(np.diff(times)))
    true_arrival = truth["arrival_time_s"].values
    class3 = truth["shadow_class"].values == 3
    height, width = class3.shape
    print(f"{vars(render_args)} rows {args.rows} gains from rows {args.gains_from_rows} truth gain {args.truth_gain} "
          f"({os.path.dirname(os.path.dirname(descent.__file__))})")
    print(f"  {height}x{width} px, {times.size} frames; CPU s photometry {cpu[1] - cpu[0]:.2f}, edges "
          f"{cpu[2] - cpu[1]:.2f}, arrival {cpu[3] - cpu[2]:.2f}; wall {wall:.1f} s")
    if clock is not None:
        print(f"  neighbours' lit level: {clock.pixels} px, {clock.seconds:.3f} s CPU "
              f"({1e6 * clock.seconds / max(clock.pixels, 1):.1f} us per pixel read, "
              f"{1e6 * clock.seconds / (height * width):.2f} us per pixel of the frame)")
    print(f"  class 3 ({class3.sum()} px): "
          f"{_line(arrival_errors(estimate, true_arrival, evaluate=class3, interval_s=interval))}")
    if "cloud_attenuation" in truth:
        # the lit pixels a cloud shades in the first frame (the first pass's reference)
        clouded = class3 & truth["lit_center"].values[0].astype(bool) & (truth["cloud_attenuation"].values[0] < 0.95)
        print(f"  under a cloud in the first frame ({clouded.sum()} px): "
              f"{_line(arrival_errors(estimate, true_arrival, evaluate=clouded, interval_s=interval))}")
    for code, name in descent.RAMP_STATES.items():
        chosen = class3 & (state == code) & np.isfinite(estimate)
        if chosen.any():
            print(f"  class 3 in state {name} ({chosen.sum()} px): "
                  f"{_line(arrival_errors(estimate, true_arrival, evaluate=chosen, interval_s=interval))}")
    if "cloud_attenuation" in truth:
        # the cloud's transmittance of each pixel at its true arrival (nearest frame)
        frame = np.clip(np.rint(np.nan_to_num(truth["arrival_frame"].values)).astype(int), 0, times.size - 1)
        at_arrival = np.take_along_axis(truth["cloud_attenuation"].values, frame[None], axis=0)[0]
        for low, high in zip(TRANSMITTANCE_BINS[:-1], TRANSMITTANCE_BINS[1:]):
            chosen = class3 & (at_arrival >= low) & (at_arrival < high)
            print(f"  class 3 under a transmittance in [{low}, {min(high, 1.0)}{')' if high < 1 else ']'} at the arrival "
                  f"({chosen.sum()} px): "
                  f"{_line(arrival_errors(estimate, true_arrival, evaluate=chosen, interval_s=interval))}")
    if "event_kind" in arrival:
        print(f"  events: {_counts(EVENT_KINDS, arrival['event_kind'].values)}")
    start = truth["penumbra_start_time_s"].values if "penumbra_start_time_s" in truth else None
    if start is not None and np.isfinite(start).any():
        end = truth["penumbra_end_time_s"].values
        # the truth's penumbra times are searched within the record: NaN = before its start / after its end
        begun, ended = np.isfinite(start), np.isfinite(end)
        groups = {"whole penumbra in the record": class3 & begun & ended,
                  "under way at the first frame": class3 & ~begun,
                  "not ended by the last frame": class3 & begun & ~ended}
        error = np.abs(estimate - true_arrival) / interval
        with np.errstate(invalid="ignore"):
            beyond = class3 & (error > 5)
        for name, group in groups.items():
            print(f"  {name} ({group.sum()} px, {100 * group.sum() / class3.sum():.0f} %): "
                  f"{_line(arrival_errors(estimate, true_arrival, evaluate=group, interval_s=interval))}; "
                  f"{100 * (beyond & group).sum() / max(beyond.sum(), 1):.0f} % of those beyond 5")
        group = groups["under way at the first frame"]
        print(f"    timed {int(np.isfinite(estimate[group]).sum())} of {int(group.sum())}; reasons: "
              f"{_counts(ARRIVAL_REASONS, reason[group])}")
        print(f"    ramp states: {_counts(descent.RAMP_STATES, state[group])}")
        for code, name in descent.RAMP_STATES.items():
            chosen = group & (state == code) & np.isfinite(estimate)
            if chosen.any():
                print(f"    timed in state {name} ({chosen.sum()} px): "
                      f"{_line(arrival_errors(estimate, true_arrival, evaluate=chosen, interval_s=interval))}")
    if args.field_error and "cloud_attenuation" in truth and "shade_field" in photometry:
        _field_error(photometry, truth)
    if args.save:
        np.savez_compressed(args.save, estimate=estimate, reason=reason, state=state, truth=true_arrival,
                            class3=class3, times=times)


if __name__ == "__main__":
    main()
