"""The light-field workflow stages as front functions: files in, datasets out.

Each ``shadowcam`` light-field step calls one function of this module. A capture is
described by its ``capture.json`` (:func:`shadowcam.synthetic.lightfield.capture.capture_description`):
screens (name, ``position_mm``, pixel -> screen homography), the mask (``start_mm``,
``step_mm``), the bracket ``exposure_times`` and the sensor levels. Frames stream: the
HDR merge writes one frame at a time into a ``.npy`` stack and the shadow times read it
in blocks, so memory does not grow with the number of frames.

Offers
------
DESCRIPTION_FILE : name of the capture description inside a capture folder.
SWEEP_AXES : sweep suffix -> mask axis of its wire.
read_description : a capture folder's description, validated.
describe_capture : the description of a captured (not rendered) light field, from its capture plan.
sweep_files : the RAW files of one sweep of a capture folder.
bracket_files : the DN brackets of each frame from a sweep's files (a generator).
merge_sweep : merge a sweep's brackets into an HDR ``.npy`` stack, one frame at a time.
hdr_blocks : the HDR stack in time blocks for the dip tracker (a generator).
sweep_dataset : one sweep's mask positions as a dataset.
screen_maps : each screen's mask-coordinate map from its two sweep datasets.
rays_from_sweeps : four sweep datasets + the description -> the rays dataset.
render_positions : the rays rendered on planes at several positions -> one dataset.
far_field : the rays' candela table over the directions of the beam.
"""

import json
from pathlib import Path

import numpy as np
import xarray as xr

from shadowcam._shared.atomic import atomic_path
from shadowcam._shared.validation import check_positive
from shadowcam.io.decode import header_metadata
from shadowcam.io.manifest import natural_key
from shadowcam.io.raw_mosaic import read_mosaic
from shadowcam.lightfield import hdr, rays
from shadowcam.lightfield.photometry_export import far_field_table
from shadowcam.lightfield.render import irradiance_on_plane
from shadowcam.lightfield.screen import homography_from_markers, screen_coordinates, screen_positions

DESCRIPTION_FILE = "capture.json"
#: sweep suffix -> mask axis its wire moves along (as :data:`shadowcam.io.capture_plan.LIGHTFIELD_SWEEPS`)
SWEEP_AXES = {"h": "x", "v": "y"}


def read_description(folder):
    """The ``capture.json`` of a light-field capture folder, with its screens validated (nearest first)."""
    path = Path(folder) / DESCRIPTION_FILE
    if not path.is_file():
        raise ValueError(f"{path} does not exist: render the capture (shadowcam render-lightfield) first")
    description = json.loads(path.read_text())
    description["screens"] = screen_positions(description)
    return description


def describe_capture(plan):
    """The ``capture.json`` description of a captured light field.

    The camera's gain and read noise (the HDR merge's inverse-variance weights) are the
    manifest's ``lightfield.camera.gain_dn_per_e`` and ``read_noise_dn`` (1 DN per electron
    and 1 DN where absent); the merge's output is electrons per second (``responsivity``
    1), proportional to the screen irradiance. Black and white levels are the first
    file's (the lowest white level of its CFA sites).

    Parameters
    ----------
    plan : shadowcam.io.capture_plan.CapturePlan
        Plan of a ``kind: lightfield`` manifest with files (not rendered).

    Returns
    -------
    dict
        As :func:`shadowcam.synthetic.lightfield.capture.capture_description`, plus ``files``
        (sweep name -> RAW files in natural order).
    """
    facts = plan.lightfield
    if facts is None or plan.rendered:
        raise ValueError(f"plan must be of a captured kind: lightfield manifest; got {plan.manifest_path}")
    first = plan.sweeps[facts["screens"][0]["sweeps"]["h"]].files
    times = list(facts["screens"][0]["exposure_times_s"])
    if times[0] is None:
        times = [header_metadata(p)["exposure_s"] for p in first[:facts["brackets"]]]
        if any(t is None or not t > 0 for t in times):
            raise ValueError(f"manifest {plan.manifest_path}: key 'lightfield.exposure' is source metadata but "
                             f"{first[0]} and its bracket carry no ExposureTime ({times}); list "
                             "lightfield.exposure_times_s in the manifest")
    _, levels = read_mosaic(first[0])
    screens = []
    for screen in facts["screens"]:
        h = screen["homography"]
        if h is None:
            h = homography_from_markers(screen["markers"]["pixels"], screen["markers"]["points"]).tolist()
        screens.append({"name": screen["id"], "position_mm": screen["position_mm"], "homography": h})
    mask = facts["mask"]
    return {
        "kind": "lightfield", "screens": screens,
        "mask": {**mask, "n_frames": plan.sweeps[facts["screens"][0]["sweeps"]["h"]].n_frames},
        "exposure_times": [float(t) for t in times],
        "sensor": {"black_level": float(np.mean(levels["black_sites"])), "white_level": float(np.min(levels["white_sites"])),
                   "gain": facts["camera"]["gain_dn_per_e"], "read_noise": facts["camera"]["read_noise_dn"],
                   "responsivity": 1.0, "footprint_variance_px2": facts["camera"]["footprint_variance_px2"]},
        "files": {name: list(sweep.files) for name, sweep in plan.sweeps.items()},
    }


