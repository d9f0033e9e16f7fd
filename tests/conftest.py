"""Shared test fixtures: paths, the workflow runner and seeded synthetic-data factories.

Test modules import nothing from each other or from helper modules; everything they
share is a fixture here. Factories are session-scoped fixtures that return a function
(call it with the options the test needs); they are plain functions of their arguments
and seed, so they are safe inside hypothesis tests.

Offers
------
repo : path of the repository root.
shared_data : the shared dev data folder (``REPO.parent / "shared" / "data"``, or
    ``$SHADOWCAM_SHARED_DATA``); skips when absent, fails when ``$CI`` is set.
workflow_copy(dest) : copy the workflow (Snakefile, rules, schemas, config, profiles,
    synthetic manifests) into `dest` so that it runs in a scratch working directory.
snakemake(args, cwd) : run the snakemake of this interpreter's environment, with the
    environment's ``bin`` (the ``shadowcam`` command) first on PATH.
write_manifest(path, doc) : write a capture manifest with the checksums of its files.
write_image(path, pixels, **attributes) : an image file in the pixels' own type (OpenImageIO).
write_pidng(path, mosaic, ...) : a 12-bit Bayer DNG written the way the shared dev data are (pidng).
make_frames(folder, count, ...) : random 16-bit TIFF frames and their decoded float32 values.
make_capture(tmp_path, ...) : a capture folder and its manifest; rewrite(path, doc) rewrites it.
sweep_manifest(folder, rate_hz=...) : a lab manifest for the TIFF sweep ``folder/data/u``.
wire_sweep(...) : the seeded synthetic shadow sweep with its exact shadow times.
make_timelapse(...) : the seeded synthetic outdoor time-lapse with its exact arrival times.
make_lightfield_manifest(folder, ...) : a captured kind: lightfield manifest of rendered DNG brackets.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

REPO = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
WORKFLOW_FILES = ("Snakefile", "workflow", "config", "profiles")
SYNTHETIC_MANIFESTS = ("synthetic_tiny.yaml", "synthetic_lab.yaml", "synthetic_array.yaml",
                       "synthetic_lights.yaml", "synthetic_area.yaml")


# --------------------------------------------------------------------------- paths


@pytest.fixture(scope="session")
def repo():
    """The repository root."""
    return REPO


@pytest.fixture(scope="session")
def shared_data():
    """The shared dev data folder (``lab-dev``, ``outdoor-dev``).

    ``$SHADOWCAM_SHARED_DATA`` if set, else ``shared/data`` beside the repository (CI
    clones it there). Missing: a failure under CI (``$CI`` set), a skip elsewhere.
    """
    configured = os.environ.get("SHADOWCAM_SHARED_DATA")
    path = Path(configured) if configured else REPO.parent / "shared" / "data"
    if not path.is_dir():
        reason = (f"shared dev data not found at {path}: clone shared/ beside the repository "
                  f"or set SHADOWCAM_SHARED_DATA")
        if os.environ.get("CI"):
            pytest.fail(reason, pytrace=False)
        pytest.skip(reason)
    return path


# --------------------------------------------------------------------------- workflow


def _workflow_copy(dest):
    """Copy the workflow and the synthetic manifests into `dest`; return `dest` as a Path."""
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    for name in WORKFLOW_FILES:
        source = REPO / name
        if source.is_dir():
            shutil.copytree(source, dest / name, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy2(source, dest / name)
    (dest / "data_manifest").mkdir(exist_ok=True)
    for name in SYNTHETIC_MANIFESTS:
        shutil.copy2(REPO / "data_manifest" / name, dest / "data_manifest" / name)
    return dest


def _snakemake(args, cwd, *, timeout=600):
    """Run ``snakemake *args`` in `cwd`; return the CompletedProcess (stdout+stderr in .stdout)."""
    env = dict(os.environ, PATH=f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}")
    return subprocess.run(
        [str(BIN / "snakemake"), *args], cwd=cwd, env=env, timeout=timeout,
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )


def _write_manifest(path, doc):
    """Write manifest `doc` (a dict) to `path` with a ``checksums`` block of its files; return `path`."""
    from shadowcam.io.manifest import checksums_for

    path = Path(path)
    path.write_text(yaml.safe_dump(doc))
    path.write_text(yaml.safe_dump({**doc, "checksums": checksums_for(path)}))
    return path


@pytest.fixture(scope="session")
def workflow_copy():
    return _workflow_copy


@pytest.fixture(scope="session")
def snakemake():
    return _snakemake


@pytest.fixture(scope="session")
def write_manifest():
    return _write_manifest


# --------------------------------------------------------------------------- image files


def _write_image(path, pixels, **attributes):
    """Write `pixels` (H, W, C) in their own integer/float type with OpenImageIO."""
    import OpenImageIO as oiio

    type_name = {"float32": "float", "float16": "half"}.get(str(pixels.dtype), str(pixels.dtype))
    spec = oiio.ImageSpec(pixels.shape[1], pixels.shape[0], pixels.shape[2], type_name)
    for key, value in attributes.items():
        spec.attribute(key, value)
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec), oiio.geterror()
    assert out.write_image(pixels)
    out.close()
    return path


def _write_dng(path, mosaic, *, pattern="RGGB", black=256, white=4095, exposure=None, stamp=None):
    """12-bit uncompressed DNG as the shared dev data are written (pidng)."""
    from pidng.core import RAW2DNG, DNGTags, Tag
    from pidng.defs import CalibrationIlluminant, CFAPattern, DNGVersion, Orientation, PhotometricInterpretation

    height, width = mosaic.shape
    tags = DNGTags()
    identity = [[1, 1], [0, 1], [0, 1], [0, 1], [1, 1], [0, 1], [0, 1], [0, 1], [1, 1]]
    for tag, value in [
        (Tag.ImageWidth, width), (Tag.ImageLength, height), (Tag.TileWidth, width), (Tag.TileLength, height),
        (Tag.Orientation, Orientation.Horizontal),
        (Tag.PhotometricInterpretation, PhotometricInterpretation.Color_Filter_Array),
        (Tag.SamplesPerPixel, 1), (Tag.BitsPerSample, 12), (Tag.CFARepeatPatternDim, [2, 2]),
        (Tag.CFAPattern, getattr(CFAPattern, pattern)), (Tag.BlackLevel, black), (Tag.WhiteLevel, white),
        (Tag.ColorMatrix1, identity), (Tag.CalibrationIlluminant1, CalibrationIlluminant.D65),
        (Tag.AsShotNeutral, [[1, 2], [1, 1], [1, 4]]),  # neutral (0.5, 1, 0.25) -> multipliers (2, 1, 4)
        (Tag.Make, "shadowcam test"), (Tag.Model, "synthetic RGGB"),
        (Tag.DNGVersion, DNGVersion.V1_4), (Tag.DNGBackwardVersion, DNGVersion.V1_2),
    ]:
        tags.set(tag, value)
    if exposure is not None:
        tags.set(Tag.ExposureTime, [exposure])
    if stamp is not None:
        tags.set(Tag.DateTimeOriginal, stamp)
    writer = RAW2DNG()
    writer.options(tags, path=str(path.parent), compress=False)
    writer.convert(mosaic.astype(np.uint16), filename=path.stem)
    return path


def _make_frames(folder, count, *, shape=(12, 10, 3), seed=0, **attributes):
    """`count` random 16-bit TIFF frames in `folder`; return their paths and float32 values."""
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    pixels = rng.integers(0, 65536, (count,) + shape).astype(np.uint16)
    paths = [_write_image(folder / f"{k:04d}.tif", pixels[k], **attributes) for k in range(count)]
    return paths, pixels.astype(np.float32) / np.float32(65535)


def _rewrite(path, doc):
    """Write `doc` to `path` as YAML (no checksums added); return `path`."""
    path.write_text(yaml.safe_dump(doc))
    return path


def _make_capture(tmp_path, *, names=("f8.png", "f9.png", "f10.png"), with_checksums=True, **overrides):
    """A capture folder data/ and a manifest manifests/cap.yaml with root ../data; return (path, doc)."""
    from shadowcam.io.manifest import checksums_for

    data = tmp_path / "data"
    (data / "u").mkdir(parents=True)
    rng = np.random.default_rng(5)
    for name in names:
        _write_image(data / "u" / name, rng.integers(0, 65536, (6, 8, 3)).astype(np.uint16))
    _write_image(data / "ref.png", np.full((6, 8, 3), 1000, np.uint16))
    doc = {
        "name": "cap",
        "kind": "lab",
        "light": "point",
        "root": "../data",
        "sweeps": {"u": {"files": "u/*.png", "axis": "u"}},
        "reference": "ref.png",
        "timing": {"source": "rate", "rate_hz": 2.0},
        "provenance": "test",
        "licence": "CC0-1.0",
    }
    doc.update(overrides)
    path = tmp_path / "manifests" / "cap.yaml"
    path.parent.mkdir(exist_ok=True)
    path.write_text(yaml.safe_dump(doc))
    if with_checksums:
        doc["checksums"] = checksums_for(path)
        path.write_text(yaml.safe_dump(doc))
    return path, doc


def _sweep_manifest(folder, *, rate_hz):
    """Write `folder`/cap.yaml describing sweep u = `folder`/data/u/*.tif, with checksums."""
    return _write_manifest(folder / "cap.yaml", {
        "name": "cap", "kind": "lab", "light": "point", "root": "data",
        "sweeps": {"u": {"files": "u/*.tif", "axis": "u"}}, "timing": {"source": "rate", "rate_hz": rate_hz}})


@pytest.fixture(scope="session")
def write_image():
    return _write_image


@pytest.fixture(scope="session")
def write_pidng():
    return _write_dng


@pytest.fixture(scope="session")
def make_frames():
    return _make_frames


@pytest.fixture(scope="session")
def make_capture():
    return _make_capture


@pytest.fixture(scope="session")
def rewrite():
    return _rewrite


@pytest.fixture(scope="session")
def sweep_manifest():
    return _sweep_manifest


# --------------------------------------------------------------------------- synthetic sweep


def _wire_sweep(*, n_frames=40, shape=(48, 64), px_per_frame=2.0, width=2.0, t0=6.0, tilt=0.3,
                supersample=8, centres=None, depth=1.0, ramp=0.0, level=None, albedo=None, seed=0,
                electrons=None, read_noise=0.0, noise=0.0, shadowed_box=None, dtype=np.float32):
    """A shadow sweeping a textured plane, and the exact time its centre passes each pixel.

    The shadow's centre line crosses image point (row y, col x) at time
    ``t0 + (x + tilt * y) / px_per_frame`` (pixel centres at integer + 0.5); the shadow
    is `width` frames wide (hard edged: point light, opaque wire) and removes `depth` of
    the light; `ramp` > 0 adds linear ramps of `ramp` frames at its edges (an area
    source's penumbra). Each pixel integrates ``supersample**2`` points.

    `centres` instead gives the shadow times directly (a time, a (rows, cols) array, or a
    list of them for several dips, with a list of `depth`), evaluated at the pixel (no
    sub-samples): a pure temporal dip profile.

    Radiance: `level` (a scalar: frames (T, H, W)), or `albedo` (H, W, 3), or the seeded
    random texture 0.3 to 0.9 (frames (T, H, W, 3)). `shadowed_box` (r0, r1, c0, c1) is a
    region in a scene object's cast shadow: never lit. Noise, after conversion to `dtype`:
    `electrons` (a 12-bit sensor, 1 DN per electron, white = 4095 DN, with Gaussian
    `read_noise` DN) or additive Gaussian `noise`.

    Returns frames and the exact shadow time at pixel centres (H, W), NaN outside the sweep
    (with `centres`: the first dip's times).
    """
    rng = np.random.default_rng(seed)
    h, w = shape
    if centres is None:
        offsets = (np.arange(supersample) + 0.5) / supersample
        ys = np.arange(h)[:, None, None, None] + offsets[None, None, :, None]
        xs = np.arange(w)[None, :, None, None] + offsets[None, None, None, :]
        dip_times = [t0 + (xs + tilt * ys) / px_per_frame]  # (H, W, s, s)
        gt = t0 + (np.arange(w)[None] + 0.5 + tilt * (np.arange(h)[:, None] + 0.5)) / px_per_frame
    else:
        centres = list(centres) if isinstance(centres, list) else [centres]
        dip_times = [np.broadcast_to(np.asarray(c, np.float64), shape)[..., None, None] for c in centres]
        gt = np.array(np.broadcast_to(np.asarray(centres[0] if centres else np.nan, np.float64), shape))
    depths = list(depth) if isinstance(depth, list) else [depth] * len(dip_times)
    if level is not None:
        base = level
    else:
        base = albedo if albedo is not None else 0.3 + 0.6 * rng.random((h, w, 3))
    frames = np.empty((n_frames,) + shape + ((3,) if np.ndim(base) == 3 else ()), dtype)
    for k in range(n_frames):
        removed = np.zeros(dip_times[0].shape if dip_times else shape + (1, 1))
        for t_dip, d in zip(dip_times, depths):
            dist = np.abs(k - t_dip) - width / 2
            cover = (dist < 0).astype(np.float64) if ramp == 0 else np.clip(0.5 - dist / ramp, 0, 1)
            removed += d * cover
        lit_fraction = (1 - np.clip(removed, 0, 1)).mean(axis=(2, 3))
        frames[k] = base * (lit_fraction[..., None] if np.ndim(base) == 3 else lit_fraction)
    if shadowed_box is not None:
        r0, r1, c0, c1 = shadowed_box
        frames[:, r0:r1, c0:c1] = 0
        gt[r0:r1, c0:c1] = np.nan
    gt[(gt < 0) | (gt > n_frames - 1)] = np.nan
    if electrons is not None:
        dn = rng.poisson(frames * electrons) + rng.normal(0, read_noise, frames.shape)
        frames = (np.clip(np.round(dn), -64, 4095) / 4095).astype(dtype)
    if noise:
        frames = frames + rng.normal(0, noise, frames.shape).astype(dtype)
    return frames, gt


@pytest.fixture(scope="session")
def wire_sweep():
    """The seeded synthetic shadow sweep factory: ``wire_sweep(**options) -> (frames, truth)``."""
    return _wire_sweep


# --------------------------------------------------------------------------- synthetic time-lapse


def _make_timelapse(*, height=64, width=64, n_frames=40, interval=60.0, speed=0.5, slope=0.15, y0=50.0,
                    sky_rows=6, seed=0, shake=0.0, noise=False, gain_steps=False, jitter=0.0, drop=(),
                    sun_fade=0.0, ss=8):
    """Seeded synthetic outdoor time-lapse with exact ground truth.

    A textured cliff (H x W) with a sky band at the top; a straight shadow edge
    ``y(t, c) = y0 - speed * t / interval + slope * (c + 0.5 - W / 2)`` (pixel-edge
    rows; lit above) climbs it. Pixels are box-filtered (``ss x ss`` sub-samples),
    lit radiance = albedo * (sun(t) + sky(t) * ambient), shadowed = albedo * sky(t) * ambient;
    then exposure gain, a sub-pixel shake (cubic resampling), Poisson-Gaussian noise.
    The exact arrival time of a pixel centre is where the edge passes ``r + 0.5``.

    Return a dict with ``frames (T, H, W, 3)`` float32, ``time_s``, ``arrival_s (H, W)``
    (NaN where the edge never passes or sky), ``edge_row (T, W)``, ``shift (T, 2)``,
    ``gain (T,)``, ``sky (H, W)``, ``interval``, ``lit_at_start (H, W)``.
    """
    from shadowcam.outdoor.translation import translate

    rng = np.random.default_rng(seed)
    nominal = np.arange(n_frames + len(drop))
    keep = np.array([k not in set(drop) for k in nominal])
    time_s = (nominal * interval + rng.uniform(-jitter, jitter, nominal.size) * interval)[keep]
    time_s -= time_s[0]
    albedo = 0.5 + 0.3 * rng.random((height, width, 1)) * np.array([1.0, 0.9, 0.7])
    albedo = albedo.astype(np.float64)
    sky = np.zeros((height, width), bool)
    sky[:sky_rows] = True
    ambient = 0.1
    cols = np.arange(width) + 0.5
    offs = (np.arange(ss) + 0.5) / ss
    sub_r = (np.arange(height)[:, None] + offs[None, :]).ravel()  # H*ss sub-rows
    sub_c = (np.arange(width)[:, None] + offs[None, :]).ravel()

    def edge_at(t):
        return y0 - speed * t / interval + slope * (sub_c - width / 2)

    frames, edges, shifts, gains = [], [], [], []
    gain = 1.0
    for k, t in enumerate(time_s):
        lit = (sub_r[:, None] < edge_at(t)[None, :]).astype(np.float64)
        cover = lit.reshape(height, ss, width, ss).mean(axis=(1, 3))
        sun = 1.0 - sun_fade * t / max(time_s[-1], 1.0)
        skyl = 1.0 - 0.5 * sun_fade * t / max(time_s[-1], 1.0)
        radiance = albedo * (sun * cover[..., None] + skyl * ambient)
        radiance[sky] = np.array([0.25, 0.3, 0.45]) * skyl
        if gain_steps and k and k % 7 == 0:
            gain *= 2 ** (1 / 3)
        image = (radiance * gain * 0.5).astype(np.float32)
        shift = rng.uniform(-shake, shake, 2) if (shake and k) else np.zeros(2)
        if shake and k:
            image = translate(image, -shift, method="opencv_cubic")  # content moves by +shift
        if noise:
            electrons = np.clip(image, 0, None) * 15000.0
            image = ((rng.poisson(electrons) + rng.normal(0, 4, image.shape)) / 15000.0).astype(np.float32)
        frames.append(image)
        edges.append(y0 - speed * t / interval + slope * (cols - width / 2))
        shifts.append(shift)
        gains.append(gain)
    centre = np.arange(height)[:, None] + 0.5
    line = y0 + slope * (cols[None, :] - width / 2)
    arrival = (line - centre) * interval / speed  # y(t) = centre
    lit_at_start = (centre < line) & ~sky
    arrival = np.where(lit_at_start & (arrival <= time_s[-1]), arrival, np.nan)
    return {"frames": np.array(frames), "time_s": time_s, "arrival_s": arrival, "edge_row": np.array(edges),
            "shift": np.array(shifts), "gain": np.array(gains), "sky": sky, "interval": float(interval),
            "lit_at_start": lit_at_start}


@pytest.fixture(scope="session")
def make_timelapse():
    """The seeded synthetic outdoor time-lapse factory: ``make_timelapse(**options) -> dict``."""
    return _make_timelapse


def _make_lightfield_manifest(folder, *, name="captured_lf", shape=(32, 32), n_frames=12, quadrature=300,
                              noise=False, exposure="manifest", sensor=None):
    """Render a light field's DNG brackets into ``folder/data`` and write a captured manifest of them.

    Screens ``near`` and ``far``, the renderer's gain and read noise as ``lightfield.camera``;
    ``exposure="metadata"`` reads the bracket times from the files. Returns ``(manifest path, the renderer's description)``.
    """
    import hashlib

    from shadowcam.synthetic.lightfield.capture import LightFieldCapture, write_capture

    folder = Path(folder)
    root = folder / "data"
    options = {} if sensor is None else {"sensor": sensor}
    rendered = write_capture(root, LightFieldCapture(shape=shape, n_frames=n_frames, quadrature=quadrature,
                                                     noise=noise, screen_names=("near", "far"), **options))
    block = {"screens": [{"id": s["name"], "position_m": s["position_mm"] / 1e3, "homography": s["homography"]}
                         for s in rendered["screens"]],
             "mask": {"position_m": rendered["mask"]["position_mm"] / 1e3,
                      "start_m": rendered["mask"]["start_mm"] / 1e3, "step_m": rendered["mask"]["step_mm"] / 1e3},
             "camera": {"gain_dn_per_e": rendered["sensor"]["gain"], "read_noise_dn": rendered["sensor"]["read_noise"],
                        "footprint_variance_px2": rendered["sensor"]["footprint_variance_px2"]}}
    if exposure == "metadata":
        block["exposure"] = {"source": "metadata", "brackets": len(rendered["exposure_times"])}
    else:
        block["exposure_times_s"] = rendered["exposure_times"]
    manifest = {
        "name": name, "kind": "lightfield", "light": "area", "root": os.path.relpath(root, folder),
        "sweeps": {f"{s}_{suffix}": {"files": f"{s}/{axis}/*.dng"}
                   for s in ("near", "far") for suffix, axis in (("h", "x"), ("v", "y"))},
        "timing": {"source": "rate", "rate_hz": 3.0},
        "checksums": {p.relative_to(root).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
                      for p in root.rglob("*.dng")},
        "lightfield": block,
    }
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(manifest))
    return path, rendered


@pytest.fixture(scope="session")
def make_lightfield_manifest():
    """Factory of captured light-field manifests: ``make_lightfield_manifest(folder, ...) -> (path, description)``."""
    return _make_lightfield_manifest
