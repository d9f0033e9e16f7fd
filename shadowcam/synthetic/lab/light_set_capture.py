"""A rendered several-lights capture from a manifest's ``synthetic:`` block (paper Fig. 11).

Offers
------
make_lights : the manifest's ``lights`` entries -> PointLight / TubeLight objects.
render_light_set_capture : ``synthetic`` block (with ``lights``) -> frames of the u and v
    sweeps, the reference image and the per-light ground truth.
"""

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