def sweep_files(folder, description, sweep):
    """RAW files of `sweep` (``<screen>_h`` or ``<screen>_v``): the description's ``files``, else the
    rendered layout ``<folder>/<screen>/<x|y>/*.dng``."""
    screen, _, suffix = sweep.rpartition("_")
    if suffix not in SWEEP_AXES or screen not in [s["name"] for s in description["screens"]]:
        raise ValueError(f"sweep must be <screen>_h or <screen>_v with a screen of {folder}; got {sweep!r}")
    if "files" in description:
        return description["files"][sweep]
    return sorted(Path(folder, screen, SWEEP_AXES[suffix]).glob("*.dng"))


def bracket_files(paths, *, brackets):
    """The DN brackets of each frame: runs of `brackets` consecutive files.

    Parameters
    ----------
    paths : sequence of str
        RAW files in natural order, ``len(paths)`` a multiple of `brackets`.
    brackets : int, keyword-only

    Yields
    ------
    (E, H, W) uint16 ndarray
        The mosaics of one frame's brackets.
    """
    paths = sorted(map(str, paths), key=natural_key)
    if brackets < 1 or not paths or len(paths) % brackets:
        raise ValueError(f"paths must hold a whole number of brackets of {brackets} files; got {len(paths)} files "
                         "(brackets of different sizes): check the sweep's files")
    for start in range(0, len(paths), brackets):
        yield np.stack([read_mosaic(p)[0] for p in paths[start:start + brackets]])


def merge_sweep(paths, out, *, exposure_times, sensor):
    """Merge a sweep's brackets into an HDR stack ``(T, H, W)`` float32 ``.npy`` (lux), frame by frame.

    Parameters
    ----------
    paths : sequence of str
        The sweep's RAW files (see :func:`bracket_files`).
    out : str or Path
        Output ``.npy``, written atomically.
    exposure_times : (E,) array_like, keyword-only
        Seconds per bracket.
    sensor : mapping, keyword-only
        ``black_level``, ``white_level``, ``gain``, ``read_noise``, ``responsivity``
        (electrons per second per lux).

    Returns
    -------
    dict
        ``n_frames`` and ``all_saturated``: photosites where every bracket of some frame saturated
        (their HDR value is NaN: :data:`shadowcam.lightfield.hdr.REASONS` ``all_saturated``).
    """
    times = np.asarray(exposure_times, np.float64)
    n_frames = len(paths) // len(times)
    frames = bracket_files(paths, brackets=len(times))
    merged = hdr.merge_stream(frames, times, black_level=sensor["black_level"], white_level=sensor["white_level"],
                              gain=sensor["gain"], read_noise=sensor["read_noise"],
                              responsivity=sensor["responsivity"])
    saturated = 0
    with atomic_path(out) as tmp:
        stack = None
        for t, frame in enumerate(merged):
            if stack is None:
                stack = np.lib.format.open_memmap(tmp, mode="w+", dtype=np.float32,
                                                  shape=(n_frames,) + frame.shape[1:3])
            stack[t] = frame[0, ..., 0]
            saturated = saturated | np.isnan(frame[0, ..., 0])
        stack.flush()
        del stack
    return {"n_frames": n_frames, "all_saturated": int(np.count_nonzero(saturated))}


