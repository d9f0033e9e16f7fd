"""Capture plans: every fact about a capture that the steps after it need, derived once.

A capture plan is read from a manifest (``data_manifest/<name>.yaml``) before
anything runs: it validates the manifest against the package's schema
(:func:`shadowcam.io.manifest.load_manifest`, the same check and message as
every ``shadowcam`` step), resolves each sweep's files with the manifest's own
rules (recursive globs, files only, natural order), and answers what the
workflow plans jobs from: frame counts, the frame shape, the frame times,
whether there is a reference frame, calibration sweeps and ground truth,
whether the capture is outdoor or lab, which sweeps are timed, which dual
coordinate model runs (both scene sweeps) or that the capture is a shadow
pushbroom (one scene sweep), the shadow camera the lab sweeps make (decided once
by :func:`shadowcam.cameras.models.choose_camera_model` from the sweep geometry:
direction, speed and light of each sweep) and the halo of an edge-tracking strip.

A ``kind: lightfield`` manifest has screens (id, position, homography or markers),
a horizontal and a vertical sweep per screen and exposure brackets; its plan carries
them in :attr:`CapturePlan.lightfield` (:func:`lightfield_facts`).

A manifest with a ``synthetic:`` block (and no ``sweeps``) describes a capture
the renderer writes; its plan takes the frame count and shape from that block
and has no files yet. Its optional ``synthetic.camera`` block declares the
shadow camera to render (sweeps, primal camera, optics); each sweep's frame
count is what its wire needs to cross the rendered dual field
(:func:`shadowcam.cameras.models.frames_to_cross`, the renderer's own rule).

Offers
------
SCENE_SWEEPS : the two perpendicular scene sweeps of a lab capture.
CALIBRATION_SWEEPS : the calibration-plane sweeps of a lab capture.
OUTDOOR_SWEEP : preferred name of the time-lapse sweep of an outdoor capture.
ARRAY_SWEEPS : the two experiments of a captured camera array.
PLANNED_SHIFT_COLUMNS : camera shake (columns) the planned strip halo allows for.
SweepPlan : one sweep: name, files, frame count, frame times, axis, geometry.
CapturePlan : the plan of one capture (frozen dataclass).
LIGHTFIELD_SWEEPS : sweep suffix -> mask axis the wire moves along, of a light-field screen.
lightfield_facts : the screens, sweeps and brackets of a ``kind: lightfield`` manifest.
capture_plan : read a manifest into a :class:`CapturePlan`.
footprint_variance : a lab capture's declared pixel footprint variance (``sensor.footprint_variance_px2``).
"""

import inspect
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

import numpy as np

from shadowcam.cameras.dual_coords import choose_dual_model
from shadowcam.io.frame_files import check_capture_frames, check_frame_files
from shadowcam.io.manifest import load_manifest

#: scene sweeps of a lab capture (perpendicular, measuring dual u and v)
SCENE_SWEEPS = ("u", "v")
#: calibration-plane sweeps of a lab capture
CALIBRATION_SWEEPS = ("cal_u", "cal_v")
#: name of the time-lapse sweep of an outdoor capture (else its only sweep)
OUTDOOR_SWEEP = "timelapse"
#: camera shake (columns) the planned strip halo allows for; a strip job sizes its own
#: halo from the registration shifts it reads (shadowcam.outdoor.strips.strip_halo)
PLANNED_SHIFT_COLUMNS = 4
#: optics of a rendered lab camera (``synthetic.camera.optics``)
OPTICS = ("none", "mirror", "glass")
#: sweep suffix of a light-field screen -> mask axis its wire moves along (h: a vertical
#: wire moving along x; v: a horizontal wire moving along y)
LIGHTFIELD_SWEEPS = {"h": "x", "v": "y"}


@dataclass(frozen=True)
class SweepPlan:
    """One sweep of a capture.

    Attributes
    ----------
    name : str
        Sweep name (``u``, ``v``, ``cal_u``, ``cal_v``, ``timelapse``, ...).
    files : tuple of str
        Absolute paths in frame order (empty for a capture not rendered yet).
    n_frames : int
        Frames of the sweep (for a rendered capture, the frames it is rendered with).
    times_s : tuple of float
        Frame time of each file in seconds (empty for a capture not rendered yet).
    axis : str or None
        Dual axis the sweep measures (``u`` or ``v``), if the manifest says.
    direction_deg : float or None
        Lab scene sweep: wire motion direction in the mask plane (degrees from dual u
        toward v); None for other sweeps.
    speed : float or None
        Lab scene sweep: wire speed relative to the other sweeps (dual pixels per frame).
    light : tuple of float or None
        Lab scene sweep with its own light: ``light_offset`` (rendered) or
        ``light_position`` (manifest sweeps); None = the capture's light.
    """

    name: str
    files: tuple = ()
    n_frames: int = 0
    times_s: tuple = ()
    axis: str = None
    direction_deg: float = None
    speed: float = None
    light: tuple = None


