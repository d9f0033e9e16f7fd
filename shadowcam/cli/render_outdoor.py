"""Outdoor branch of ``shadowcam render``: write a synthetic sunset time-lapse capture.

Called by :mod:`shadowcam.cli.render` when the manifest's ``kind`` is ``outdoor`` or the
scene is an outdoor scene (``ridge``). The output directory receives::

    frames/000000.dng ...   RGGB Bayer DNG (or 16-bit linear TIFF), one per kept frame, with
                            DateTimeOriginal + SubsecTimeOriginal (ms) and ExposureTime
                            (base exposure x 2**ae_ev: the auto-exposure step, not the flicker)
    timestamps.json         times_s, files, nominal_index, dropped_nominal_indices,
                            intervals_s, exposure_time_s, capture_start
    ground_truth.nc         shadowcam.synthetic.outdoor.capture ground truth (+ sensor attrs, provenance)
    capture.json            capture description: kind outdoor, light distant, sweep timelapse,
                            timing from the timestamps.json sidecar, checksums, ground_truth

Offers
------
OUTDOOR_OPTIONS : keys of the ``synthetic.outdoor`` block and their defaults.
accuracy_condition : ``clean`` or ``nuisances`` (which accuracy targets apply) from the options.
outdoor_options : merge the ``outdoor`` block over the defaults (validated).
render_outdoor_capture_dir : render and write a capture.
"""

import datetime
import json
import logging
import time

from shadowcam import __version__
from shadowcam.io.provenance import file_sha256

log = logging.getLogger(__name__)

#: ``synthetic.outdoor`` keys -> defaults (ephemeris of dev_ridge, every nuisance on)
OUTDOOR_OPTIONS = {
    "latitude_deg": 35.0, "declination_deg": -18.0,
    "start_elevation_deg": 20.0, "end_elevation_deg": 1.5,
    "auto_exposure": True, "shake_px": 1.0, "cloud": True,
    "irregular_timing": True, "dropped_frames": 2,
    "base_exposure_s": 0.004,
}
#: noise seeds are ``[seed, TIMELAPSE_SWEEP_INDEX, frame]``
TIMELAPSE_SWEEP_INDEX = 5
#: calendar date written with the apparent solar time of each frame
CAPTURE_DATE = datetime.date(2025, 1, 21)


def accuracy_condition(noise, outdoor):
    """Accuracy-target condition of a rendered time-lapse: ``clean`` or ``nuisances``.

    A capture is clean when no nuisance of the issue's list is on: sensor noise,
    auto-exposure steps, shake, cloud, irregular intervals, dropped frames.
    """
    nuisances = (noise, outdoor["auto_exposure"], outdoor["shake_px"] > 0, outdoor["cloud"],
                 outdoor["irregular_timing"], outdoor["dropped_frames"] > 0)
    return "nuisances" if any(nuisances) else "clean"


def outdoor_options(block):
    """Return :data:`OUTDOOR_OPTIONS` updated by `block` (the manifest's ``outdoor`` mapping)."""
    block = dict(block or {})
    unknown = set(block) - set(OUTDOOR_OPTIONS)
    if unknown:
        raise ValueError(f"synthetic.outdoor: unknown key(s) {sorted(unknown)}; "
                         f"known: {sorted(OUTDOOR_OPTIONS)}")
    return dict(OUTDOOR_OPTIONS, **block)


def _capture_start(hour_angle0_deg):
    seconds = round((12.0 + hour_angle0_deg / 15.0) * 3600.0)
    return datetime.datetime.combine(CAPTURE_DATE, datetime.time()) + datetime.timedelta(
        seconds=seconds)