def hdr_blocks(path, *, block=16):
    """The HDR stack of :func:`merge_sweep` as ``(t, H, W, 1)`` blocks (memory-mapped)."""
    stack = np.load(path, mmap_mode="r")
    for start in range(0, stack.shape[0], block):
        yield np.asarray(stack[start:start + block])[..., None]


def sweep_dataset(hdr_path, *, mask_start, mask_step, half_window=4, method="edge_fit"):
    """Mask positions of one sweep from its HDR stack (:func:`shadowcam.lightfield.rays.sweep_mask_positions`).

    Returns
    -------
    xarray.Dataset
        ``(row, col)`` variables ``position`` and ``position_std`` (mm at the mask), ``lit_level``
        (lux), ``flags`` (shadow-time reason codes) and ``time`` (frames, for the time map).
    """
    shape = np.load(hdr_path, mmap_mode="r").shape[1:]
    found = rays.sweep_mask_positions(hdr_blocks(hdr_path), shape, mask_start=mask_start, mask_step=mask_step,
                                      half_window=half_window, method=method)
    dims = ("row", "col")
    return xr.Dataset(
        {"position": (dims, found["position"], {"units": "mm", "long_name": "mask position of the shadow"}),
         "position_std": (dims, found["position_std"], {"units": "mm"}),
         "time": (dims, (found["position"] - mask_start) / mask_step, {"units": "frame", "long_name": "shadow time"}),
         "lit_level": (dims, np.asarray(found["lit_level"]).reshape(shape), {"units": "lx"}),
         "flags": (dims, found["flags"], {"long_name": "shadow-time reason code"})},
        coords={"row": np.arange(shape[0]), "col": np.arange(shape[1])},
        attrs={"mask_start_mm": float(mask_start), "mask_step_mm": float(mask_step)},
    )


def _as_found(dataset):
    return {"position": dataset["position"].values, "position_std": dataset["position_std"].values,
            "lit_level": dataset["lit_level"].values}


def screen_maps(sweeps, description):
    """Each screen's mask-coordinate map (:func:`shadowcam.lightfield.rays.screen_mask_map`), nearest first.

    Parameters
    ----------
    sweeps : mapping of (screen name, suffix) to xarray.Dataset
        :func:`sweep_dataset` of each screen's ``h`` and ``v`` sweep.
    description : dict
        :func:`read_description`.
    """
    maps = []
    for screen in description["screens"]:
        missing = [s for s in SWEEP_AXES if (screen["name"], s) not in sweeps]
        if missing:
            raise ValueError(f"sweeps must hold the h and v sweeps of screen {screen['name']!r}; missing {missing}")
        h, v = (sweeps[(screen["name"], s)] for s in SWEEP_AXES)
        xy, area = screen_coordinates(screen["homography"], h["position"].shape)
        maps.append(rays.screen_mask_map(_as_found(h), _as_found(v), xy=xy, area=area,
                                         position_mm=screen["position_mm"]))
    return maps