@dataclass(frozen=True)
class CapturePlan:
    """Facts of one capture, derived from its manifest before anything runs.

    Attributes
    ----------
    name : str
        Dataset name (the manifest's ``name``).
    manifest_path : str
        Absolute path of the manifest.
    kind : str
        ``lab`` or ``outdoor``.
    rendered : bool
        The capture is rendered from the manifest's ``synthetic:`` block.
    sweeps : mapping of str to SweepPlan
        Every sweep of the capture, in manifest order.
    frame_shape : (2,) tuple of int
        ``(rows, cols)`` of the frames (the first frame of the first sweep).
    timing : mapping
        The manifest's ``timing`` entry (empty for a rendered capture).
    reference : tuple of str
        Absolute paths of the unshadowed reference frame(s) (empty if none or rendered).
    has_reference : bool
        The capture has an unshadowed reference frame (a rendered one always has).
    has_ground_truth : bool
        Rendered, or the manifest has a ``ground_truth`` entry.
    has_calibration : bool
        Both calibration sweeps and the ``calibration_plane`` exist.
    dual_model : str or None
        ``uniform`` or ``calibration``: the dual-coordinate model that runs (lab with both
        scene sweeps only).
    scene_sweeps : tuple of str
        The scene sweeps of a lab capture: ``u, v``, or the one of a single-sweep capture
        (empty outdoors).
    camera_model : str or None
        Lab: the shadow camera the scene sweeps make, a key of
        :data:`shadowcam.cameras.models.CAMERA_MODELS` (``perspective``, ``orthographic``,
        ``linear``, ``cross_slit`` or ``pushbroom``).
    camera : mapping
        Lab: the capture description the camera models read (``light``, ``sweeps``:
        declarations ``name, angle_deg, speed, frames`` and ``light_offset`` per scene
        sweep) plus, for a rendered camera block, ``primal`` and ``optics``.
    stages : tuple of str
        Lab stages after the shadow times that the capture supports: ``dual_coords,
        dual_view`` with both scene sweeps, ``pushbroom`` with one (empty outdoors).
    timed_sweeps : tuple of str
        Sweeps whose shadow times are estimated: the scene sweeps and, when the
        calibration model runs, ``cal_u, cal_v`` (lab only; empty outdoors).
    outdoor_sweep : str or None
        The time-lapse sweep (outdoor only).
    strip_halo : int
        Halo columns each side of an edge-tracking strip, for
        :data:`PLANNED_SHIFT_COLUMNS` of camera shake (outdoor only; 0 for lab).
    lightfield : mapping or None
        :func:`lightfield_facts` of a ``kind: lightfield`` capture (else None).
    camera_array : mapping or None
        A virtual camera array, else None; its stages are ``camera_array`` only. Rendered:
        the ``synthetic.camera_array`` block (``rows``, ``cols``, ``spacing_frames``,
        ``radius_frames``) and the scene's ``frames`` (the light's steps across the mask
        plane). Captured (top-level ``camera_array``, sweeps :data:`ARRAY_SWEEPS`):
        ``rows``, ``cols``, ``spacing_frames`` (None = estimated from the frames),
        ``crossings`` (paths, row-major) and ``ground_truth`` (path or None). Both:
        ``images``, the frames and crossing images the array reads (rendered: at most,
        both experiments taken as long as the wider family's).
    light_set : mapping or None
        A capture lit by several lights, else None; its stages are ``light_views`` only (one
        shadow camera per light). Both: ``kinds`` (point or tube, per light), ``count`` and
        ``frames`` (the longer sweep's). Rendered: ``lights`` (the ``synthetic.lights``
        entries). Captured (top-level ``lights``, sweeps u and v, a reference frame):
        ``light_along_u``, ``light_along_v`` (the described positions, tuples, or None when
        the lights are numbered in the order of their shadows) and ``ground_truth`` (path or
        None).
    """

    name: str
    manifest_path: str
    kind: str
    rendered: bool
    sweeps: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    frame_shape: tuple = (0, 0)
    timing: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    reference: tuple = ()
    has_reference: bool = False
    has_ground_truth: bool = False
    has_calibration: bool = False
    dual_model: str = None
    scene_sweeps: tuple = ()
    camera_model: str = None
    camera: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    stages: tuple = ()
    timed_sweeps: tuple = ()
    outdoor_sweep: str = None
    strip_halo: int = 0
    lightfield: MappingProxyType = None
    camera_array: MappingProxyType = None
    light_set: MappingProxyType = None

    @property
    def is_lightfield(self):
        """True for a light-field capture (manifest ``kind: lightfield``)."""
        return self.kind == "lightfield"

    @property
    def is_outdoor(self):
        """True for an outdoor time-lapse (manifest ``kind: outdoor``)."""
        return self.kind == "outdoor"

    @property
    def uses_calibration(self):
        """True if the calibration sweeps are decoded and timed (the calibration model runs)."""
        return self.dual_model == "calibration"

    @property
    def single_sweep(self):
        """True for a lab capture with one scene sweep (its camera is the shadow pushbroom)."""
        return len(self.scene_sweeps) == 1

    @property
    def megapixels(self):
        """Megapixels of one frame (float)."""
        return self.frame_shape[0] * self.frame_shape[1] / 1e6

    def n_frames(self, sweep):
        """Return the frame count of `sweep` (int); ValueError naming the sweep if unknown."""
        return self.sweep(sweep).n_frames

    def sweep(self, name):
        """Return the :class:`SweepPlan` of sweep `name`; ValueError naming it if unknown."""
        if name not in self.sweeps:
            raise ValueError(
                f"sweep {name!r} is not a sweep of manifest {self.manifest_path}; available: {list(self.sweeps)}"
            )
        return self.sweeps[name]




