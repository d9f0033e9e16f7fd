"""Real-size outdoor time-lapse samples for throughput and memory benchmarks.

A camera time-lapse is tens of megapixels per frame; the shared development
capture (dev_ridge) is 192x128. This module turns small linear frames into
real-size sensor mosaics: the frame is steadied (its recorded shake undone at
the source resolution: upsampled ~31x, dev_ridge's <= 1 px shake would become
~30 px), upsampled (bilinear, so the shadow edge becomes a ramp as wide as the
scale factor), shaken by a realistic amount at full resolution (sub-pixel to
2 px, recorded), exposed, and given the Poisson-Gaussian noise and 14-bit
quantisation of :mod:`shadowcam.synthetic.sensor` at full resolution, so that decoding,
compression and every per-pixel stage see data of the real size and noise. It
is for measuring speed and memory, and the registration against the recorded
shake; the arrival times have no ground truth at the new size.

Shake convention (as dev_ridge, shared/data README 2.3): ``frame(u, v) =
image(u - dx, v - dy)``, content moves by ``+dx`` (cols) and ``+dy`` (rows).

Offers
------
parse_size : ``"6000x4000"`` (cols x rows) -> ``(rows, cols)``.
steady_frame : undo a frame's recorded shake (source resolution).
sample_shake : seeded per-frame shake of a real-size sample, on OpenCV's 1/32 px grid.
upsample_frame : bilinear upsampling of a linear (H, W, C) frame to (rows, cols, C).
sample_mosaic : one real-size noisy RGGB mosaic (uint16 DN) from a small frame, optionally shaken.
source_shake : the recorded shake of a source capture's frames (zeros if unknown).
write_sample : write a real-size DNG time-lapse sample, its sidecar and its checksummed manifest.
"""

import datetime
import json
import logging
from pathlib import Path

import cv2
import numpy as np

from shadowcam._shared.validation import check_array
from shadowcam.synthetic.outdoor.nuisance import apply_shake, shake_offsets
from shadowcam.outdoor.translation import translate
from shadowcam.synthetic.sensor import simulate_raw

log = logging.getLogger(__name__)

#: sub-pixel grid of OpenCV's warps (INTER_BITS = 5): a shake on it is applied exactly
SHAKE_STEP_PX = 1.0 / 32


def parse_size(text):
    """Return ``(rows, cols)`` of a ``"COLSxROWS"`` size string (e.g. ``"6000x4000"``)."""
    try:
        cols, rows = (int(part) for part in str(text).lower().split("x"))
    except ValueError:
        raise ValueError(f"size must be COLSxROWS, e.g. 6000x4000; got {text!r}") from None
    if rows < 22 or cols < 22 or rows % 2 or cols % 2:
        raise ValueError(f"size {text!r}: rows and cols must be even and >= 22 (Bayer mosaic, LibRaw limit)")
    return rows, cols


def steady_frame(image, *, dx, dy):
    """Undo a recorded shake: return ``image`` with ``frame(u, v) = image(u - dx, v - dy)`` solved.

    Parameters
    ----------
    image : (H, W, C) ndarray
        A shaken linear frame.
    dx, dy : float
        Its recorded shake along cols and rows, pixels.

    Returns
    -------
    (H, W, C) ndarray
        Resampled at ``(u + dx, v + dy)`` with the cubic spline the shake was
        made with (:func:`shadowcam.synthetic.outdoor.nuisance.apply_shake`), edges replicated.
    """
    image = np.asarray(image, dtype=np.float32)
    check_array(image, "image", ndim=3)
    return apply_shake(image, -float(dx), -float(dy))


def sample_shake(frames, *, seed, max_px=2.0):
    """Per-frame camera shake of a real-size sample (content moves by +dx, +dy).

    :func:`shadowcam.synthetic.outdoor.nuisance.shake_offsets` (AR(1) jitter, rms ~0.3
    `max_px`, plus gusts up to `max_px`), rounded to :data:`SHAKE_STEP_PX` so that
    OpenCV's warp applies it without quantisation error.

    Parameters
    ----------
    frames : int
    seed : int
    max_px : float, optional
        Largest shake, pixels of the sample (2: sub-pixel to 2 px, a tripod in wind).

    Returns
    -------
    dx, dy : (frames,) float64 ndarray
    """
    if int(frames) < 1:
        raise ValueError(f"frames must be >= 1; got {frames}")
    dx, dy = shake_offsets(int(frames), seed=seed, max_px=max_px)
    return (np.round(dx / SHAKE_STEP_PX) * SHAKE_STEP_PX, np.round(dy / SHAKE_STEP_PX) * SHAKE_STEP_PX)


