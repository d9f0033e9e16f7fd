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
PLANNED_SHIFT_COLUMNS : camera shake (columns) the planned strip halo allows for.
SweepPlan : one sweep: name, files, frame count, frame times, axis, geometry.
CapturePlan : the plan of one capture (frozen dataclass).
capture_plan : read a manifest into a :class:`CapturePlan`.
"""

import inspect
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

import numpy as np

from shadowcam.cameras.dual_coords import choose_dual_model
from shadowcam.io.frame_files import check_capture_frames
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
        differ in size (:func:`shadowcam.io.frame_files.check_capture_frames`).
    """
    manifest = load_manifest(manifest_path)
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