def _tracker_margin():
    from shadowcam.outdoor.tracking import EdgeTracker

    return inspect.signature(EdgeTracker).parameters["margin"].default


def _planned_halo(margin):
    from shadowcam.outdoor.strips import strip_halo

    shift = np.array([[0.0, float(PLANNED_SHIFT_COLUMNS)]])
    return strip_halo(shift, margin=_tracker_margin() if margin is None else int(margin))


def _rendered_sweeps(manifest):
    synthetic = manifest["synthetic"]
    if manifest["kind"] == "outdoor":
        names = (OUTDOOR_SWEEP,)
    else:
        names = SCENE_SWEEPS + (CALIBRATION_SWEEPS if synthetic.get("calibration", False) else ())
    direction = {"u": 0.0, "v": 90.0}
    return {name: SweepPlan(name=name, n_frames=int(synthetic["frames"]),
                            direction_deg=direction.get(name),
                            speed=1.0 if name in direction else None)
            for name in names}


def _rendered_camera_sweeps(manifest, path):
    """Sweeps of a ``synthetic.camera`` block; frame counts cross the rendered dual field."""
    from shadowcam.cameras.models import frames_to_cross

    synthetic = manifest["synthetic"]
    n = int(synthetic["frames"])  # the rendered mask plane has a frames x frames dual grid
    sweeps = {}
    for index, entry in enumerate(synthetic["camera"]["sweeps"]):
        name = entry["name"]
        if name in sweeps:
            raise ValueError(f"manifest {path}: key 'synthetic.camera.sweeps[{index}].name': "
                             f"duplicate sweep name {name!r}; give each sweep its own name")
        offset = entry.get("light_offset")
        if offset is not None and manifest["light"] == "distant":
            raise ValueError(f"manifest {path}: key 'synthetic.camera.sweeps[{index}]"
                             ".light_offset' shifts a point or area light, but 'light' is "
                             "distant; use light: point (or area) for a cross-slit camera")
        angle, speed = float(entry.get("direction_deg", 0.0)), float(entry.get("speed", 1.0))
        sweeps[name] = SweepPlan(
            name=name, n_frames=frames_to_cross((n, n), angle, speed), direction_deg=angle,
            speed=speed, light=None if offset is None else tuple(float(x) for x in offset))
    if synthetic.get("calibration", False):
        for name in list(sweeps):
            sweeps[f"cal_{name}"] = SweepPlan(name=f"cal_{name}", n_frames=sweeps[name].n_frames)
    return sweeps


def _user_sweeps(manifest):
    out = {}
    for name, entry in manifest["sweeps"].items():
        default = {"u": 0.0, "v": 90.0}.get(name)
        scene = name in SCENE_SWEEPS or entry.get("direction_deg") is not None
        light = entry.get("light_position")
        out[name] = SweepPlan(
            name=name,
            files=tuple(entry["paths"]),
            n_frames=len(entry["paths"]),
            times_s=tuple(float(t) for t in entry["times_s"]),
            axis=entry.get("axis"),
            direction_deg=float(entry.get("direction_deg", default)) if scene else None,
            speed=float(entry.get("speed", 1.0)) if scene else None,
            light=None if light is None else tuple(float(x) for x in light),
        )
    return out