def render_outdoor_capture_dir(options, out_dir):
    """Render the outdoor capture described by `options` into `out_dir`.

    Parameters
    ----------
    options : dict
        ``shadowcam.cli.render.resolve_options`` result; ``options["outdoor"]`` is the
        manifest's ``synthetic.outdoor`` block (may be None).
    out_dir : Path

    Returns
    -------
    Path
    """
    import numpy as np

    from shadowcam.cli.render import DEFAULTS, _write_frame, staging_dir, write_ground_truth
    from shadowcam.synthetic.outdoor.capture import NUISANCES, edge_speed, render_outdoor_capture
    from shadowcam.synthetic.outdoor.render import make_outdoor_scene
    from shadowcam.synthetic.sensor import SensorModel, electrons_per_unit_radiance

    started = time.perf_counter()
    outdoor = outdoor_options(options.get("outdoor"))
    seed = int(options["seed"])
    scene = make_outdoor_scene(
        options["scene"], seed=seed, height=options["height"], width=options["width"],
        latitude_deg=outdoor["latitude_deg"], declination_deg=outdoor["declination_deg"],
        start_elevation_deg=outdoor["start_elevation_deg"],
        end_elevation_deg=outdoor["end_elevation_deg"])
    capture = render_outdoor_capture(
        scene, frames=int(options["frames"]), supersample=int(options["supersample"]),
        seed=seed, **{k: outdoor[k] for k in NUISANCES})
    gt = capture.ground_truth
    log.info("scene, frames and ground truth rendered in %.2f s", time.perf_counter() - started)
    sensor = SensorModel(bit_depth=options["bit_depth"])
    scale = electrons_per_unit_radiance(gt["reference_radiance"].values, sensor=sensor,
                           target_fraction=options["exposure"])
    ext = options["format"]
    times = capture.times_s
    ae_ev = gt["ae_ev"].values
    exposure_s = np.round(outdoor["base_exposure_s"] * 2.0 ** ae_ev, 6)  # as written (1 us)
    start = _capture_start(scene.sun.hour_angle0_deg)

    with staging_dir(out_dir) as tmp:
        (tmp / "frames").mkdir()
        written = []
        for k, image in enumerate(capture.frames):
            rel = f"frames/{k:06d}.{ext}"
            when = start + datetime.timedelta(milliseconds=int(round(times[k] * 1000.0)))
            _write_frame(tmp / rel, image, options=options, sensor=sensor, scale=scale,
                         seed=[seed, TIMELAPSE_SWEEP_INDEX, k], when=when,
                         exposure_time=float(exposure_s[k]))
            written.append(rel)
        side = {
            "units": "seconds since the first frame",
            "times_s": [float(t) for t in times],
            "files": written,
            "nominal_index": gt["nominal_index"].values.tolist(),
            "dropped_nominal_indices": json.loads(gt.attrs["dropped_nominal_indices"]),
            "intervals_s": np.diff(times).round(3).tolist(),
            "exposure_time_s": [float(e) for e in exposure_s],
            "capture_start": start.isoformat(),
            "clock": "local apparent solar time",
        }
        with open(tmp / "timestamps.json", "w") as handle:
            json.dump(side, handle, indent=1)
            handle.write("\n")
        written.append("timestamps.json")
        checksums = {rel: file_sha256(tmp / rel) for rel in written}
        config = {k: options[k] for k in DEFAULTS} | {"outdoor": outdoor}
        fast, frames_per_px = edge_speed(gt["arrival_frame"].values, gt["shadow_class"].values)
        gt = gt.assign(
            exposure_time_s=("time", exposure_s,
                             {"units": "s", "long_name": "ExposureTime metadata"}),
            dn_per_radiance=((), scale * sensor.gain,
                             {"units": "DN", "long_name": "DN per unit radiance at gain 1"}))
        write_ground_truth(
            tmp, gt, sensor=sensor, scale=scale, config=config, checksums=checksums,
            frame_format=ext, base_exposure_s=outdoor["base_exposure_s"],
            edge_fast_pair_fraction=fast, edge_median_frames_per_px=frames_per_px,
            image_formation="L_k = sun + sky + skydome (cloud on the sun term); "
                            "E_k = exposure_gain_k * shift_k(L_k); "
                            "DN = clip(round(black + Poisson(scale E_k) + N(0, read^2)))"
                            " on the RGGB mosaic",
            noise_seed=f"numpy.random.default_rng([seed, {TIMELAPSE_SWEEP_INDEX}, frame])")
        description = {
            "name": options["name"],
            "kind": "outdoor",
            "description": options["description"],
            "light": "distant",
            "root": ".",
            "sweeps": {"timelapse": {"files": f"frames/*.{ext}"}},
            "timing": {"source": "sidecar", "file": "timestamps.json", "key": "times_s"},
            "checksums": checksums,
            "ground_truth": {"format": "shadowcam_outdoor_nc", "file": "ground_truth.nc",
                             "noise": accuracy_condition(options["noise"], outdoor)},
            "provenance": (f"rendered by shadowcam {__version__} 'shadowcam render' (scene "
                           f"{options['scene']}, seed {seed}, {options['height']}x"
                           f"{options['width']}, {len(times)} frames, {ext} "
                           f"{options['bit_depth']}-bit, noise {options['noise']}, outdoor "
                           f"{json.dumps(outdoor, sort_keys=True)}); deterministic"),
            "licence": "CC0-1.0",
        }
        with open(tmp / "capture.json", "w") as handle:
            json.dump(description, handle, indent=2)
            handle.write("\n")
    log.info("class counts %s; edge crosses %.1f%% of vertical class-3 pixel steps in under a "
             "frame (median %.2f frames per pixel)", gt.attrs["class_counts"], 100 * fast,
             frames_per_px)
    log.info("capture %s written to %s in %.2f s", options["name"], out_dir,
             time.perf_counter() - started)
    return out_dir
