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
pushbroom (one scene sweep), and the halo of an edge-tracking strip.

A manifest with a ``synthetic:`` block (and no ``sweeps``) describes a capture
the renderer writes; its plan takes the frame count and shape from that block
and has no files yet.

Offers
------
SCENE_SWEEPS : the two perpendicular scene sweeps of a lab capture.
CALIBRATION_SWEEPS : the calibration-plane sweeps of a lab capture.
OUTDOOR_SWEEP : preferred name of the time-lapse sweep of an outdoor capture.
PLANNED_SHIFT_COLUMNS : camera shake (columns) the planned strip halo allows for.
SweepPlan : one sweep: name, files, frame count, frame times, axis.
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
#: dual-coordinate models that may be requested ("auto" picks one of the other two)


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
    """

    name: str
    files: tuple = ()
    n_frames: int = 0
    times_s: tuple = ()
    axis: str = None


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
    return {name: SweepPlan(name=name, n_frames=int(synthetic["frames"])) for name in names}


def _user_sweeps(manifest):
    return {
        name: SweepPlan(
            name=name,
            files=tuple(entry["paths"]),
            n_frames=len(entry["paths"]),
            times_s=tuple(float(t) for t in entry["times_s"]),
            axis=entry.get("axis"),
        )
        for name, entry in manifest["sweeps"].items()
    }


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
        a scene sweep (``u`` or ``v``), an outdoor capture has several sweeps and
        none named ``timelapse``, `dual_model` is ``calibration`` without
        calibration sweeps, or the first frames of the sweeps and the reference
        differ in size (:func:`shadowcam.io.frame_files.check_capture_frames`).
    """
    manifest = load_manifest(manifest_path)
    path = manifest["manifest_path"]
    rendered = "synthetic" in manifest
    sweeps = _rendered_sweeps(manifest) if rendered else _user_sweeps(manifest)
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
        scene = tuple(s for s in SCENE_SWEEPS if s in sweeps)
        if not scene:
            raise ValueError(
                f"manifest {path}: key 'sweeps' has no scene sweep; a lab capture needs sweep u "
                "(or v) for the shadow pushbroom, or both u and v for the dual view"
            )
        first = scene[0]
    calibration = all(s in sweeps for s in CALIBRATION_SWEEPS) and (rendered or "calibration_plane" in manifest)
    if not outdoor and len(scene) == 1:
        facts.update(scene_sweeps=scene, stages=("pushbroom",), timed_sweeps=scene)
    elif not outdoor:
        model = choose_dual_model(
            dual_model,
            calibration_available=calibration,
            missing=f"the calibration sweeps cal_u, cal_v and calibration_plane in manifest {path}",
        )
        facts.update(
            dual_model=model,
            scene_sweeps=SCENE_SWEEPS,
            stages=("dual_coords", "dual_view"),
            timed_sweeps=SCENE_SWEEPS + (CALIBRATION_SWEEPS if model == "calibration" else ()),
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