def _scene_sweep_names(sweeps):
    """Scene sweeps of a lab capture: u, v, then the others with a direction (manifest order)."""
    named = tuple(s for s in SCENE_SWEEPS if s in sweeps)
    others = tuple(n for n, s in sweeps.items() if n not in SCENE_SWEEPS
                   and s.direction_deg is not None and not n.startswith("cal_"))
    return named + others


def _camera(manifest, sweeps, scene, path):
    """The capture description of the scene sweeps and the camera model it needs (checked)."""
    from shadowcam.cameras.models import choose_camera_model

    rendered = "synthetic" in manifest
    block = manifest["synthetic"].get("camera", {}) if rendered else {}
    key = "synthetic.camera.sweeps" if block else "sweeps"
    own = [name for name in scene if sweeps[name].light is not None]
    if own and len(own) != len(scene) and not rendered:
        raise ValueError(
            f"manifest {path}: key 'sweeps.<name>.light_position' is given for sweeps {own} "
            f"but not for {[n for n in scene if n not in own]}; give every scene sweep its "
            "light position (cross-slit camera) or none (one light)")
    declared = []
    for name in scene:
        sweep = sweeps[name]
        declaration = {"name": name, "angle_deg": sweep.direction_deg, "speed": sweep.speed,
                       "frames": sweep.n_frames}
        if sweep.light is not None:
            declaration["light_offset"] = list(sweep.light)
        declared.append(declaration)
    description = {"light": manifest["light"], "sweeps": declared}
    if block:
        description.update(primal=block.get("primal", "perspective"),
                           optics=block.get("optics", "none"))
    try:
        model = choose_camera_model(description, block.get("model", "auto"))
    except ValueError as err:
        text = str(err).replace("description.sweeps", "sweeps").replace(
            "description.light", "light")
        raise ValueError(f"manifest {path}: key '{key}': {text}") from None
    return model, description


def _lightfield_error(path, key, problem, fix):
    return ValueError(f"manifest {path}: key {key} {problem}; {fix}")


def _bracket_times(entry, default, exposure, *, path, key):
    times = entry.get("exposure_times_s", default)
    if times is not None:
        return tuple(float(t) for t in times)
    if exposure.get("source") == "metadata" and "brackets" in exposure:
        return (None,) * int(exposure["brackets"])
    raise _lightfield_error(
        path, f"'{key}.exposure_times_s'", "is missing: the bracket exposure times are not known",
        "list them in seconds (lightfield.exposure_times_s), or set lightfield.exposure: "
        "{source: metadata, brackets: N} to read them from the files",
    )