def upsample_frame(image, *, rows, cols):
    """Upsample a linear frame bilinearly.

    Parameters
    ----------
    image : (H, W, C) ndarray
        Linear frame.
    rows, cols : int
        Output size.

    Returns
    -------
    (rows, cols, C) float32 ndarray
        Pixel centres map to pixel centres (OpenCV ``INTER_LINEAR``).
    """
    image = np.asarray(image, dtype=np.float32)
    check_array(image, "image", ndim=3)
    if rows < 1 or cols < 1:
        raise ValueError(f"rows and cols must be positive; got {rows}, {cols}")
    return cv2.resize(image, (int(cols), int(rows)), interpolation=cv2.INTER_LINEAR).reshape(rows, cols, -1)


def sample_mosaic(image, *, rows, cols, sensor, scale, seed, shake=(0.0, 0.0)):
    """One real-size noisy RGGB mosaic of a small linear frame.

    Parameters
    ----------
    image : (H, W, 3) ndarray
        Linear frame (e.g. a dev_ridge PNG, white level = 1).
    rows, cols : int
        Sensor size (even).
    sensor : shadowcam.synthetic.sensor.SensorModel
        Bit depth, black level, gain, read noise.
    scale : float
        Electrons per unit of `image` (:func:`shadowcam.synthetic.sensor.electrons_per_unit_radiance`); the same
        for every frame, so that the capture's own exposure changes are kept.
    seed : int or sequence of int
        Noise seed (``numpy.random.default_rng``).
    shake : (2,) array_like, optional
        ``(dx, dy)``, pixels of the sample: the upsampled frame is moved by it
        (cubic, edges replicated, clipped at 0) before exposure and noise.

    Returns
    -------
    (rows, cols) uint16 ndarray
        DN in ``[0, sensor.white_level]``.
    """
    if rows % 2 or cols % 2:
        raise ValueError(f"rows and cols must be even (RGGB mosaic); got {rows}, {cols}")
    big = upsample_frame(image, rows=rows, cols=cols)
    if big.shape[2] != 3:
        raise ValueError(f"image must have 3 channels (RGB); got {big.shape[2]}")
    dx, dy = (float(v) for v in shake)
    if dx or dy:
        big = np.maximum(translate(big, (-dy, -dx), method="opencv_cubic"), np.float32(0))
    return simulate_raw(big, sensor=sensor, scale=scale, seed=seed, noise=True, mosaic=True)


def source_shake(source, first, stop):
    """Recorded shake ``(dx, dy)`` of the source frames ``first .. stop - 1`` (zeros if unknown).

    Parameters
    ----------
    source : mapping
        Loaded manifest of the source capture (its ground truth may record ``shake_dx_px``).
    first, stop : int
    """
    from shadowcam.io.ground_truth import load_ground_truth

    if "ground_truth" in source:
        truth = load_ground_truth(source)
        if "shake_dx_px" in truth:
            return truth["shake_dx_px"].values[first:stop], truth["shake_dy_px"].values[first:stop]
    log.warning("source %s records no shake: its shake (if any) is upsampled with the frames", source["name"])
    return np.zeros(stop - first), np.zeros(stop - first)


