"""A whole synthetic outdoor time-lapse: noise-free frames with nuisances, and its ground truth.

Image formation (as dev_ridge, README 2.4, plus an optional cloud shadow)::

    L_k  = frame_radiance(t_k)                       (sun + fading sky + sky dome; cloud on sun)
    E_k  = exposure_gain_k * shift_k(L_k)             (what reaches the sensor, in radiance units)

The sensor (:mod:`shadowcam.synthetic.sensor`: Poisson-Gaussian noise, RGGB mosaic) and the files are
the caller's business (``shadowcam render``).

Offers
------
NUISANCES : switch -> default (auto_exposure, shake_px, cloud, irregular_timing, dropped_frames).
OutdoorCapture : times, per-frame records, noise-free sensor-plane frames ``E_k`` and the
    ground-truth Dataset.
render_outdoor_capture : render a capture of an :class:`~shadowcam.synthetic.outdoor.render.OutdoorScene`.
noisy_frame_store : a capture's frames through the sensor's noise, as an in-memory frame store.
edge_speed : fraction of vertically adjacent class-3 pixel pairs the edge crosses in under a
    frame (edge faster than 1 px / frame there).
"""

import json
import logging
from dataclasses import dataclass

import numpy as np

from shadowcam._shared.progress import Progress
from shadowcam._shared.validation import check_in_interval
from shadowcam.io.frame_times import time_to_frame
from shadowcam.synthetic.outdoor import nuisance as nz
from shadowcam.synthetic.outdoor import truth as gt
from shadowcam.synthetic.outdoor.clouds import CLOUD_SCENARIOS, cloud_shadows
from shadowcam.synthetic.outdoor.render import (frame_radiance, sample_grid, sky_colour, sun_lit_fraction,
                                                trace_samples)
from shadowcam.synthetic.outdoor.sun import elevation_azimuth, sun_colour

log = logging.getLogger(__name__)

#: nuisance switches and their defaults (all on)
NUISANCES = {"auto_exposure": True, "shake_px": 1.0, "cloud": True, "irregular_timing": True,
             "dropped_frames": 2}


@dataclass(frozen=True, eq=False)
class OutdoorCapture:
    """Rendered outdoor capture (noise-free, before the sensor).

    Attributes
    ----------
    frames : (K, rows, cols, 3) float32 ndarray
        ``E_k``: gain x shifted radiance (radiance units).
    ground_truth : xarray.Dataset
        Variables of :data:`shadowcam.synthetic.outdoor.truth.DEFINITIONS` and more (dims ``time``,
        ``row``, ``col``, ``channel``, ``subpixel``).
    """

    frames: np.ndarray
    ground_truth: object

    @property
    def times_s(self):
        """(K,) frame times, seconds since frame 0."""
        return self.ground_truth["times_s"].values


def _cloud_record(spec):
    model = ("1 - depth exp(-|p_xy - c(t)|^2 / (2 sigma^2))" if spec["rim_m"] is None
             else "1 - depth / (1 + exp((|p_xy - c(t)| - sigma) / rim))")
    record = {"model": model, "depth": spec["depth"], "sigma_m": spec["sigma_m"],
              "start_xy": np.asarray(spec["start_xy"]).tolist(),
              "velocity_xy_m_per_s": np.asarray(spec["velocity_xy"]).tolist()}
    return record if spec["rim_m"] is None else record | {"rim_m": spec["rim_m"]}


def _pixel_mean(values, shape, s2):
    return values.reshape(shape[0], shape[1], s2, *values.shape[1:]).mean(axis=2)


