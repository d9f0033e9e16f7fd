"""Write a rendered synthetic capture as a capture directory, like a camera would.

A capture directory holds the raw frames (RGGB Bayer DNG or 16-bit linear TIFF),
``ground_truth.nc`` (the render's truth, sensor attrs, provenance) and
``capture.json`` (the capture description in the manifest structure, with the
checksum of every file). Lab captures hold ``frames_u/000000.dng ...``,
``frames_v/``, with calibration ``cal_u/``, ``cal_v/``, and ``reference.dng``;
outdoor time-lapses hold ``frames/`` and a ``timestamps.json`` sidecar. The
directory is written beside its target and renamed into place at the end, so a
killed run leaves no half capture.

Offers
------
CAPTURE_START : capture start time of lab captures (frame k of a sweep is k seconds later).
write_frame : simulate the sensor on a radiance image and write one raw frame.
write_ground_truth : ground truth + sensor attrs + provenance -> ``ground_truth.nc``.
write_capture : render and write the capture of :func:`capture_options` options (lab or outdoor).
write_lab_capture : render and write a lab capture (two sweeps, reference, optional calibration).
write_outdoor_capture : render and write an outdoor sunset time-lapse.
"""

import datetime
import json
import logging
import time
from pathlib import Path

import numpy as np

from shadowcam import __version__
from shadowcam._shared.atomic import atomic_directory
from shadowcam._shared.progress import Progress
from shadowcam.io.datasets import write_dataset
from shadowcam.io.provenance import file_sha256
from shadowcam.synthetic.capture_options import (
    DEFAULTS,
    OPTIONAL_KEYS,
    accuracy_condition,
    lab_scene_description,
    outdoor_options,
)

log = logging.getLogger(__name__)

#: capture start time written into the lab DNGs; frame k of every sweep is k seconds later
CAPTURE_START = datetime.datetime(2024, 1, 1, 0, 0, 0)
#: noise seed index of lab sweeps other than u, v, cal_u, cal_v: this plus the sweep's position
EXTRA_SWEEP_INDEX = 10
#: outdoor noise seeds are ``[seed, TIMELAPSE_SWEEP_INDEX, frame]``
TIMELAPSE_SWEEP_INDEX = 5
#: calendar date written with the apparent solar time of each outdoor frame
CAPTURE_DATE = datetime.date(2025, 1, 21)


def write_frame(path, radiance, *, frame_format, noise, sensor, scale, seed, when,
                exposure_time=None, compression="none"):
    """Simulate the sensor on `radiance` and write one frame to `path`.

    Parameters
    ----------
    path : Path
    radiance : ndarray, shape (H, W, 3)
        Linear scene radiance.
    frame_format : {"dng", "tiff"}
        ``dng``: the raw RGGB mosaic with capture time; ``tiff``: linear 16-bit RGB.
    noise : bool
        Shot and read noise on (else mean DN, rounded).
    sensor : shadowcam.synthetic.sensor.SensorModel
    scale : float
        Electrons per unit radiance.
    seed : sequence of int
        Noise seed.
    when : datetime.datetime
        DateTimeOriginal of a DNG.
    exposure_time : float, optional
        ExposureTime (s) of a DNG.
    compression : {"none", "ljpeg"}, optional
        DNG compression (lossless JPEG as cameras write, or none).
    """
    from shadowcam.io.raw_writer import write_dng, write_tiff16
    from shadowcam.synthetic.sensor import raw_to_linear, simulate_raw

    if frame_format not in ("dng", "tiff"):
        raise ValueError(f"frame_format: must be 'dng' or 'tiff', got {frame_format!r}")
    if frame_format == "dng":
        raw = simulate_raw(radiance, sensor=sensor, scale=scale, seed=seed, noise=noise, mosaic=True)
        write_dng(path, raw, bit_depth=sensor.bit_depth, black_level=sensor.black_level,
                  capture_time=when, exposure_time=exposure_time, compression=compression)
    else:
        dn = simulate_raw(radiance, sensor=sensor, scale=scale, seed=seed, noise=noise, mosaic=False)
        linear = raw_to_linear(dn, sensor=sensor)
        write_tiff16(path, np.clip(np.rint(linear * 65535.0), 0, 65535).astype(np.uint16))


def _frame_writer(options, sensor, scale):
    def write(path, radiance, **kwargs):
        write_frame(path, radiance, frame_format=options["format"], noise=options["noise"],
                    sensor=sensor, scale=scale, **kwargs)
    return write