def write_sample(source, outdir, manifest_out, *, name, size="6000x4000", frames=16, first=40, bit_depth=14,
                 seed=0, shake_px=2.0, source_label=None, compression="ljpeg"):
    """Write a real-size RAW time-lapse sample of a small outdoor capture and its manifest.

    Steadies consecutive source frames (their recorded shake undone), upsamples them
    to `size`, shakes them by a seeded amount up to `shake_px`, adds full-resolution
    sensor noise and writes RGGB DNGs ``outdir/frames/000000.dng ...``, a sidecar
    ``timestamps.json`` (``times_s``, ``shake_dx_px``, ``shake_dy_px``) and a
    checksummed ``kind: outdoor`` manifest at `manifest_out`.

    Parameters
    ----------
    source : mapping
        Loaded manifest of a small outdoor capture with one sweep.
    outdir : str or Path
        Root of the new dataset.
    manifest_out : str or Path
        Manifest YAML to write.
    name : str
        Dataset name.
    size : str
        ``COLSxROWS``.
    frames, first : int
        Number of frames and first source frame.
    bit_depth, seed : int
    shake_px : float
        Largest camera shake of the sample (0: none).
    source_label : str, optional
        How the source is named in the provenance (default its name).
    compression : {"ljpeg", "none"}, optional
        DNG compression of the frames: lossless JPEG (what cameras write) or none.

    Returns
    -------
    dict
        The manifest written.
    """
    import yaml

    from shadowcam.io.decode import read_frame
    from shadowcam.io.manifest import checksums_for
    from shadowcam.io.raw_writer import write_dng
    from shadowcam.synthetic.sensor import SensorModel, electrons_per_unit_radiance

    rows, cols = parse_size(size)
    if source.get("kind") != "outdoor" or len(source["sweeps"]) != 1:
        raise ValueError(f"source {source.get('name')}: must be an outdoor capture with one sweep")
    sweep = next(iter(source["sweeps"].values()))
    stop = first + frames
    if frames < 3 or first < 0 or stop > len(sweep["paths"]):
        raise ValueError(f"first {first}, frames {frames}: the source has {len(sweep['paths'])} frames; "
                         "take at least 3 inside it")
    times = np.asarray(sweep["times_s"][first:stop], dtype=np.float64)
    times -= times[0]
    source_dx, source_dy = source_shake(source, first, stop)
    shake_dx, shake_dy = sample_shake(frames, seed=seed, max_px=shake_px)
    sensor = SensorModel(bit_depth=bit_depth, black_level=512, gain=1.0, read_noise=3.0)

    def steady(k):
        return steady_frame(read_frame(sweep["paths"][first + k]), dx=source_dx[k], dy=source_dy[k])

    scale = electrons_per_unit_radiance(upsample_frame(steady(0), rows=rows, cols=cols), sensor=sensor, target_fraction=0.7)
    outdir = Path(outdir)
    (outdir / "frames").mkdir(parents=True, exist_ok=True)
    start_time = datetime.datetime(2026, 1, 15, 16, 0, 0)
    names = []
    for k in range(frames):
        raw = sample_mosaic(steady(k), rows=rows, cols=cols, sensor=sensor, scale=scale, seed=[seed, k],
                            shake=(shake_dx[k], shake_dy[k]))
        frame_name = f"frames/{k:06d}.dng"
        write_dng(outdir / frame_name, raw, bit_depth=sensor.bit_depth, black_level=sensor.black_level,
                  capture_time=start_time + datetime.timedelta(seconds=float(times[k])), compression=compression)
        names.append(frame_name)
        log.info("wrote %s (%d/%d), shake dx %+.3f dy %+.3f px", frame_name, k + 1, frames, shake_dx[k], shake_dy[k])
    sidecar = {"units": "s", "times_s": times.tolist(), "files": names,
               "shake_dx_px": shake_dx.tolist(), "shake_dy_px": shake_dy.tolist(),
               "shake_convention": "frame(u, v) = image(u - dx, v - dy): content moves by +dx (cols), +dy (rows)"}
    (outdir / "timestamps.json").write_text(json.dumps(sidecar))
    manifest = {
        "name": name,
        "kind": "outdoor",
        "description": f"{frames} frames of {source['name']} (from frame {first}) upsampled to "
                       f"{cols}x{rows}, {bit_depth}-bit RGGB DNG with full-resolution sensor noise, "
                       f"source shake undone, camera shake <= {shake_px:g} px applied (timestamps.json: "
                       "shake_dx_px, shake_dy_px) (benchmark sample, no arrival-time ground truth)",
        "light": "distant",
        "root": str(outdir.resolve()),
        "sweeps": {"timelapse": {"files": "frames/*.dng"}},
        "timing": {"source": "sidecar", "file": "timestamps.json", "key": "times_s"},
        "provenance": f"shadowcam outdoor-sample from {source_label or source['name']}, seed {seed}",
        "licence": source.get("licence", "CC0-1.0"),
    }
    out = Path(manifest_out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(yaml.safe_dump(manifest, sort_keys=False))
    manifest["checksums"] = checksums_for(out)
    out.write_text(yaml.safe_dump(manifest, sort_keys=False))
    return manifest