def lightfield_facts(manifest):
    """The screens, sweeps and brackets of a ``kind: lightfield`` manifest.

    Parameters
    ----------
    manifest : dict
        As :func:`shadowcam.io.manifest.load_manifest` returns it.

    Returns
    -------
    sweeps : dict of str to SweepPlan
        ``<screen id>_h`` and ``<screen id>_v`` of every screen, nearest screen first.
    facts : dict
        ``screens`` (tuple of dicts: ``id``, ``position_mm``, ``homography`` (3x3 list or
        None), ``markers`` (or None), ``sweeps`` (suffix -> sweep name), ``exposure_times_s``),
        ``brackets`` (exposures per frame), ``exposure_source`` (``manifest`` or
        ``metadata``; times None for the latter) and ``mask`` (``position_mm``,
        ``start_mm``, ``step_mm``; None for a rendered capture) and ``camera``
        (``gain_dn_per_e``, ``read_noise_dn``, each 1.0 unless given; ``given`` lists the
        keys the manifest sets).

    Raises
    ------
    ValueError
        Naming the manifest and the key, with the fix: fewer than two screens, a screen
        without ``position_m`` (or a duplicate one) or, captured, without ``homography``
        or ``markers`` or without its two sweeps; no exposure times; brackets of
        different sizes (screens with different bracket counts, or a sweep whose file
        count is not a multiple of the bracket size); a captured light field without ``mask``.
    """
    path = manifest["manifest_path"]
    rendered = "synthetic" in manifest
    block = manifest.get("lightfield") or {}
    entries = block.get("screens") or []
    if len(entries) < 2:
        raise _lightfield_error(path, "'lightfield.screens'", f"lists {len(entries)} screen(s)",
                                "a light field needs two screen positions: add an entry "
                                "{id, position_m, homography} per screen")
    exposure = dict(block.get("exposure") or {})
    screens = []
    for i, entry in enumerate(entries):
        key = f"lightfield.screens[{i}]"
        sid = entry.get("id", f"screen{i}")
        if "position_m" not in entry:
            raise _lightfield_error(path, f"'{key}.position_m'", f"is missing (screen {sid!r})",
                                    "add the screen's distance from the source along the axis, in metres")
        if not entry["position_m"] > 0:
            raise _lightfield_error(path, f"'{key}.position_m'", f"is {entry['position_m']!r}",
                                    "give the screen's distance from the source in metres (> 0)")
        if not rendered and "homography" not in entry and "markers" not in entry:
            raise _lightfield_error(path, f"'{key}'", "has neither 'homography' nor 'markers'",
                                    "give the camera-pixel -> screen-mm homography or four screen markers")
        times = _bracket_times(entry, block.get("exposure_times_s"), exposure, path=path, key=key)
        screens.append({"id": sid, "position_mm": 1e3 * float(entry["position_m"]),
                        "homography": entry.get("homography"), "markers": entry.get("markers"),
                        "sweeps": {suffix: f"{sid}_{suffix}" for suffix in LIGHTFIELD_SWEEPS},
                        "exposure_times_s": times})
    positions = [s["position_mm"] for s in screens]
    if len(set(positions)) != len(positions):
        raise _lightfield_error(path, "'lightfield.screens[*].position_m'", f"repeats a position ({positions} mm)",
                                "each screen needs its own distance from the source")
    sizes = {s["id"]: len(s["exposure_times_s"]) for s in screens}
    if len(set(sizes.values())) != 1:
        raise _lightfield_error(path, "'lightfield.screens[*].exposure_times_s'",
                                f"gives brackets of different sizes {sizes}",
                                "expose every frame of every screen with the same number of brackets")
    brackets = next(iter(sizes.values()))
    screens.sort(key=lambda s: s["position_mm"])
    sweeps = {}
    for screen in screens:
        for name in screen["sweeps"].values():
            if rendered:
                sweeps[name] = SweepPlan(name=name, n_frames=int(manifest["synthetic"]["frames"]))
                continue
            if name not in manifest["sweeps"]:
                raise _lightfield_error(path, "'sweeps'", f"has no sweep {name!r} (screen {screen['id']!r})",
                                        f"add sweeps {name}: {{files: ...}} with the screen's frames")
            entry = manifest["sweeps"][name]
            n_files = len(entry["paths"])
            if n_files == 0 or n_files % brackets:
                raise _lightfield_error(path, f"'sweeps.{name}'", f"has {n_files} files, not a multiple of the "
                                        f"{brackets} brackets per frame (brackets of different sizes)",
                                        "give every frame the same brackets, or fix the glob")
            sweeps[name] = SweepPlan(name=name, files=tuple(entry["paths"]), n_frames=n_files // brackets,
                                     times_s=tuple(float(t) for t in entry["times_s"][::brackets]))
    camera = dict(block.get("camera") or {})
    mask = block.get("mask")
    if not rendered and mask is None:
        raise _lightfield_error(path, "'lightfield.mask'", "is missing",
                                "give the mask plane's position_m and the wire's start_m and step_m")
    facts = {
        "screens": tuple(screens),
        "brackets": brackets,
        "exposure_source": "metadata" if screens[0]["exposure_times_s"][0] is None else "manifest",
        "mask": None if mask is None else {k.replace("_m", "_mm"): 1e3 * float(v) for k, v in mask.items()},
        "camera": {"gain_dn_per_e": float(camera.get("gain_dn_per_e", 1.0)),
                   "read_noise_dn": float(camera.get("read_noise_dn", 1.0)),
                   "footprint_variance_px2": float(camera.get("footprint_variance_px2", 1.0 / 12.0)),
                   "given": sorted(camera)},
    }
    return sweeps, facts


def _lightfield_plan(manifest):
    sweeps, facts = lightfield_facts(manifest)
    if "synthetic" in manifest:
        shape = (int(manifest["synthetic"]["height"]), int(manifest["synthetic"]["width"]))
    else:
        shape = check_capture_frames(manifest)
    return CapturePlan(
        name=manifest["name"],
        manifest_path=manifest["manifest_path"],
        kind="lightfield",
        rendered="synthetic" in manifest,
        sweeps=MappingProxyType(sweeps),
        frame_shape=shape,
        timing=MappingProxyType(dict(manifest.get("timing") or {})),
        has_ground_truth="synthetic" in manifest,
        stages=("hdr", "shadow_times", "rays", "renders", "exports"),
        timed_sweeps=tuple(sweeps),
        lightfield=MappingProxyType(facts),
    )


