"""A rendered several-lights capture from a manifest's ``synthetic:`` block (paper Fig. 11).

Offers
------
make_lights : the manifest's ``lights`` entries -> PointLight / TubeLight objects.
render_light_set_capture : ``synthetic`` block (with ``lights``) -> frames of the u and v
    sweeps, the reference image and the per-light ground truth.
write_light_set_capture : render and write the capture directory of a manifest's options.
"""

import datetime

import numpy as np
import xarray as xr

from shadowcam.synthetic.lab.light_sets import TubeLight, light_set_ground_truth, trace_light_set
from shadowcam.synthetic.lab.render import SWEEP_INDEX, render_image, sweep_frames
from shadowcam.synthetic.lab.scene import PointLight
from shadowcam.synthetic.lab.scenes import make_scene
from shadowcam.synthetic.sensor import SensorModel, electrons_per_unit_radiance, raw_to_linear, simulate_raw


def make_lights(entries, scene):
    """Lights of a manifest's ``synthetic.lights`` around `scene`'s point light.

    Parameters
    ----------
    entries : sequence of mapping
        ``kind`` (point or tube), ``offset`` (e_u, e_v, normal) scene units, tube ``axis``
        (u or v, default v) and ``length`` (default 0.012).
    scene : Scene
        A point-light lab scene.

    Returns
    -------
    list of PointLight or TubeLight
    """
    if not isinstance(scene.light, PointLight):
        raise ValueError("manifest key 'light': several lights are placed around a point light; "
                         "use light: point")
    m = scene.mask
    lights = []
    for index, entry in enumerate(entries):
        du, dv, dn = entry.get("offset", (0.0, 0.0, 0.0))
        centre = scene.light.position + du * m.e_u + dv * m.e_v + dn * m.normal
        if entry["kind"] == "point":
            lights.append(PointLight(centre, scene.light.intensity))
        elif entry["kind"] == "tube":
            axis = m.e_u if entry.get("axis", "v") == "u" else m.e_v
            half = 0.5 * float(entry.get("length", 0.012)) * axis
            lights.append(TubeLight(centre - half, centre + half, intensity=scene.light.intensity))
        else:
            raise ValueError(f"synthetic.lights[{index}].kind must be point or tube; got {entry['kind']!r}")
    return lights


