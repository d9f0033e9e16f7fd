"""Options of a synthetic capture: defaults, the manifest's ``synthetic`` block, overrides.

A synthetic dataset's manifest carries a ``synthetic`` block (docs/contracts.md);
outdoor captures add a ``synthetic.outdoor`` block. Explicit options (command-line
flags) override the manifest, which overrides the defaults.

Offers
------
DEFAULTS : option -> default of every capture.
OPTIONAL_KEYS : ``synthetic`` keys held only when the manifest gives them (camera, shutter).
OUTDOOR_OPTIONS : keys of the ``synthetic.outdoor`` block and their defaults.
FORMATS, BIT_DEPTHS : allowed frame formats and sensor bit depths.
capture_options : merge defaults, a manifest and overrides into validated options.
outdoor_options : merge the ``outdoor`` block over :data:`OUTDOOR_OPTIONS` (validated).
accuracy_condition : ``clean`` or ``nuisances`` (which accuracy targets apply) of an outdoor capture.
lab_scene_description : the scene description (``scene_from_description``) of lab options,
    with the manifest's ``synthetic.camera`` block (sweeps, primal camera, optics).
"""

import logging
from pathlib import Path

log = logging.getLogger(__name__)

#: option -> default when neither the manifest nor an override gives it
DEFAULTS = {
    "scene": "tabletop", "seed": 0, "height": 192, "width": 192, "frames": 96,
    "format": "dng", "bit_depth": 12, "noise": True, "calibration": False,
    "light": "point", "supersample": 4, "exposure": 0.8, "outdoor": None,
}
#: ``synthetic`` keys without a default that a capture's options hold only when given:
#: ``camera`` (the shadow camera to render), ``shutter`` (exposure of a lab frame as a
#: fraction of the frame interval; absent = an instant), ``wire_radius_frames`` (the wire's
#: radius in mask steps; absent = one), ``area_light`` (shape, size, samples of an area
#: light; absent = the preset's disc), ``camera_array`` (the static wire grid of a virtual
#: camera array, written by :func:`shadowcam.synthetic.lab.array_capture.write_array_capture`),
#: ``lights`` (several lights under the sweeps, written by
#: :func:`shadowcam.synthetic.lab.light_set_capture.write_light_set_capture`)
OPTIONAL_KEYS = ("camera", "shutter", "wire_radius_frames", "area_light", "camera_array", "lights")
#: optional keys that describe the lab scene (``scenes.DESCRIPTION_KEYS``)
SCENE_KEYS = ("wire_radius_frames", "area_light")
#: scenes rendered as outdoor time-lapses
OUTDOOR_SCENES = ("ridge",)
FORMATS = ("dng", "tiff")
BIT_DEPTHS = (8, 10, 12, 14, 16)
#: ``synthetic.outdoor`` keys -> defaults (ephemeris of dev_ridge, every nuisance on)
OUTDOOR_OPTIONS = {
    "latitude_deg": 35.0, "declination_deg": -18.0,
    "start_elevation_deg": 20.0, "end_elevation_deg": 1.5,
    "auto_exposure": True, "shake_px": 1.0, "cloud": True,
    "irregular_timing": True, "dropped_frames": 2,
    "base_exposure_s": 0.004, "sun_diameter_deg": 0.0, "window": None,
    "dng_compression": "none",
}


def _read_synthetic_block(path):
    import yaml

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"manifest {path} does not exist")
    with open(path) as handle:
        manifest = yaml.safe_load(handle)
    if not isinstance(manifest, dict):
        raise ValueError(f"manifest {path}: expected a mapping at top level")
    block = manifest.get("synthetic")
    if not isinstance(block, dict):
        raise ValueError(f"manifest {path}: key 'synthetic' is missing or not a mapping; "
                         "only synthetic datasets can be rendered")
    unknown = set(block) - set(DEFAULTS) - set(OPTIONAL_KEYS)
    if unknown:
        log.warning("manifest %s: ignoring unknown key(s) in 'synthetic': %s", path,
                    sorted(unknown))
        block = {k: v for k, v in block.items() if k in DEFAULTS}
    return manifest, block