def rays_from_sweeps(sweeps, description, *, anchor="far", mask_std_scale=0.05):
    """The rays dataset of a capture: its two nearest screens' :func:`screen_maps` joined.

    The rays go through the anchor pixels' mask points on the description's mask plane
    (``mask.position_mm``), from each pixel's flux centroid (the camera's
    ``sensor.footprint_variance_px2``; 1/12, a box pixel, where the description has none).
    Anchored on the far screen by default: through the mask point both anchors' direction
    errors are the mask error over the mask-to-anchor distance (the far one's half as large).
    The near screen's rings are the less sharp, so its pixels' flux centroids (first order in
    the footprint) are the closer to the rays' when the camera's footprint is known, but its
    renders beyond the far screen depend more on that footprint (docs/benchmarks.md
    "Light field: rays through the mask point").

    Parameters
    ----------
    sweeps, description
        As :func:`screen_maps`.
    anchor, mask_std_scale : keyword-only
        As :func:`shadowcam.lightfield.rays.rays_dataset`.

    Returns
    -------
    xarray.Dataset
    """
    maps = screen_maps(sweeps, description)
    return rays.rays_dataset(maps[0], maps[1], anchor=anchor, mask_position_mm=description["mask"]["position_mm"],
                             footprint_variance=description["sensor"].get("footprint_variance_px2", 1.0 / 12.0),
                             mask_std_scale=mask_std_scale)


def render_grid(description, shape, position_mm, *, pitch_factor):
    """Grid of a render at `position_mm`: ``(shape, pitch mm)``.

    The pitch is `pitch_factor` times the near camera's pixel pitch magnified to the
    target distance; the grid keeps the camera's field (``shape // pitch_factor``).
    """
    check_positive(pitch_factor, "pitch_factor", finite=True)
    near = description["screens"][0]
    _, area = screen_coordinates(near["homography"], shape)
    near_pitch = float(np.sqrt(np.median(area)))
    pitch = pitch_factor * near_pitch * position_mm / near["position_mm"]
    return tuple(max(2, int(round(n / pitch_factor))) for n in shape), pitch


def render_positions(ray_set, description, positions_mm, *, pitch_factor=2.0):
    """The rays rendered on planes normal to the axis at `positions_mm`.

    Returns
    -------
    xarray.Dataset
        ``irradiance`` ``(position, row, col)`` lux on each plane's grid
        (:func:`render_grid`), ``pixel_size`` ``(position,)`` mm.
    """
    positions = np.asarray(positions_mm, np.float64)
    if positions.ndim != 1 or positions.size == 0 or not np.all(positions > 0):
        raise ValueError(f"positions_mm must list distances > 0 from the source; got {positions_mm!r}")
    camera = ray_set["flux"].shape
    shape, _ = render_grid(description, camera, positions[0], pitch_factor=pitch_factor)
    images, pitches = [], []
    for z in positions:
        _, pitch = render_grid(description, camera, z, pitch_factor=pitch_factor)
        images.append(irradiance_on_plane(ray_set, centre=(0.0, 0.0, z), shape=shape, pixel_size=pitch).values)
        pitches.append(pitch)
    return xr.Dataset(
        {"irradiance": (("position", "row", "col"), np.stack(images), {"units": "lx"}),
         "pixel_size": (("position",), np.array(pitches), {"units": "mm"})},
        coords={"position": ("position", positions, {"units": "mm"}), "row": np.arange(shape[0]),
                "col": np.arange(shape[1])},
        attrs={"pitch_factor": float(pitch_factor)},
    )


def far_field(ray_set, *, c_step_deg=15.0, gamma_step_deg=1.0):
    """The rays' candela table, ``gamma`` from 0 to the widest ray's angle, ``C`` every `c_step_deg`.

    The table samples the far field resolved at the capture's angular resolution
    (:func:`shadowcam.lightfield.photometry_export.far_field_table`); the steps only
    choose where it is sampled.
    """
    check_positive(c_step_deg, "c_step_deg", finite=True)
    check_positive(gamma_step_deg, "gamma_step_deg", finite=True)
    d = ray_set["direction"].values
    widest = float(np.degrees(np.arctan(np.nanmax(np.hypot(d[..., 0], d[..., 1]) / d[..., 2]))))
    gamma = np.arange(0.0, min(np.floor(widest), 89.0) + gamma_step_deg / 2, gamma_step_deg)
    c = np.arange(0.0, 360.0 - c_step_deg / 2, c_step_deg)
    return far_field_table(ray_set, vertical_angles=gamma, horizontal_angles=c)
