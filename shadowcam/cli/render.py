"""``shadowcam render``: render a synthetic capture (frames, GT, capture.json): lab or outdoor.

Usage::

    shadowcam render --manifest data_manifest/X.yaml --out results/X/capture
    shadowcam render --scene tabletop --seed 1 --height 192 --width 192 --frames 96 \\
        --format dng --bit-depth 12 [--no-noise] [--calibration] --out DIR

The manifest's ``synthetic`` block (docs/contracts.md) gives the options; explicit flags
override it. Outdoor captures (manifest ``kind: outdoor`` or scene ``ridge``, options in
``synthetic.outdoor``) are written by :mod:`shadowcam.cli.render_outdoor`; the rest of this
docstring describes lab captures. DIR receives ``frames_u/000000.dng ...``, ``frames_v/``, ``cal_u/``, ``cal_v/``
(with calibration), ``reference.dng``, ``ground_truth.nc`` and ``capture.json`` (the capture
description in the manifest structure). Everything is written to a temporary sibling
directory first and renamed into place at the end, so a killed run leaves no half capture.
"""

import argparse
import contextlib
import datetime
import json
import logging
import os
import shutil
import time
from pathlib import Path

import numpy as np

from shadowcam import __version__
from shadowcam.io.provenance import attach_provenance, file_sha256

log = logging.getLogger(__name__)

#: option -> default when neither the manifest nor a flag gives it
DEFAULTS = {
    "scene": "tabletop", "seed": 0, "height": 192, "width": 192, "frames": 96,
    "format": "dng", "bit_depth": 12, "noise": True, "calibration": False,
    "light": "point", "supersample": 4, "exposure": 0.8, "outdoor": None,
}
#: scenes rendered by the outdoor branch
OUTDOOR_SCENES = ("ridge",)
FORMATS = ("dng", "tiff")
BIT_DEPTHS = (8, 10, 12, 14, 16)
#: capture start time written into the DNGs; frame k of every sweep is k seconds later
CAPTURE_START = datetime.datetime(2024, 1, 1, 0, 0, 0)