def render_outdoor_capture(scene, *, frames, supersample=3, seed=0, sun_diameter_deg=0.0,
                           **nuisances):
    """Render the frames and the ground truth of a sunset time-lapse.

    Parameters
    ----------
    scene : shadowcam.synthetic.outdoor.render.OutdoorScene
    frames : int, keyword-only
        Number of kept frames.
    supersample : int, keyword-only
        Samples per pixel side (the ``subpixel`` GT uses the same samples).
    seed : int, keyword-only
        Seed of the nuisances.
    sun_diameter_deg : float, keyword-only
        0: a point sun (hard shadow edges); the real sun is
        :data:`shadowcam.synthetic.outdoor.render.SUN_DIAMETER_DEG` across and casts a
        penumbra (:func:`shadowcam.synthetic.outdoor.render.sun_lit_fraction`). Arrival times
        are those of the disc's centre; the disc adds ``penumbra_start_time_s`` and
        ``penumbra_end_time_s``.
    **nuisances
        Keys of :data:`NUISANCES`. ``cloud``: False, True (the ``"drifting"`` cloud) or a
        scenario of :data:`shadowcam.synthetic.outdoor.clouds.CLOUD_SCENARIOS`.

    Returns
    -------
    OutdoorCapture
    """
    import xarray as xr

    unknown = set(nuisances) - set(NUISANCES)
    if unknown:
        raise ValueError(f"nuisances: unknown switch(es) {sorted(unknown)}; known: {sorted(NUISANCES)}")
    opts = dict(NUISANCES, **nuisances)
    cloud = opts["cloud"]
    if not (isinstance(cloud, bool) or cloud in CLOUD_SCENARIOS):
        raise ValueError(f"cloud: must be true, false or one of {list(CLOUD_SCENARIOS)}; got {cloud!r}")
    if int(supersample) < 1:
        raise ValueError(f"supersample must be >= 1; got {supersample}")
    check_in_interval(sun_diameter_deg, "sun_diameter_deg", 0.0, 1.0, closed="both")
    rows, cols = scene.camera.height, scene.camera.width
    s = int(supersample)
    s2 = s * s

    times, nominal, dropped = nz.capture_times(
        scene.duration_s, frames, seed=seed, irregular=bool(opts["irregular_timing"]),
        dropped=int(opts["dropped_frames"]))
    log.info("outdoor render: tracing the terrain and its horizon for %dx%d pixels x %d samples",
             rows, cols, s2)
    samples = trace_samples(scene, *sample_grid(rows, cols, s))
    centres = trace_samples(scene, *sample_grid(rows, cols))

    # ground truth: pixel centres and sub-pixel samples
    log.info("outdoor render: ground-truth shadow arrival times over %d frames", len(times))
    t_centre, lit_centre, first = gt.arrival_times(centres, scene.sun, times)
    t_sub, lit_sub, _ = gt.arrival_times(samples, scene.sun, times)
    classes = gt.classify(lit_centre, first, centres.sky)
    cls = classes["shadow_class"]
    arrival = np.where(cls == 3, t_centre, np.nan)
    T_img = t_centre.reshape(rows, cols)
    penumbra = {}
    if sun_diameter_deg > 0:
        radius = np.radians(0.5 * sun_diameter_deg)
        for key, offset, keep in (("penumbra_start_time_s", radius, cls == 3),
                                  ("penumbra_end_time_s", -radius, cls >= 2)):
            t_edge = gt.arrival_times(centres, scene.sun, times, offset_rad=offset)[0]
            penumbra[key] = np.where(keep & np.isfinite(t_edge), t_edge, np.nan)
    sky_img = centres.sky.reshape(rows, cols)

    # frames
    cloud_on = cloud is not False
    seen = ~centres.sky
    clouds = cloud_shadows("drifting" if cloud in (True, False) else cloud, terrain=scene.terrain,
                           duration_s=scene.duration_s, points_xy=centres.position[seen, :2],
                           arrival_s=t_centre[seen], times_s=times, seed=seed)
    # without a cloud the record still holds where the drifting one would have been
    cloud_attrs = {"enabled": cloud_on, **_cloud_record(clouds[0])}
    if cloud not in (True, False):
        cloud_attrs.update(scenario=cloud, clouds=[_cloud_record(spec) for spec in clouds])
    if not cloud_on:
        clouds = []
    hit = ~samples.sky
    radiance, clean, cloud_att, sun_seen = [], [], [], []
    progress = Progress(len(times), "outdoor render: frames")
    for k, t in enumerate(times):
        trans = np.ones(len(samples.sky))
        for spec in clouds:
            trans[hit] *= nz.cloud_transmittance(samples.position[hit, :2], t, **spec)
        lit = (lit_sub[k] if sun_diameter_deg == 0 else
               sun_lit_fraction(samples, scene.sun, t, diameter_deg=sun_diameter_deg))
        L, L_clear = frame_radiance(samples, scene, t, shape=(rows, cols), supersample=s,
                                    lit=lit, cloud=trans if cloud_on else None)
        radiance.append(L)
        clean.append(L_clear)
        cloud_att.append(_pixel_mean(trans, (rows, cols), s2).astype(np.float32))
        sun_seen.append(_pixel_mean(np.asarray(lit, dtype=np.float64), (rows, cols), s2))
        progress.update(k + 1)
    log.info("outdoor render: exposure, shake and the pushbroom ground truth")
    radiance = np.stack(radiance)
    clean = np.stack(clean)
    levels = np.array([nz.metered_level(L) for L in radiance])
    gain, ae_ev = nz.auto_exposure(levels, seed=seed, enabled=bool(opts["auto_exposure"]))
    dx, dy = nz.shake_offsets(len(times), seed=seed, max_px=float(opts["shake_px"]))
    lit_gain, sky_gain = gt.state_gains(clean, np.stack(sun_seen), sky_img, exposure_gain=gain)
    sensor_frames = np.stack([
        (gain[k] * nz.apply_shake(radiance[k], dx[k], dy[k])).astype(np.float32)
        for k in range(len(times))])

    # pushbroom ground truth
    reference = clean[0]
    edge_y, n_trans, edge_row = gt.pushbroom_edge(T_img, sky_img, times)
    frac = edge_y - edge_row - 0.5
    below_ok = np.zeros_like(edge_row, dtype=bool)
    has = edge_row >= 0
    kk, cc = np.nonzero(has)
    below_ok[has] = T_img[edge_row[has] + 1, cc] != -np.inf  # not shadowed at start
    pb_front = gt.sample_rows(reference, edge_row, frac, below_ok)
    pb_live = np.full_like(pb_front, np.nan)
    pb_live[kk, cc] = clean[kk, edge_row[has], cc]
    pb_bin, pb_count = gt.pushbroom_bins(T_img, cls.reshape(rows, cols), reference, times)

    sun_dirs = scene.sun.direction(times)
    elev, azim = elevation_azimuth(sun_dirs)
    cause = np.zeros(rows * cols, dtype=np.uint8)
    idx = np.flatnonzero(cls == 3)
    if idx.size:
        d_after = scene.sun.direction(t_centre[idx])
        facing = np.einsum("ij,ij->i", centres.normal[idx], d_after) > 0
        cause[idx] = np.where(facing, 1, 2)

    sub_img = t_sub.reshape(rows, cols, s2).astype(np.float32)
    sub_sky = samples.sky.reshape(rows, cols, s2)
    with np.errstate(invalid="ignore"):
        half = np.median(t_sub.reshape(rows, cols, s2), axis=2)
    half[sub_sky.any(axis=2) | ~np.isfinite(half)] = np.nan
    offsets = np.stack(np.meshgrid((np.arange(s) + 0.5) / s, (np.arange(s) + 0.5) / s,
                                   indexing="ij")[::-1], axis=-1).reshape(s2, 2)

    img = (rows, cols)
    rc, rcc, trc = ("row", "col"), ("row", "col", "channel"), ("time", "row", "col")
    tc, tcc = ("time", "col"), ("time", "col", "channel")

    def var(dims, data, units, long_name):
        return xr.Variable(dims, data, {"units": units, "long_name": long_name})

    position = centres.position.reshape(rows, cols, 3).astype(np.float32)
    position[sky_img] = np.nan
    data = {
        "shadow_class": var(rc, cls.reshape(img), "1", "0 sky, 1 never shadowed, 2 shadowed at start, 3 shadow arrives"),
        "sky_mask": var(rc, centres.sky.reshape(img), "1", "pixel-centre ray misses the terrain"),
        "never_shadowed": var(rc, classes["never_shadowed"].reshape(img), "1", "lit in every frame"),
        "shadowed_at_start": var(rc, classes["shadowed_at_start"].reshape(img), "1", "unlit in frame 0"),
        "always_shadowed": var(rc, classes["always_shadowed"].reshape(img), "1", "unlit in every frame"),
        "relit_after_arrival": var(rc, classes["relit_after_arrival"].reshape(img), "1", "lit again after the first shadowed frame"),
        "cause": var(rc, cause.reshape(img), "1", "class 3: 1 cast shadow, 2 attached shadow"),
        "arrival_time_s": var(rc, arrival.reshape(img), "s", "time the sun is first blocked at the pixel centre"),
        "arrival_frame": var(rc, time_to_frame(arrival, times, outside="nan").reshape(img), "frame", "arrival time as a fractional frame index"),
        "first_shadowed_frame": var(rc, first.reshape(img).astype(np.int32), "frame", "first frame with the pixel centre unlit (-1 never)"),
        "lit_center": var(trc, lit_centre.reshape(len(times), rows, cols), "1", "pixel-centre point lit by the sun at frame k"),
        "subpixel_arrival_time_s": var(("row", "col", "subpixel"), sub_img, "s", "arrival time of the render samples (+inf never, -inf at start, NaN sky)"),
        "subpixel_offsets": var(("subpixel", "xy"), offsets.astype(np.float32), "pixel", "sample offsets (x, y) from the pixel corner"),
        "arrival_time_half_coverage_s": var(rc, half, "s", "median of the sub-pixel arrival times"),
        "arrival_frame_half_coverage": var(rc, time_to_frame(half, times, outside="nan"), "frame", "half-coverage arrival as a fractional frame index"),
        "subpixel_sky_fraction": var(rc, sub_sky.mean(axis=2).astype(np.float32), "1", "fraction of the sub-pixel samples that are sky"),
        "sky_fraction": var(rc, sub_sky.mean(axis=2).astype(np.float32), "1", "fraction of the rendered pixel footprint that is sky"),
        "position_world": var(rcc, position, "m", "terrain point at the pixel centre (x east, y north, z up)"),
        "normal_shading": var(rcc, np.where(sky_img[..., None], np.nan, centres.normal.reshape(rows, cols, 3)).astype(np.float32), "1", "shading normal at the pixel centre"),
        "depth_z": var(rc, centres.depth_z.reshape(img).astype(np.float32), "m", "camera z of the pixel-centre point"),
        "reference_radiance": var(rcc, reference, "1", "noise-free radiance of frame 0 (no cloud, gain, shake, noise)"),
        "times_s": var(("time",), times, "s", "capture time since frame 0"),
        "nominal_index": var(("time",), nominal.astype(np.int32), "1", "slot in the nominal schedule"),
        "sun_dirs": var(("time", "xyz"), sun_dirs, "1", "unit vector toward the sun (east, north, up)"),
        "sun_elevation_deg": var(("time",), elev, "degree", "sun elevation"),
        "sun_azimuth_deg": var(("time",), azim, "degree", "sun compass azimuth"),
        "sun_rgb": var(("time", "channel"), sun_colour(elev, reference_elevation_deg=scene.start_elevation_deg), "1", "sun colour"),
        "sky_rgb": var(("time", "channel"), sky_colour(elev, start_elevation_deg=scene.start_elevation_deg), "1", "radiance of the uniform sky light"),
        "exposure_gain": var(("time",), gain, "1", "true total exposure gain (steps x flicker)"),
        "lit_gain": var(("time",), lit_gain, "1", gt.DEFINITIONS["lit_gain"]),
        "sky_gain": var(("time",), sky_gain, "1", gt.DEFINITIONS["sky_gain"]),
        "ae_ev": var(("time",), ae_ev, "EV", "auto-exposure step part"),
        "metered_level": var(("time",), levels, "1", "centre-weighted mean radiance metered by auto-exposure"),
        "shake_dx_px": var(("time",), dx, "pixel", "camera shake: content moves by +dx (columns)"),
        "shake_dy_px": var(("time",), dy, "pixel", "camera shake: content moves by +dy (rows)"),
        "cloud_attenuation": var(trc, np.stack(cloud_att), "1", "mean cloud-shadow transmittance of the sun term over the pixel"),
        "cloud_center_xy": var(("time", "xy"), np.asarray(cloud_attrs["start_xy"])
                               + np.outer(times, cloud_attrs["velocity_xy_m_per_s"]), "m",
                               "centre of the cloud shadow on the ground"),
        "pb_edge_y": var(tc, edge_y, "pixel", "shadow-edge row coordinate per column"),
        "pb_n_transitions": var(tc, n_trans, "1", "lit-above/shadowed-below pairs per column"),
        "pb_front": var(tcc, pb_front, "1", "ground-truth ridge pushbroom"),
        "pb_front_live": var(tcc, pb_live, "1", "pushbroom from each frame's own noise-free radiance"),
        "pb_bin": var(tcc, pb_bin, "1", "mean reference radiance of pixels swept between frames"),
        "pb_bin_count": var(tc, pb_count, "1", "pixels in pb_bin"),
    }
    for key, values in penumbra.items():
        data[key] = var(rc, values.reshape(img), "s", gt.DEFINITIONS[key])
    camera = scene.camera
    ds = xr.Dataset(data, coords={"time": np.arange(len(times)), "channel": ["R", "G", "B"]})
    ds.attrs.update({
        "definitions": json.dumps(gt.DEFINITIONS),
        "scene": "ridge",
        "K": json.dumps(camera.K.tolist()),
        "R_world_to_cv": json.dumps(camera.R.tolist()),
        "t_world_to_cv": json.dumps((-camera.R @ camera.center).tolist()),
        "camera_center": json.dumps(camera.center.tolist()),
        "latitude_deg": scene.sun.latitude_deg,
        "declination_deg": scene.sun.declination_deg,
        "hour_angle0_deg": scene.sun.hour_angle0_deg,
        "dropped_nominal_indices": json.dumps(dropped.tolist()),
        "nuisances": json.dumps(opts),
        "cloud": json.dumps(cloud_attrs),
        "class_counts": json.dumps({name: int((cls == c).sum()) for c, name in gt.SHADOW_CLASSES.items()}
                                   | {"relit_after_arrival": int(classes["relit_after_arrival"].sum()),
                                      "always_shadowed": int(classes["always_shadowed"].sum())}),
        "supersample": s,
        "sun_diameter_deg": float(sun_diameter_deg),
    })
    return OutdoorCapture(frames=sensor_frames, ground_truth=ds)