def _rendered_lab_plan(manifest, stage, **facts):
    """The plan of a rendered lab capture that runs one stage of its own (`facts`: its block)."""
    synthetic = manifest["synthetic"]
    return CapturePlan(
        name=manifest["name"],
        manifest_path=manifest["manifest_path"],
        kind="lab",
        rendered=True,
        frame_shape=(int(synthetic["height"]), int(synthetic["width"])),
        has_reference=True,
        has_ground_truth=True,
        stages=(stage,),
        **{key: MappingProxyType(value) for key, value in facts.items()},
    )


#: sweeps of a captured camera array: light moving along e_u, along e_v
ARRAY_SWEEPS = ("horizontal", "vertical")


def _camera_array_plan(manifest):
    path = manifest["manifest_path"]
    rendered = "synthetic" in manifest and "camera_array" in manifest["synthetic"]
    key = "synthetic.camera_array" if rendered else "camera_array"
    if manifest["kind"] != "lab":
        raise ValueError(f"manifest {path}: key '{key}' needs kind: lab; got kind: {manifest['kind']}")
    if rendered:
        synthetic = manifest["synthetic"]
        array = {"radius_frames": 0.6, **synthetic["camera_array"], "frames": int(synthetic["frames"])}
        spread = float(array["spacing_frames"]) * (max(array["rows"], array["cols"]) - 1) + 1
        array["images"] = int(2 * (array["frames"] + spread) + array["rows"] * array["cols"])
        return _rendered_lab_plan(manifest, "camera_array", camera_array=array)
    block = manifest["camera_array"]
    missing = [name for name in ARRAY_SWEEPS if name not in manifest["sweeps"]]
    if missing:
        raise ValueError(f"manifest {path}: key 'sweeps' has no sweep {missing[0]!r}; a camera array needs "
                         "sweep horizontal (light moving along e_u) and sweep vertical (along e_v), each "
                         "{files: <glob>}")
    rows, cols, crossings = int(block["rows"]), int(block["cols"]), tuple(block["paths"])
    if len(crossings) != rows * cols:
        raise ValueError(f"manifest {path}: key 'camera_array.crossings' gives {len(crossings)} images but "
                         f"rows x cols = {rows} x {cols} wire crossings need {rows * cols}; give one image "
                         "per crossing (row-major over wire row, wire column) or fix rows/cols")
    shape = check_capture_frames(manifest)
    first = manifest["sweeps"][ARRAY_SWEEPS[0]]["paths"][0]
    check_frame_files(crossings, what=f"manifest {path}, key 'camera_array.crossings'", first=first)
    sweeps = {name: SweepPlan(name=name, files=tuple(manifest["sweeps"][name]["paths"]),
                              n_frames=len(manifest["sweeps"][name]["paths"]),
                              times_s=tuple(float(t) for t in manifest["sweeps"][name]["times_s"]))
              for name in ARRAY_SWEEPS}
    truth = manifest.get("ground_truth")
    array = {"rows": rows, "cols": cols, "spacing_frames": block.get("spacing_frames"),
             "crossings": crossings, "images": sum(s.n_frames for s in sweeps.values()) + len(crossings),
             "ground_truth": None if truth is None else str(Path(manifest["root"]) / truth["file"])}
    return CapturePlan(name=manifest["name"], manifest_path=path, kind="lab", rendered=False,
                       sweeps=MappingProxyType(sweeps), frame_shape=shape,
                       timing=MappingProxyType(dict(manifest.get("timing") or {})),
                       has_ground_truth=truth is not None, stages=("camera_array",),
                       camera_array=MappingProxyType(array))


def _light_positions(block, count, path):
    """The lights' described positions along the u and v sweeps (None, None when not given)."""
    along = {name: block.get(f"light_along_{name}") for name in SCENE_SWEEPS}
    given = [name for name, value in along.items() if value is not None]
    if len(given) == 1:
        other = next(name for name in SCENE_SWEEPS if name not in given)
        raise ValueError(f"manifest {path}: key 'lights.light_along_{given[0]}' is given but "
                         f"'lights.light_along_{other}' is not; the positions pair each light's shadows "
                         "of the two sweeps, so give both (one number per light) or neither (light k = "
                         "the k-th shadow to pass in both sweeps)")
    for name in given:
        values = [float(x) for x in along[name]]
        if len(values) != count:
            raise ValueError(f"manifest {path}: key 'lights.light_along_{name}' has {len(values)} positions "
                             f"but 'lights.kinds' declares {count} lights; give one position per light, "
                             "in the order of 'kinds'")
        if len(set(values)) != len(values):
            raise ValueError(f"manifest {path}: key 'lights.light_along_{name}' puts two lights at one "
                             f"position {values}: their shadows would pass together and cannot be told "
                             "apart; check the positions (lights level along a sweep need a sweep across)")
        along[name] = tuple(values)
    return along["u"], along["v"]