def add_parser(subparsers, name):
    """Register the ``render`` step and return its parser."""
    p = subparsers.add_parser(name, help="render a synthetic lab or outdoor capture",
                              description=__doc__,
                              formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--manifest", type=Path, help="data_manifest YAML with a 'synthetic' block")
    p.add_argument("--out", type=Path, required=True, help="output capture directory")
    p.add_argument("--name", help="capture name (default: manifest name or scene_seed)")
    p.add_argument("--scene", help=f"preset scene (default {DEFAULTS['scene']})")
    p.add_argument("--seed", type=int, help="scene and noise seed")
    p.add_argument("--height", type=int, help="image rows")
    p.add_argument("--width", type=int, help="image cols")
    p.add_argument("--frames", type=int, help="frames per sweep (= dual grid size)")
    p.add_argument("--format", choices=FORMATS, help="frame format")
    p.add_argument("--bit-depth", type=int, choices=BIT_DEPTHS, help="sensor bit depth")
    p.add_argument("--no-noise", dest="noise", action="store_const", const=False,
                   help="noise-free frames (mean DN, rounded)")
    p.add_argument("--calibration", action=argparse.BooleanOptionalAction,
                   default=None, help="also render the calibration-plane sweeps cal_u, cal_v")
    p.add_argument("--light", choices=("point", "area", "distant"),
                   help="light type (default: the manifest's 'light', else point)")
    p.add_argument("--supersample", type=int, help="sub-samples per pixel side (default 4)")
    p.add_argument("--exposure", type=float,
                   help="fraction of the DN range reached by the 99.5th percentile of the "
                        "reference (default 0.8)")
    return p


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
    unknown = set(block) - set(DEFAULTS)
    if unknown:
        log.warning("manifest %s: ignoring unknown key(s) in 'synthetic': %s", path,
                    sorted(unknown))
        block = {k: v for k, v in block.items() if k in DEFAULTS}
    return manifest, block


def resolve_options(args):
    """Merge defaults, the manifest's ``synthetic`` block and explicit flags.

    Returns
    -------
    options : dict
        Keys of ``DEFAULTS`` plus ``name``, ``kind``, ``description``.
    """
    options = dict(DEFAULTS)
    manifest = {}
    if args.manifest is not None:
        manifest, block = _read_synthetic_block(args.manifest)
        block.pop("light", None)
        options.update(block)
        if manifest.get("light") is not None:  # the light type is a top-level manifest key
            options["light"] = manifest["light"]
    for key in DEFAULTS:
        value = getattr(args, key, None)
        if value is not None:
            options[key] = value
    if options["format"] not in FORMATS:
        raise ValueError(f"format: must be one of {FORMATS}, got {options['format']!r}")
    if options["bit_depth"] not in BIT_DEPTHS:
        raise ValueError(f"bit_depth: must be one of {BIT_DEPTHS}, got {options['bit_depth']!r}")
    for key in ("height", "width"):
        if options["format"] == "dng" and int(options[key]) < 22:
            raise ValueError(f"{key}: DNG frames need at least 22 pixels (LibRaw limit)")
    options["name"] = (args.name or manifest.get("name")
                       or f"synthetic_{options['scene']}_{options['seed']}")
    options["kind"] = manifest.get(
        "kind", "outdoor" if options["scene"] in OUTDOOR_SCENES else "lab")
    options["description"] = manifest.get(
        "description", f"synthetic {options['kind']} capture of scene {options['scene']!r}")
    return options


def _write_frame(path, radiance, *, options, sensor, scale, seed, when, exposure_time=None):
    from shadowcam.io.raw_writer import write_dng, write_tiff16
    from shadowcam.synthetic.sensor import raw_to_linear, simulate_raw

    if options["format"] == "dng":
        raw = simulate_raw(radiance, sensor=sensor, scale=scale, seed=seed,
                           noise=options["noise"], mosaic=True)
        write_dng(path, raw, bit_depth=sensor.bit_depth, black_level=sensor.black_level,
                  capture_time=when, exposure_time=exposure_time)
    else:
        dn = simulate_raw(radiance, sensor=sensor, scale=scale, seed=seed,
                          noise=options["noise"], mosaic=False)
        linear = raw_to_linear(dn, sensor=sensor)
        write_tiff16(path, np.clip(np.rint(linear * 65535.0), 0, 65535).astype(np.uint16))


@contextlib.contextmanager
def staging_dir(out_dir):
    """Yield a temporary sibling of `out_dir`; on success rename it into place (replacing
    an old `out_dir`), on any error remove it, so no half-written capture is left."""
    out_dir = Path(out_dir)
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    tmp = out_dir.parent / f".{out_dir.name}.tmp-{os.getpid()}"
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir()
    try:
        yield tmp
        old = None
        if out_dir.exists():
            old = out_dir.parent / f".{out_dir.name}.old-{os.getpid()}"
            out_dir.rename(old)
        tmp.rename(out_dir)
        if old is not None:
            shutil.rmtree(old)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def write_ground_truth(folder, gt, *, sensor, scale, config, checksums, **attrs):
    """Write `gt` with the sensor's attrs, `attrs` and provenance as ``folder/ground_truth.nc``
    and add its checksum to `checksums` (which, before, lists the capture's frames)."""
    gt = gt.assign_attrs(
        electrons_per_unit_radiance=scale, black_level=sensor.black_level,
        white_level=sensor.white_level, read_noise_dn=sensor.read_noise,
        gain_dn_per_electron=sensor.gain, **attrs)
    gt = attach_provenance(gt, config=config, input_checksums=checksums, step="render")
    gt.to_netcdf(folder / "ground_truth.nc", engine="h5netcdf")
    checksums["ground_truth.nc"] = file_sha256(folder / "ground_truth.nc")


def render_capture_dir(options, out_dir):
    """Render a capture described by `options` (see ``resolve_options``) into `out_dir`."""
    from shadowcam.synthetic.lab.render import SWEEP_INDEX, prepare_capture
    from shadowcam.synthetic.lab.scene import make_scene
    from shadowcam.synthetic.sensor import SensorModel, electrons_per_unit_radiance

    started = time.perf_counter()
    scene = make_scene(options["scene"], seed=options["seed"], height=options["height"],
                       width=options["width"], frames=options["frames"],
                       light_kind=options["light"])
    renderer = prepare_capture(scene, supersample=options["supersample"],
                               calibration=options["calibration"])
    log.info("static rays cast in %.2f s", time.perf_counter() - started)
    sensor = SensorModel(bit_depth=options["bit_depth"])
    scale = electrons_per_unit_radiance(renderer.reference, sensor=sensor,
                           target_fraction=options["exposure"])
    ext = options["format"]
    seed = int(options["seed"])

    with staging_dir(out_dir) as tmp:
        written = []
        ref_name = f"reference.{ext}"
        _write_frame(tmp / ref_name, renderer.reference, options=options, sensor=sensor,
                     scale=scale, seed=[seed, SWEEP_INDEX["reference"], 0], when=CAPTURE_START)
        written.append(ref_name)
        sweeps = {}
        for name in renderer.sweep_names:
            folder = f"frames_{name}" if name in ("u", "v") else name
            (tmp / folder).mkdir()
            frames = renderer.frames(name)
            n = len(frames)
            for k in range(n):
                rel = f"{folder}/{k:06d}.{ext}"
                when = CAPTURE_START + datetime.timedelta(seconds=k)
                _write_frame(tmp / rel, frames[k], options=options, sensor=sensor,
                             scale=scale, seed=[seed, SWEEP_INDEX[name], k], when=when)
                written.append(rel)
                if (k + 1) % max(1, n // 4) == 0 or k + 1 == n:
                    log.info("sweep %s: %d/%d frames written", name, k + 1, n)
            sweeps[name] = {"files": f"{folder}/*.{ext}", "axis": name.removeprefix("cal_")}
            del frames
        checksums = {rel: file_sha256(tmp / rel) for rel in written}
        config = {k: options[k] for k in DEFAULTS}
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
        with open(tmp / "capture.json", "w") as handle:
            json.dump(capture, handle, indent=2)
            handle.write("\n")
    log.info("capture %s written to %s in %.2f s", options["name"], out_dir,
             time.perf_counter() - started)
    return out_dir


def run(args):
    """Run the ``render`` step."""
    if args.manifest is None and args.scene is None:
        raise ValueError("give --manifest (with a 'synthetic' block) or --scene")
    options = resolve_options(args)
    if options["kind"] == "outdoor":
        from shadowcam.cli.render_outdoor import render_outdoor_capture_dir

        render_outdoor_capture_dir(options, args.out)
    else:
        render_capture_dir(options, args.out)