def noisy_frame_store(capture, *, bit_depth=14, seed=3, exposure=0.6, push_stops=0.0):
    """A capture's frames with Poisson-Gaussian sensor noise on linear RGB (no mosaic), as a frame store.

    Parameters
    ----------
    capture : OutdoorCapture
    bit_depth : int, keyword-only
        Of the :class:`shadowcam.synthetic.sensor.SensorModel`.
    seed : int, keyword-only
        Frame ``k``'s noise is drawn with seed ``[seed, k]``.
    exposure : float, keyword-only
        The reference radiance's share of the sensor's range
        (:func:`shadowcam.synthetic.sensor.electrons_per_unit_radiance`).
    push_stops : float, keyword-only
        Stops the photographer pushes the exposure beyond `exposure` (the signal times
        ``2 ** push_stops``): the brightest lit ground then reaches the sensor's white level,
        where its samples read 1 (the RAW white level after black subtraction, as a decoded
        frame store's). 0 (default): today's frames, bit for bit.

    Returns
    -------
    xarray.Dataset
        ``image (time, row, col, channel)`` float32 in [0, 1], coords ``time_s`` and
        ``exposure_s`` (4 ms times the auto-exposure steps: the metadata carries no flicker);
        attrs ``black_level``, ``white_level`` and ``normalisation`` as a decoded frame store's.
    """
    import xarray as xr

    from shadowcam.synthetic.sensor import SensorModel, electrons_per_unit_radiance, raw_to_linear, simulate_raw

    truth = capture.ground_truth
    sensor = SensorModel(bit_depth=int(bit_depth))
    scale = electrons_per_unit_radiance(truth["reference_radiance"].values, sensor=sensor, target_fraction=exposure)
    if push_stops:
        scale = scale * 2.0 ** float(push_stops)
    images = np.stack([raw_to_linear(simulate_raw(frame, sensor=sensor, scale=scale, seed=[seed, k], mosaic=False),
                                     sensor=sensor) for k, frame in enumerate(capture.frames)])
    return xr.Dataset({"image": (("time", "row", "col", "channel"), images)},
                      coords={"time_s": ("time", capture.times_s),
                              "exposure_s": ("time", 0.004 * 2.0 ** truth["ae_ev"].values)},
                      attrs={"black_level": sensor.black_level, "white_level": sensor.white_level,
                             "normalisation": "linear; (value - black_level) / (white_level - black_level)"})


def edge_speed(arrival_frame, shadow_class):
    """Fraction of vertically adjacent class-3 pairs whose arrival frames differ by < 1
    (the edge crosses that pixel step in under one frame) and the median frames per pixel.

    Returns
    -------
    fast_fraction, median_frames_per_px : float
    """
    a = np.asarray(arrival_frame, dtype=np.float64)
    both = (shadow_class[:-1] == 3) & (shadow_class[1:] == 3)
    diff = np.abs(a[:-1] - a[1:])[both]
    if diff.size == 0:
        return float("nan"), float("nan")
    return float((diff < 1.0).mean()), float(np.median(diff))