def _light_set_plan(manifest):
    path = manifest["manifest_path"]
    rendered = "lights" in manifest.get("synthetic", {})
    key = "synthetic.lights" if rendered else "lights"
    if manifest["kind"] != "lab" or (rendered and "camera" in manifest["synthetic"]):
        raise ValueError(f"manifest {path}: key '{key}' needs kind: lab and the standard u, v sweeps "
                         "(no synthetic.camera block)")
    if rendered:
        synthetic = manifest["synthetic"]
        entries = tuple(synthetic["lights"])
        lights = {"lights": entries, "kinds": tuple(e["kind"] for e in entries), "count": len(entries),
                  "frames": int(synthetic["frames"])}
        return _rendered_lab_plan(manifest, "light_views", light_set=lights)
    kinds = tuple(manifest["lights"]["kinds"])
    if len(kinds) < 2:
        said = "no light" if not kinds else "one light"
        raise ValueError(f"manifest {path}: key 'lights.kinds' declares {said}; the several-lights stage "
                         "needs two lights or more. A capture under one light is the standard lab capture: "
                         "remove the 'lights' block and its u, v sweeps run shadow_time, dual_coords and "
                         "dual_view")
    missing = [name for name in SCENE_SWEEPS if name not in manifest["sweeps"]]
    if missing:
        raise ValueError(f"manifest {path}: key 'sweeps' has no sweep {missing[0]!r}; a several-lights capture "
                         "needs the u and v sweeps (each {files: <glob>}) to give each light both dual "
                         "coordinates")
    if not manifest["reference_paths"]:
        raise ValueError(f"manifest {path}: key 'reference' is missing; the several-lights stage colours each "
                         "light's dual view from the unshadowed frame: add reference: <file> (all lights on, "
                         "no wire)")
    along_u, along_v = _light_positions(manifest["lights"], len(kinds), path)
    shape = check_capture_frames(manifest)
    sweeps = {name: SweepPlan(name=name, files=tuple(manifest["sweeps"][name]["paths"]),
                              n_frames=len(manifest["sweeps"][name]["paths"]),
                              times_s=tuple(float(t) for t in manifest["sweeps"][name]["times_s"]), axis=name)
              for name in SCENE_SWEEPS}
    truth = manifest.get("ground_truth")
    lights = {"kinds": kinds, "count": len(kinds), "light_along_u": along_u, "light_along_v": along_v,
              "frames": max(s.n_frames for s in sweeps.values()),
              "ground_truth": None if truth is None else str(Path(manifest["root"]) / truth["file"])}
    return CapturePlan(name=manifest["name"], manifest_path=path, kind="lab", rendered=False,
                       sweeps=MappingProxyType(sweeps), frame_shape=shape,
                       timing=MappingProxyType(dict(manifest.get("timing") or {})),
                       reference=tuple(manifest["reference_paths"]), has_reference=True,
                       has_ground_truth=truth is not None, stages=("light_views",),
                       light_set=MappingProxyType(lights))


