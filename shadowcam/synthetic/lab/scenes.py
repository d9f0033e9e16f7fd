"""Whole lab scenes: a scene's objects, light, camera, mask plane, sweeps and optics; presets.

Builds on the primitives of :mod:`shadowcam.synthetic.lab.scene`, the general sweeps of
:mod:`shadowcam.synthetic.lab.sweeps` and the optics of :mod:`shadowcam.synthetic.lab.optics`.

Offers
------
Scene : a renderable scene.
calibration_scene : the scene holding only its calibration (back) plane.
CAMERA_KINDS : primal camera kinds of the presets (perspective, orthographic).
SCENES, make_scene : presets by name (tabletop, tabletop_squares, panels) and the factory.
scene_from_description, DESCRIPTION_KEYS : a scene from a capture description (the scene
    keys of a manifest's ``synthetic:`` block: light, camera, sweeps, optics, wire radius,
    area light, ...).
AREA_LIGHT_KEYS : keys of an ``area_light`` description.
"""

from dataclasses import dataclass, replace

import numpy as np

from shadowcam._shared.validation import check_in, check_positive
from shadowcam.synthetic.lab.optics import optics_setup
from shadowcam.synthetic.lab.scene import (
    AREA_SHAPES, AreaLight, BackPlane, Box, DistantLight, GroundPlane, MaskPlane, Material, OrthographicCamera,
    PinholeCamera, PointLight, Sphere, Texture, look_at_camera, make_mask_plane, make_wire_sweeps,
)
from shadowcam.synthetic.lab.sweeps import make_sweeps


@dataclass(frozen=True, eq=False)
class Scene:
    """A renderable lab scene: objects, one light, a camera, the mask plane and sweeps.

    `optics` holds optical elements (``optics.OPTICAL_ELEMENTS``: mirrors, thick glass) that
    bend the camera's primary rays only; empty = the camera sees the scene directly.
    `dual_sweeps` names the two sweeps whose shadow times are the pixel coordinates of the
    reciprocal (virtual) view (``lab.virtual.SweepPairCamera``); None = the standard dual
    camera of the mask plane (``dual_camera``).
    """

    name: str
    objects: tuple
    light: object
    camera: PinholeCamera
    mask: MaskPlane
    sweeps: dict
    seed: int = 0
    optics: tuple = ()
    dual_sweeps: tuple = None

    @property
    def back_plane(self):
        """The scene's calibration plane (first BackPlane), or None."""
        return next((o for o in self.objects if isinstance(o, BackPlane)), None)


def calibration_scene(scene):
    """Return `scene` holding only its back plane (same light, camera and sweeps)."""
    plane = scene.back_plane
    if plane is None:
        raise ValueError("scene: has no BackPlane to calibrate with")
    return replace(scene, name=f"{scene.name}_calibration", objects=(plane,))


#: primal camera kinds of the presets
CAMERA_KINDS = ("perspective", "orthographic")


def _orthographic_like(camera, distance):
    """Orthographic camera with the pinhole's pose whose field matches it at `distance`."""
    pixel_size = distance / camera.K[0, 0]
    return OrthographicCamera(R=camera.R, center=camera.center, pixel_size=pixel_size,
                              width=camera.width, height=camera.height)