def render_light_set_capture(synthetic, *, light="point"):
    """Render the u and v sweeps of a scene lit by several lights.

    Parameters
    ----------
    synthetic : mapping
        The manifest's ``synthetic`` block with ``lights``; its optional ``shutter`` is the
        exposure of each frame as a fraction of the frame interval (absent: an instant
        exposure), as for the single-light lab renderer
        (:func:`~shadowcam.synthetic.lab.render.sweep_frames`). With ``noise: true`` every
        image passes through the sensor model (:mod:`shadowcam.synthetic.sensor`: Poisson
        shot noise, Gaussian read noise, ``bit_depth``-bit quantisation, per channel, no
        mosaic) exposed so that the reference's 99.5th percentile reaches ``exposure``
        (default 0.8) of the range, seeded ``[seed, sweep_index, frame]`` as the capture
        writer's frames, and is returned in radiance units.
    light : str
        The manifest's ``light`` (``point``).

    Returns
    -------
    xarray.Dataset
        ``frames_u`` (t_u, y, x, channel), ``frames_v`` (t_v, y, x, channel), ``reference``
        (y, x, channel), and per sweep s the ground truth ``t_center_s``, ``t_first_s``,
        ``t_last_s`` (light, y, x) and ``share`` (light, y, x)
        (:func:`~shadowcam.synthetic.lab.light_sets.light_set_ground_truth`), and
        ``light_along_s`` (light,): each light's centre along sweep s's wire velocity (the
        order in which its shadows pass a point; part of the capture description).
    """
    if "lights" not in synthetic:
        raise ValueError("synthetic: no lights block; add lights: [{kind: point}, ...]")
    scene = make_scene(synthetic["scene"], seed=int(synthetic["seed"]), height=int(synthetic["height"]),
                       width=int(synthetic["width"]), frames=int(synthetic["frames"]), light_kind=light)
    lights = make_lights(synthetic["lights"], scene)
    shutter = float(synthetic.get("shutter", 0.0))
    paths, source = trace_light_set(scene.objects, scene.camera, lights,
                                    supersample=int(synthetic.get("supersample", 3)))
    reference = render_image(paths)
    sense = _sensor_exposure(synthetic, reference)
    data = {"reference": (("y", "x", "channel"), sense(reference, "reference", 0))}
    for name in ("u", "v"):
        sweep = scene.sweeps[name]
        frames = sweep_frames(paths, sweep, scene.mask, shutter=shutter)
        data[f"frames_{name}"] = ((f"t_{name}", "y", "x", "channel"),
                                  np.stack([sense(frame, name, k) for k, frame in enumerate(frames)]))
        truth = light_set_ground_truth(scene.objects, scene.camera, lights, sweep, paths, source)
        for key in ("t_center", "t_first", "t_last"):
            data[f"{key}_{name}"] = (("light", "y", "x"), truth[key])
        data["share"] = (("light", "y", "x"), truth["share"])
        # where each light sits along the wire's motion: its shadows pass in that order
        direction = sweep.velocity / np.linalg.norm(sweep.velocity)
        data[f"light_along_{name}"] = (("light",), np.array(
            [float(np.dot(getattr(light, "center", getattr(light, "position", None)), direction))
             for light in lights]))
    return xr.Dataset(data, coords={"channel": ["R", "G", "B"], "light": np.arange(len(lights))},
                      attrs={"lights": str(list(synthetic["lights"]))})


def _sensor_exposure(synthetic, reference):
    """Image -> float32 image: through the noisy sensor when ``synthetic.noise``, else as is."""
    if not synthetic.get("noise", False):
        return lambda image, sweep, frame: np.asarray(image, dtype=np.float32)
    sensor = SensorModel(bit_depth=int(synthetic.get("bit_depth", 12)))
    scale = electrons_per_unit_radiance(reference, sensor=sensor,
                                        target_fraction=float(synthetic.get("exposure", 0.8)))
    to_radiance = np.float32((sensor.white_level - sensor.black_level) / (sensor.gain * scale))
    seed = int(synthetic["seed"])

    def sense(image, sweep, frame):
        raw = simulate_raw(image, sensor=sensor, scale=scale, seed=[seed, SWEEP_INDEX[sweep], frame],
                           noise=True, mosaic=False)
        return raw_to_linear(raw, sensor=sensor) * to_radiance
    return sense