def write_ground_truth(folder, gt, *, sensor, scale, config, checksums, **attrs):
    """Write `gt` with the sensor's attrs, `attrs` and provenance as ``folder/ground_truth.nc``.

    Its checksum is added to `checksums` (which, before, lists the capture's frames
    and becomes the file's ``input_checksums``).
    """
    gt = gt.assign_attrs(
        electrons_per_unit_radiance=scale, black_level=sensor.black_level,
        white_level=sensor.white_level, read_noise_dn=sensor.read_noise,
        gain_dn_per_electron=sensor.gain, **attrs)
    write_dataset(gt, folder / "ground_truth.nc", config=config, checksums=checksums, step="render")
    checksums["ground_truth.nc"] = file_sha256(folder / "ground_truth.nc")


def _write_json(path, document, *, indent):
    with open(path, "w") as handle:
        json.dump(document, handle, indent=indent)
        handle.write("\n")


def write_capture(options, out_dir):
    """Render the capture described by `options` and write it to `out_dir`.

    Parameters
    ----------
    options : dict
        :func:`shadowcam.synthetic.capture_options.capture_options` result; ``kind``
        chooses :func:`write_outdoor_capture` or :func:`write_lab_capture`.
    out_dir : str or Path

    Returns
    -------
    Path
    """
    if options.get("kind") not in ("lab", "outdoor"):
        raise ValueError(f"options['kind']: must be 'lab' or 'outdoor', got {options.get('kind')!r}")
    writer = write_outdoor_capture if options["kind"] == "outdoor" else write_lab_capture
    return writer(options, Path(out_dir))


def _sweep_geometry(options, scene, name):
    """capture.json keys of a lab sweep: axis (u, v) and, with a camera block, its geometry."""
    base = name.removeprefix("cal_")
    out = {"axis": base} if base in ("u", "v") else {}
    block = options.get("camera")
    if not block or name.startswith("cal_"):
        return out
    entry = next(e for e in block["sweeps"] if e["name"] == name)
    out.update(direction_deg=float(entry.get("direction_deg", 0.0)),
               speed=float(entry.get("speed", 1.0)))
    if any(e.get("light_offset") is not None for e in block["sweeps"]):
        light = scene.sweeps[name].light or scene.light
        out["light_position"] = [float(x) for x in light.position]
    return out


def write_lab_capture(options, out_dir):
    """Render the lab capture described by `options` into `out_dir` (see :func:`write_capture`)."""
    from shadowcam.synthetic.lab.render import SWEEP_INDEX, footprint_variance, prepare_capture
    from shadowcam.synthetic.lab.scenes import scene_from_description
    from shadowcam.synthetic.sensor import SensorModel, electrons_per_unit_radiance

    started = time.perf_counter()
    try:
        scene = scene_from_description(lab_scene_description(options))
    except ValueError as err:
        if not options.get("camera"):
            raise
        text = str(err).replace("specs[", "sweeps[")
        raise ValueError(f"capture {options['name']!r}: key 'synthetic.camera': {text}") from None
    renderer = prepare_capture(scene, supersample=options["supersample"],
                               calibration=options["calibration"])
    log.info("static rays cast in %.2f s", time.perf_counter() - started)
    sensor = SensorModel(bit_depth=options["bit_depth"])
    scale = electrons_per_unit_radiance(renderer.reference, sensor=sensor,
                           target_fraction=options["exposure"])
    write = _frame_writer(options, sensor, scale)
    ext = options["format"]
    seed = int(options["seed"])

    with atomic_directory(out_dir) as tmp:
        written = []
        ref_name = f"reference.{ext}"
        write(tmp / ref_name, renderer.reference, seed=[seed, SWEEP_INDEX["reference"], 0],
              when=CAPTURE_START)
        written.append(ref_name)
        sweeps = {}
        for index, name in enumerate(renderer.sweep_names):
            folder = f"frames_{name}" if name in ("u", "v") else name
            noise_index = SWEEP_INDEX.get(name, EXTRA_SWEEP_INDEX + index)
            (tmp / folder).mkdir()
            frames = renderer.frames(name, shutter=float(options.get("shutter", 0.0)))
            n = len(frames)
            progress = Progress(n, f"render sweep {name}")
            for k in range(n):
                rel = f"{folder}/{k:06d}.{ext}"
                write(tmp / rel, frames[k], seed=[seed, noise_index, k],
                      when=CAPTURE_START + datetime.timedelta(seconds=k))
                written.append(rel)
                progress.update(k + 1)
            sweeps[name] = {"files": f"{folder}/*.{ext}", **_sweep_geometry(options, scene, name)}
            del frames
        checksums = {rel: file_sha256(tmp / rel) for rel in written}
        config = {k: options[k] for k in DEFAULTS}
        config.update({k: options[k] for k in OPTIONAL_KEYS if options.get(k) is not None})
        write_ground_truth(
            tmp, renderer.ground_truth, sensor=sensor, scale=scale, config=config,
            checksums=checksums, frame_format=ext,
            noise_seed="numpy.random.default_rng([seed, sweep_index, frame]); "
                       "sweep_index u=0 v=1 cal_u=2 cal_v=3 reference=9")
        capture = {
            "name": options["name"],
            "kind": "lab",
            "description": options["description"],
            "light": options["light"],
            "root": ".",
            "sweeps": sweeps,
            "reference": ref_name,
            "timing": {"source": "rate", "rate_hz": 1.0},
            "checksums": checksums,
            "dual": {"width": scene.mask.n_u, "height": scene.mask.n_v},
            "sensor": {"footprint_variance_px2": footprint_variance(options["supersample"])},
            "ground_truth": {"format": "shadowcam_nc", "file": "ground_truth.nc",
                             "noise": "raw12" if options["noise"] else "noise_free"},
            "provenance": (f"rendered by shadowcam {__version__} 'shadowcam render' "
                           f"(scene {options['scene']}, seed {seed}, "
                           f"{options['height']}x{options['width']}, "
                           f"{options['frames']} frames per sweep, {ext} "
                           f"{options['bit_depth']}-bit, noise {options['noise']}); "
                           "deterministic"),
            "licence": "CC0-1.0",
        }
        if renderer.homography is not None:
            capture["calibration_plane"] = {"homography": renderer.homography.tolist()}
        _write_json(tmp / "capture.json", capture, indent=2)
    log.info("capture %s written to %s in %.2f s", options["name"], out_dir,
             time.perf_counter() - started)
    return out_dir