def _tabletop(*, seed, height, width, frames, light_kind, camera_kind="perspective",
              back_texture="discs"):
    rng = np.random.default_rng([seed, 1234])
    jit = lambda s: rng.uniform(-s, s)  # noqa: E731
    ground_y = -0.05
    tex_sphere = Texture("checker", [[0.15, 0.25, 0.6], [0.85, 0.8, 0.65]], 0.012, seed)
    tex_ground = Texture("bricks", [[0.55, 0.3, 0.22], [0.5, 0.35, 0.25], [0.62, 0.6, 0.55]],
                         0.012, seed)
    tex_back = Texture(back_texture, [[0.75, 0.75, 0.72], [0.8, 0.2, 0.2], [0.2, 0.55, 0.25],
                                      [0.2, 0.3, 0.75], [0.85, 0.7, 0.15]], 0.05, seed)
    shade = lambda c: np.clip(np.asarray(c) * rng.uniform(0.9, 1.1, 3), 0, 1)  # noqa: E731
    radii = (0.034, 0.022, 0.013)
    xz = ((-0.06, -0.04), (0.015, 0.04), (0.075, 0.0))
    mats = (Material(texture=tex_sphere, specular=0.04),
            Material(albedo=shade([0.8, 0.5, 0.25]), specular=0.04),
            Material(albedo=shade([0.35, 0.7, 0.4]), specular=0.04))
    objects = [Sphere((x + jit(0.006), ground_y + r, z + jit(0.006)), r, m)
               for r, (x, z), m in zip(radii, xz, mats)]
    objects.append(Box((0.02 + jit(0.005), ground_y + 0.03, -0.085 + jit(0.005)),
                       (0.018, 0.03, 0.015), 35.0 + jit(5.0),
                       Material(albedo=shade([0.55, 0.58, 0.7]))))
    objects.append(GroundPlane(ground_y, Material(texture=tex_ground)))
    objects.append(BackPlane((0.0, 0.23, -0.13), 1.0, 0.56, 12.0 + jit(2.0),
                             Material(texture=tex_back)))
    camera = look_at_camera((0.03, 0.085, 0.3), (0.0, -0.02, -0.03), fov_x_deg=42.0,
                            width=width, height=height)
    if camera_kind == "orthographic":
        camera = _orthographic_like(camera, distance=0.33)
    elif camera_kind != "perspective":
        raise ValueError(f"camera_kind: must be one of {CAMERA_KINDS}, got {camera_kind!r}")
    aim = np.array([-0.005, -0.02, -0.02])
    light_pos = camera.center + np.array([-0.09, -0.045, 0.035])
    intensity = (0.02, 0.02, 0.02)
    if light_kind == "point":
        light = PointLight(light_pos, intensity)
    elif light_kind == "area":
        light = AreaLight(light_pos, aim - light_pos, 0.006, "disc", intensity, 4)
    elif light_kind == "distant":
        light = DistantLight(light_pos - aim, (2.0, 2.0, 2.0))
    else:
        raise ValueError(f"light_kind must be 'point', 'area' or 'distant'; got {light_kind!r}")
    if light_kind == "distant":  # plane between the scene and the light, clear of objects
        mask = make_mask_plane(light, target=aim, frames=frames, f=0.2, extent=0.26)
    else:
        mask = make_mask_plane(light, target=aim, frames=frames, f=0.045, fov_deg=44.0)
    return objects, light, camera, mask


def _tabletop_squares(**options):
    return _tabletop(**options, back_texture="squares")


def _panels(**options):
    """A frontal squares back plane and a smaller frontal squares panel 0.1 nearer the
    camera and the light, over the ground: long straight parallel edges on two depth
    layers, nothing in front of them."""
    objects, light, camera, mask = _tabletop(**options, back_texture="squares")
    back = next(o for o in objects if isinstance(o, BackPlane))
    back = replace(back, yaw_deg=0.0)
    near = BackPlane(back.center + 0.1 * back.normal + np.array([0.01, -0.2, 0.0]), 0.13, 0.13,
                     0.0, back.material)
    return [o for o in objects if isinstance(o, GroundPlane)] + [back, near], light, camera, mask


#: preset scene name -> builder(seed, height, width, frames, light_kind, camera_kind)
SCENES = {"tabletop": _tabletop, "tabletop_squares": _tabletop_squares, "panels": _panels}