def write_light_set_capture(options, out_dir):
    """Render a several-lights capture and write it as a capture directory, like a camera would.

    The layout is a standard lab capture's (docs/contracts.md): ``frames_u/000000.<ext>
    ...``, ``frames_v/...``, ``reference.<ext>`` (all lights on, no wire), plus
    ``ground_truth.nc`` and ``capture.json``, whose top-level ``lights`` block (``kinds``,
    ``light_along_u``, ``light_along_v``) is the one a user's manifest gives.

    Parameters
    ----------
    options : dict
        :func:`shadowcam.synthetic.capture_options.capture_options` of a manifest whose
        ``synthetic`` block has ``lights``: ``format`` (dng: the raw RGGB mosaic; tiff:
        linear 16-bit RGB), ``noise`` (shot and read noise), ``bit_depth``, ``exposure``
        (the reference's 99.5th percentile exposed to that fraction of the range), ``seed``
        (noise seeds ``[seed, sweep_index, frame]``, sweep_index u=0 v=1 reference=9, as
        the lab capture writer's).
    out_dir : str or Path

    Returns
    -------
    Path
        `out_dir`, holding the frame files, ``ground_truth.nc`` (``reference`` radiance
        (y, x, channel), per sweep s ``t_center_s``, ``t_first_s``, ``t_last_s`` (light, y,
        x), ``share``, ``light_along_s``: :func:`render_light_set_capture` without the
        frames) and ``capture.json``.

    Raises
    ------
    ValueError
        When the options have no ``lights``.
    """
    import json
    from pathlib import Path

    from shadowcam import __version__
    from shadowcam._shared.atomic import atomic_directory
    from shadowcam._shared.progress import Progress
    from shadowcam.io.provenance import file_sha256
    from shadowcam.synthetic.capture_writer import CAPTURE_START, write_frame, write_ground_truth

    if not options.get("lights"):
        raise ValueError(f"options['lights']: capture {options.get('name')!r} has no lights block; add "
                         "lights: [{kind: point}, {kind: point, offset: [...]}] to the manifest's synthetic block")
    out_dir = Path(out_dir)
    capture = render_light_set_capture({**options, "noise": False}, light=options["light"])
    sensor = SensorModel(bit_depth=options["bit_depth"])
    scale = electrons_per_unit_radiance(capture["reference"].values, sensor=sensor,
                                        target_fraction=options["exposure"])
    ext, seed = options["format"], int(options["seed"])
    images = {"reference": [("reference", capture["reference"].values)]}
    for name in ("u", "v"):
        images[name] = [(f"frames_{name}/{k:06d}", frame) for k, frame in enumerate(capture[f"frames_{name}"].values)]
    progress = Progress(sum(len(group) for group in images.values()), "write several-lights frames", unit="images")
    written = []
    with atomic_directory(out_dir) as tmp:
        for name, group in images.items():
            for k, (stem, radiance) in enumerate(group):
                (tmp / stem).parent.mkdir(exist_ok=True)
                write_frame(tmp / f"{stem}.{ext}", radiance, frame_format=ext, noise=bool(options["noise"]),
                            sensor=sensor, scale=scale, seed=[seed, SWEEP_INDEX[name], k],
                            when=CAPTURE_START + datetime.timedelta(seconds=k))
                written.append(f"{stem}.{ext}")
                progress.update(len(written))
        checksums = {rel: file_sha256(tmp / rel) for rel in written}
        truth = capture.drop_vars(["frames_u", "frames_v"])
        kinds = [entry["kind"] for entry in options["lights"]]
        write_ground_truth(tmp, truth, sensor=sensor, scale=scale, config=dict(options),
                           checksums=checksums, frame_format=ext,
                           noise_seed="numpy.random.default_rng([seed, sweep_index, frame]); "
                                      "sweep_index u=0 v=1 reference=9")
        description = {
            "name": options["name"], "kind": "lab", "description": options["description"], "light": "point",
            "root": ".",
            "sweeps": {name: {"files": f"frames_{name}/*.{ext}", "axis": name} for name in ("u", "v")},
            "reference": f"reference.{ext}",
            "timing": {"source": "rate", "rate_hz": 1.0},
            "checksums": checksums,
            "lights": {"kinds": kinds,
                       **{f"light_along_{name}": [float(x) for x in capture[f"light_along_{name}"].values]
                          for name in ("u", "v")}},
            "ground_truth": {"format": "shadowcam_lights_nc", "file": "ground_truth.nc",
                             "noise": "raw12" if options["noise"] else "noise_free"},
            "provenance": (f"rendered by shadowcam {__version__} 'shadowcam render-lights' (scene "
                           f"{options['scene']}, seed {seed}, {options['height']}x{options['width']}, "
                           f"{len(kinds)} lights {kinds}, {ext} {options['bit_depth']}-bit, noise "
                           f"{options['noise']}); deterministic"),
            "licence": "CC0-1.0",
        }
        (tmp / "capture.json").write_text(json.dumps(description, indent=2) + "\n")
    return out_dir