def capture_options(manifest=None, *, name=None, **overrides):
    """Merge the defaults, the manifest's ``synthetic`` block and `overrides`.

    Parameters
    ----------
    manifest : str or Path, optional
        data_manifest YAML with a ``synthetic`` block; its top-level ``light``,
        ``name``, ``kind`` and ``description`` are used too.
    name : str, optional
        Capture name (default: the manifest's name, else ``synthetic_<scene>_<seed>``).
    **overrides
        Keys of :data:`DEFAULTS`; None means "not given".

    Returns
    -------
    options : dict
        Keys of :data:`DEFAULTS` plus ``name``, ``kind`` (``lab`` or ``outdoor``), ``description``
        and, when the manifest has one, ``camera`` (its ``synthetic.camera`` block).

    Raises
    ------
    ValueError
        On an unknown override, a format or bit depth not allowed, or a DNG smaller than 22 pixels.
    """
    unknown = set(overrides) - set(DEFAULTS)
    if unknown:
        raise ValueError(f"overrides: unknown option(s) {sorted(unknown)}; known: {sorted(DEFAULTS)}")
    options = dict(DEFAULTS)
    document = {}
    if manifest is not None:
        document, block = _read_synthetic_block(manifest)
        block.pop("light", None)
        options.update(block)
        if document.get("light") is not None:  # the light type is a top-level manifest key
            options["light"] = document["light"]
    options.update({key: value for key, value in overrides.items() if value is not None})
    if options["format"] not in FORMATS:
        raise ValueError(f"format: must be one of {FORMATS}, got {options['format']!r}")
    if options["bit_depth"] not in BIT_DEPTHS:
        raise ValueError(f"bit_depth: must be one of {BIT_DEPTHS}, got {options['bit_depth']!r}")
    for key in ("height", "width"):
        if options["format"] == "dng" and int(options[key]) < 22:
            raise ValueError(f"{key}: DNG frames need at least 22 pixels (LibRaw limit)")
    options["name"] = (name or document.get("name")
                       or f"synthetic_{options['scene']}_{options['seed']}")
    options["kind"] = document.get(
        "kind", "outdoor" if options["scene"] in OUTDOOR_SCENES else "lab")
    options["description"] = document.get(
        "description", f"synthetic {options['kind']} capture of scene {options['scene']!r}")
    return options


def outdoor_options(block):
    """Return :data:`OUTDOOR_OPTIONS` updated by `block` (the manifest's ``outdoor`` mapping)."""
    block = dict(block or {})
    unknown = set(block) - set(OUTDOOR_OPTIONS)
    if unknown:
        raise ValueError(f"synthetic.outdoor: unknown key(s) {sorted(unknown)}; "
                         f"known: {sorted(OUTDOOR_OPTIONS)}")
    return dict(OUTDOOR_OPTIONS, **block)


def accuracy_condition(noise, outdoor):
    """Accuracy-target condition of a rendered time-lapse: ``clean`` or ``nuisances``.

    A capture is clean when no nuisance of the issue's list is on: sensor noise,
    auto-exposure steps, shake, cloud, irregular intervals, dropped frames.
    """
    nuisances = (noise, outdoor["auto_exposure"], outdoor["shake_px"] > 0, outdoor["cloud"],
                 outdoor["irregular_timing"], outdoor["dropped_frames"] > 0)
    return "nuisances" if any(nuisances) else "clean"


def lab_scene_description(options):
    """The lab scene a capture's options ask for, as ``scene_from_description`` reads it.

    Parameters
    ----------
    options : dict
        :func:`capture_options` of a lab capture; its optional ``camera`` block (manifest
        ``synthetic.camera``: ``primal``, ``optics``, ``sweeps`` of ``{name, direction_deg,
        speed, light_offset}``) maps to the scene's ``camera``, ``optics`` and
        ``sweeps`` (wire angle = motion direction, motion perpendicular to the wire).

    Returns
    -------
    dict
        ``scene, seed, height, width, frames, light``, the ``wire_radius_frames`` and
        ``area_light`` the manifest gives and, with a camera block, ``camera``,
        ``sweeps`` and ``optics`` (None for ``none``).
    """
    description = {key: options[key] for key in ("scene", "seed", "height", "width", "frames",
                                                  "light")}
    description.update({key: options[key] for key in SCENE_KEYS if options.get(key) is not None})
    block = options.get("camera")
    if not block:
        return description
    specs = []
    for entry in block["sweeps"]:
        spec = {"name": entry["name"], "angle_deg": float(entry.get("direction_deg", 0.0)),
                "speed": float(entry.get("speed", 1.0))}
        if entry.get("light_offset") is not None:
            spec["light_offset"] = [float(x) for x in entry["light_offset"]]
        specs.append(spec)
    optics = block.get("optics", "none")
    description.update(camera=block.get("primal", "perspective"), sweeps=specs,
                       optics=None if optics == "none" else {"kind": optics})
    return description