def _area_light(light, area_light):
    """The scene's area light with the shape, size and samples of `area_light` (a mapping)."""
    if not isinstance(light, AreaLight):
        raise ValueError(f"area_light: describes an area light, but the scene's light is a "
                         f"{type(light).__name__}; set the light to 'area' (a manifest's top-level "
                         f"`light: area`) or drop the key")
    if not hasattr(area_light, "get"):
        raise ValueError(f"area_light: expected a mapping with shape, size, samples; got {area_light!r}")
    unknown = set(area_light) - set(AREA_LIGHT_KEYS)
    if unknown:
        raise ValueError(f"area_light: unknown key(s) {sorted(unknown)}; known: {list(AREA_LIGHT_KEYS)}")
    shape = area_light.get("shape", light.shape)
    check_in(shape, "area_light.shape", AREA_SHAPES)
    size = check_positive(area_light.get("size", light.size), "area_light.size", finite=True)
    samples = area_light.get("samples", light.samples_per_side)
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
        raise ValueError(f"area_light.samples: must be an integer >= 1 (samples per side), got {samples!r}")
    return replace(light, shape=shape, size=float(size), samples_per_side=int(samples))


#: keys of a scene's ``area_light`` description -> meaning
AREA_LIGHT_KEYS = {"shape": "disc, square, sphere or tube (AREA_SHAPES)",
                   "size": "diameter of the disc or sphere, side of the square, length of the tube "
                           "(scene units)",
                   "samples": "samples per side (k**2 point lights; k**3 for a sphere)"}


def make_scene(name, *, seed=0, height=192, width=192, frames=96, light_kind="point",
               camera_kind="perspective", sweeps=None, dual_sweeps=None, optics=None,
               wire_radius_frames=None, area_light=None):
    """Build a preset scene.

    Parameters
    ----------
    name : str
        Preset name, a key of ``SCENES`` (``"tabletop"``: three spheres and a yawed box on a
        brick-textured ground in front of a disc-textured back plane, light beside the camera;
        ``"tabletop_squares"``: the same with coloured squares on the back plane, whose
        edges are straight world lines; ``"panels"``: a frontal squares back plane, the
        ground and a frontal squares panel 0.1 in front of it: long parallel edges on two
        depth layers).
    seed : int
        Varies texture layout, colours and object placement slightly.
    height, width : int
        Camera image size (rows, cols).
    frames : int
        Frames per sweep of the standard pair (= dual grid size).
    light_kind : {"point", "area", "distant"}
    camera_kind : {"perspective", "orthographic"}
        Primal camera: the preset's pinhole, or an orthographic camera with its pose
        (Fig. 8: orthographic primal view, perspective dual view).
    sweeps : sequence of dict, optional
        Sweep specifications for ``sweeps.make_sweeps`` (wire angle, motion, speed, frames,
        plane offset, own light or light offset), built on the scene's mask plane with the
        scene's light as default. None = the standard u/v pair (``make_wire_sweeps``).
    dual_sweeps : (str, str), optional
        Names of the sweeps whose times are the reciprocal view's pixel coordinates
        (``lab.virtual.SweepPairCamera``). Default: None (the standard dual camera) with the
        standard pair or a single sweep; the first two sweeps otherwise.
    optics : dict, optional
        Optical elements on the camera side (paper section V), e.g. ``{"kind": "mirror"}``
        (the camera looks at the scene in a convex spherical mirror) or
        ``{"kind": "glass", "shape": "slab", "index": 1.5}``; the other keys are the options
        of ``optics.mirror_setup`` / ``optics.glass_setup`` (which need the perspective
        camera). None = direct view.
    wire_radius_frames : float, optional
        Radius of every sweep's wire in mask steps (frames of the standard pair); a wire
        wider than the source seen through it casts an umbra between two penumbrae.
        None = one mask step (a dip about two frames wide).
    area_light : dict, optional
        With ``light_kind="area"``: ``shape`` ({"disc", "square", "sphere", "tube"}; a tube
        lies along the mask plane's e_u), ``size`` (diameter of the disc or sphere, side of
        the square, length of the tube) and ``samples`` (per side);
        omitted keys keep the preset's disc of diameter 0.006 with 4 samples per side.

    Returns
    -------
    Scene
    """
    check_in(name, "name", SCENES)
    for key, value in (("height", height), ("width", width)):
        if int(value) < 2 or int(value) % 2:
            raise ValueError(f"{key}: must be an even number >= 2, got {value}")
    if camera_kind not in CAMERA_KINDS:
        raise ValueError(f"camera_kind: must be one of {CAMERA_KINDS}, got {camera_kind!r}")
    builder_options = {} if camera_kind == "perspective" else {"camera_kind": camera_kind}
    objects, light, camera, mask = SCENES[name](seed=int(seed), height=int(height),
                                                width=int(width), frames=int(frames),
                                                light_kind=light_kind, **builder_options)
    if area_light is not None:
        light = _area_light(light, area_light)
    radius = None
    if wire_radius_frames is not None:
        radius = check_positive(wire_radius_frames, "wire_radius_frames", finite=True) * mask.delta
    if sweeps is None:
        sweep_set = make_wire_sweeps(mask, radius=radius)
    else:
        sweep_set = make_sweeps(mask, sweeps, light=light, radius=radius)
        if dual_sweeps is None and len(sweep_set) >= 2:
            dual_sweeps = tuple(sweep_set)[:2]
    if dual_sweeps is not None:
        dual_sweeps = tuple(dual_sweeps)
        if len(dual_sweeps) != 2 or any(k not in sweep_set for k in dual_sweeps):
            raise ValueError(f"dual_sweeps: expected two of the sweep names "
                             f"{sorted(sweep_set)}, got {dual_sweeps!r}")
    elements = ()
    if optics is not None:
        camera, elements = optics_setup(optics, camera)
    return Scene(name=name, objects=tuple(objects), light=light, camera=camera, mask=mask,
                 sweeps=sweep_set, seed=int(seed), optics=tuple(elements),
                 dual_sweeps=dual_sweeps)