def _capture_start(hour_angle0_deg):
    seconds = round((12.0 + hour_angle0_deg / 15.0) * 3600.0)
    return datetime.datetime.combine(CAPTURE_DATE, datetime.time()) + datetime.timedelta(
        seconds=seconds)


def write_outdoor_capture(options, out_dir):
    """Render the outdoor time-lapse described by `options` into `out_dir`.

    ``options["outdoor"]`` is the manifest's ``synthetic.outdoor`` block (may be
    None). `out_dir` receives ``frames/000000.dng ...`` (DNGs with
    DateTimeOriginal + SubsecTimeOriginal (ms) and ExposureTime: base exposure
    x 2**ae_ev, the auto-exposure step, not the flicker), ``timestamps.json``
    (times_s, files, nominal_index, dropped_nominal_indices, intervals_s,
    exposure_time_s, capture_start), ``ground_truth.nc`` and ``capture.json``
    (kind outdoor, light distant, sweep timelapse, timing from the sidecar).
    """
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
        end_elevation_deg=outdoor["end_elevation_deg"], window=outdoor["window"])
    capture = render_outdoor_capture(
        scene, frames=int(options["frames"]), supersample=int(options["supersample"]),
        seed=seed, sun_diameter_deg=outdoor["sun_diameter_deg"],
        **{k: outdoor[k] for k in NUISANCES})
    gt = capture.ground_truth
    log.info("scene, frames and ground truth rendered in %.2f s", time.perf_counter() - started)
    sensor = SensorModel(bit_depth=options["bit_depth"])
    scale = electrons_per_unit_radiance(gt["reference_radiance"].values, sensor=sensor,
                           target_fraction=options["exposure"])
    write = _frame_writer(options, sensor, scale)
    ext = options["format"]
    times = capture.times_s
    exposure_s = np.round(outdoor["base_exposure_s"] * 2.0 ** gt["ae_ev"].values, 6)  # 1 us
    start = _capture_start(scene.sun.hour_angle0_deg)

    with atomic_directory(out_dir) as tmp:
        (tmp / "frames").mkdir()
        written = []
        progress = Progress(len(capture.frames), "write time-lapse frames")
        for k, image in enumerate(capture.frames):
            rel = f"frames/{k:06d}.{ext}"
            when = start + datetime.timedelta(milliseconds=int(round(times[k] * 1000.0)))
            write(tmp / rel, image, seed=[seed, TIMELAPSE_SWEEP_INDEX, k], when=when,
                  compression=outdoor["dng_compression"],
                  exposure_time=float(exposure_s[k]))
            written.append(rel)
            progress.update(k + 1)
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
        _write_json(tmp / "timestamps.json", side, indent=1)
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
        _write_json(tmp / "capture.json", description, indent=2)
    log.info("class counts %s; edge crosses %.1f%% of vertical class-3 pixel steps in under a "
             "frame (median %.2f frames per pixel)", gt.attrs["class_counts"], 100 * fast,
             frames_per_px)
    log.info("capture %s written to %s in %.2f s", options["name"], out_dir,
             time.perf_counter() - started)
    return out_dir