def capture_plan(manifest_path, *, dual_model="auto", edge_margin=None):
    """Read a manifest into the plan of its capture.

    Parameters
    ----------
    manifest_path : str or Path
        ``data_manifest/<name>.yaml`` (or a renderer's ``capture.json``).
    dual_model : {"auto", "uniform", "calibration"}, optional
        Requested dual-coordinate model of a lab capture (see :func:`choose_dual_model`).
    edge_margin : int, optional
        Frame-differencing widening of the outdoor edge tracking (its ``margin``
        option; default the tracker's), for the strip halo.

    Returns
    -------
    CapturePlan

    Raises
    ------
    ValueError
        Naming the manifest and the key when the manifest does not match the
        schema, a file or glob it references is missing, its checksums block
        does not list a file, frame times cannot be resolved, a lab capture lacks
        a scene sweep (``u``, ``v`` or one with ``direction_deg``), the sweep geometry is
        inconsistent (all scene sweeps (nearly) parallel, ``light_position`` on some
        scene sweeps only, a requested camera model the sweeps cannot give, e.g.
        ``cross_slit`` without a light per sweep, a ``light_offset`` under a distant
        light, duplicate sweep names), an outdoor capture has several sweeps and
        none named ``timelapse``, `dual_model` is ``calibration`` without
        calibration sweeps, or the first frames of the sweeps and the reference
        differ in size (:func:`shadowcam.io.frame_files.check_capture_frames`); a captured
        camera array without sweep ``horizontal`` or ``vertical``, with crossing images
        missing or other than ``rows x cols`` of them, or with crossing images of another
        format or size than the frames (``rows``/``cols`` < 1 fail the schema); a captured
        several-lights capture (top-level ``lights``) with fewer than two lights, without
        sweep u or v or a reference frame, or with ``light_along_u``/``_v`` given for one
        sweep only, not one per light, or two lights at one position.
    """
    manifest = load_manifest(manifest_path)
    if manifest["kind"] == "lightfield":
        return _lightfield_plan(manifest)
    if "camera_array" in manifest or "camera_array" in manifest.get("synthetic", {}):
        return _camera_array_plan(manifest)
    if "lights" in manifest or "lights" in manifest.get("synthetic", {}):
        return _light_set_plan(manifest)
    path = manifest["manifest_path"]
    rendered = "synthetic" in manifest
    if rendered and "camera" in manifest["synthetic"] and manifest["kind"] == "lab":
        sweeps = _rendered_camera_sweeps(manifest, path)
    elif rendered:
        sweeps = _rendered_sweeps(manifest)
    else:
        sweeps = _user_sweeps(manifest)
    outdoor = manifest["kind"] == "outdoor"
    facts = {}
    if outdoor:
        names = list(sweeps)
        if OUTDOOR_SWEEP not in names and len(names) != 1:
            raise ValueError(
                f"manifest {path}: key 'sweeps' of an outdoor capture needs one sweep "
                f"(preferably named {OUTDOOR_SWEEP!r}); found {names}"
            )
        first = OUTDOOR_SWEEP if OUTDOOR_SWEEP in names else names[0]
        facts.update(outdoor_sweep=first, strip_halo=_planned_halo(edge_margin))
    else:
        scene = _scene_sweep_names(sweeps)
        if not scene:
            raise ValueError(
                f"manifest {path}: key 'sweeps' has no scene sweep; a lab capture needs sweep u "
                "(or v) for the shadow pushbroom, or both u and v for the dual view"
            )
        first = scene[0]
    calibration = all(s in sweeps for s in CALIBRATION_SWEEPS) and (rendered or "calibration_plane" in manifest)
    if not outdoor:
        camera_model, description = _camera(manifest, sweeps, scene, path)
        facts.update(scene_sweeps=scene, camera_model=camera_model,
                     camera=MappingProxyType(description))
    if not outdoor and len(scene) == 1:
        facts.update(stages=("pushbroom",), timed_sweeps=scene)
    elif not outdoor:
        model = choose_dual_model(
            dual_model,
            calibration_available=calibration,
            missing=f"the calibration sweeps cal_u, cal_v and calibration_plane in manifest {path}",
        )
        calibration_sweeps = tuple(f"cal_{name}" for name in scene if f"cal_{name}" in sweeps)
        facts.update(
            dual_model=model,
            stages=("dual_coords", "dual_view"),
            timed_sweeps=scene + (calibration_sweeps if model == "calibration" else ()),
        )
    if rendered:
        shape = (int(manifest["synthetic"]["height"]), int(manifest["synthetic"]["width"]))
    else:
        shape = check_capture_frames(manifest)
    return CapturePlan(
        name=manifest["name"],
        manifest_path=path,
        kind=manifest["kind"],
        rendered=rendered,
        sweeps=MappingProxyType(sweeps),
        frame_shape=shape,
        timing=MappingProxyType(dict(manifest.get("timing") or {})),
        reference=tuple(manifest["reference_paths"]),
        has_reference=rendered or bool(manifest["reference_paths"]),
        has_ground_truth=rendered or "ground_truth" in manifest,
        has_calibration=calibration,
        **facts,
    )


def footprint_variance(manifest):
    """A lab capture's pixel footprint variance, px^2 per axis, as its description declares it.

    Parameters
    ----------
    manifest : dict
        A loaded manifest (:func:`shadowcam.io.manifest.load_manifest`).

    Returns
    -------
    float or None
        ``sensor.footprint_variance_px2``; None where the description declares none (the
        dips are then taken as timed at the pixel centres).
    """
    value = (manifest.get("sensor") or {}).get("footprint_variance_px2")
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value) or value < 0:
        raise ValueError(f"manifest {manifest.get('manifest_path', '')}: key 'sensor.footprint_variance_px2' "
                         f"must be a number >= 0 (px^2); got {value!r}: give the footprint's per-axis "
                         "second moment (1/12 for a box pixel) or leave the key out")
    return float(value)