#: capture-description key -> make_scene argument (the scene part of a ``synthetic:`` block)
DESCRIPTION_KEYS = {"scene": "name", "seed": "seed", "height": "height", "width": "width",
                    "frames": "frames", "light": "light_kind", "camera": "camera_kind",
                    "sweeps": "sweeps", "dual_sweeps": "dual_sweeps", "optics": "optics",
                    "wire_radius_frames": "wire_radius_frames", "area_light": "area_light"}


def scene_from_description(description):
    """Build the scene a capture description asks for.

    Parameters
    ----------
    description : mapping
        Like a manifest's ``synthetic:`` block: ``scene`` (preset name, required), ``seed``,
        ``height``, ``width``, ``frames``, ``light`` ({"point", "area", "distant"}),
        ``camera`` ({"perspective", "orthographic"}), ``sweeps`` (list of sweep specs of
        ``sweeps.make_sweeps``, e.g. ``{"name": "w", "angle_deg": 30, "speed": 1.0,
        "light_offset": [0, 0, -0.02]}``), ``dual_sweeps`` (two sweep names), ``optics``
        (optical elements, e.g. ``{"kind": "glass", "shape": "slab", "index": 1.5}``; see
        ``make_scene``), ``wire_radius_frames`` (wire radius in mask steps), ``area_light``
        (``{shape, size, samples}`` of an area light). Other keys
        (frame format, noise, supersample, ...) describe the rendering, not the scene, and
        are left to the caller. Missing keys take ``make_scene``'s defaults, so a
        description without light/camera/sweeps gives exactly today's scene.

    Returns
    -------
    Scene
    """
    if not hasattr(description, "get") or "scene" not in description:
        raise ValueError("description: expected a mapping with at least a 'scene' key")
    options = {arg: description[key] for key, arg in DESCRIPTION_KEYS.items()
               if key in description and description[key] is not None}
    return make_scene(options.pop("name"), **options)
