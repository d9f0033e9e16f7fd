"""Ground truth of synthetic captures in the standard form (docs/contracts.md).

Standard form (an ``xarray.Dataset``):

* ``(row, col)``: ``t_u``, ``t_v`` (shadow time in frames, NaN where not lit
  or not swept), ``lit`` (bool);
* ``(v, u, channel)``: ``reciprocal`` (linear render from the light = the dual view);
* ``(v, u)``: ``dual_cam_visible`` (bool);

plus whatever else the source has (``P``, ``reference_linear``, ...). Camera
arrays are indexed at pixel centres; dual pixel (row j, col i) is ``u = i, v = j``.

Supported formats (the manifest's ``ground_truth.format``):

* ``shadowcam_nc`` -- the netCDF written by ``shadowcam render`` (already standard);
* ``mitsuba_lab_npz`` -- ``gt.npz`` of the shared lab development data
  (``shared/data/README.md`` section 1.5).

Outdoor time-lapses (manifest ``kind: outdoor``) have their own standard form,
:data:`OUTDOOR_REQUIRED` (``shadow_class``, ``sky_mask``, ``arrival_time_s``, ...
over ``(row, col)``; ``times_s`` over ``time``; ``pb_edge_y`` over ``(time, col)``,
the definitions of ``shared/data/README.md`` section 2.6), from

* ``shadowcam_outdoor_nc`` -- the ``ground_truth.nc`` of the project's outdoor
  renderer (same variable names and dims);
* ``mitsuba_outdoor_npz`` -- ``gt.npz`` of the shared outdoor development data.

Offers
------
GT_FORMATS : format name -> loader(path) -> Dataset.
REQUIRED : standard variables and their dims.
load_ground_truth : the standard GT Dataset of a manifest.
mitsuba_lab_npz_to_dataset : convert the arrays of a lab ``gt.npz``.
check_ground_truth : raise ValueError unless a Dataset is in standard form.
OUTDOOR_REQUIRED : standard outdoor variables and their dims.
mitsuba_outdoor_npz_to_dataset : convert the arrays of an outdoor ``gt.npz``.
check_outdoor_ground_truth : raise ValueError unless a Dataset is in outdoor standard form.
"""

import logging
from pathlib import Path

import numpy as np
import xarray as xr

log = logging.getLogger(__name__)

#: standard variables and their dims
REQUIRED = {
    "t_u": ("row", "col"),
    "t_v": ("row", "col"),
    "lit": ("row", "col"),
    "reciprocal": ("v", "u", "channel"),
    "dual_cam_visible": ("v", "u"),
}

_CAM = ("row", "col")
_DUAL = ("v", "u")
# gt.npz key -> (dims, attrs); keys not listed here are skipped
_LAB_NPZ_VARS = {
    "t_u": (_CAM, {"units": "frame", "long_name": "analytic shadow time, sweep u (= dual u)"}),
    "t_v": (_CAM, {"units": "frame", "long_name": "analytic shadow time, sweep v (= dual v)"}),
    "t_u_all": (_CAM, {"units": "frame", "long_name": "t_u without lit / range restriction"}),
    "t_v_all": (_CAM, {"units": "frame", "long_name": "t_v without lit / range restriction"}),
    "valid_u": (_CAM, {"long_name": "isfinite(t_u)"}),
    "valid_v": (_CAM, {"long_name": "isfinite(t_v)"}),
    "xprime": (_CAM, {"units": "dual pixel", "long_name": "true dual coordinate u (= t_u)"}),
    "yprime": (_CAM, {"units": "dual pixel", "long_name": "true dual coordinate v (= t_v)"}),
    "lit": (_CAM, {"long_name": "faces light and camera, unoccluded from the light"}),
    "hit": (_CAM, {"long_name": "pixel-centre ray hits geometry"}),
    "depth": (_CAM, {"units": "scene unit", "long_name": "camera z of P"}),
    "cos_L": (_CAM, {"units": "1", "long_name": "cosine normal / direction to light"}),
    "cos_C": (_CAM, {"units": "1", "long_name": "cosine normal / direction to camera"}),
    "dist_L": (_CAM, {"units": "scene unit", "long_name": "distance P to light"}),
    "dist_C": (_CAM, {"units": "scene unit", "long_name": "distance P to camera centre"}),
    "P": (_CAM + ("xyz",), {"units": "scene unit", "long_name": "world point at pixel centre"}),
    "N": (_CAM + ("xyz",), {"long_name": "geometric normal"}),
    "N_shading": (_CAM + ("xyz",), {"long_name": "shading normal"}),
    "reference_linear": (_CAM + ("channel",), {"units": "radiance", "long_name": "linear render without the wire"}),
    "reciprocal": (_DUAL + ("channel",), {"units": "radiance", "long_name": "reciprocal render (dual view)"}),
    "dual_P": (_DUAL + ("xyz",), {"units": "scene unit", "long_name": "world point at dual pixel centre"}),
    "dual_hit": (_DUAL, {"long_name": "dual pixel ray hits geometry"}),
    "dual_cam_visible": (_DUAL, {"long_name": "dual point directly visible from the camera"}),
    "dual_cam_xy": (_DUAL + ("cam_axis",), {"units": "camera pixel", "long_name": "camera (col, row) of dual point"}),
}


#: standard outdoor variables and their dims
OUTDOOR_REQUIRED = {
    "shadow_class": ("row", "col"),
    "sky_mask": ("row", "col"),
    "arrival_time_s": ("row", "col"),
    "arrival_frame": ("row", "col"),
    "first_shadowed_frame": ("row", "col"),
    "relit_after_arrival": ("row", "col"),
    "times_s": ("time",),
}
_TIME = ("time",)
# outdoor gt.npz key -> (dims, attrs); keys not listed here are skipped
_OUTDOOR_NPZ_VARS = {
    "shadow_class": (_CAM, {"long_name": "0 sky, 1 never shadowed, 2 shadowed at start, 3 shadow arrives"}),
    "sky_mask": (_CAM, {"long_name": "pixel-centre ray misses terrain"}),
    "never_shadowed": (_CAM, {"long_name": "class 1"}),
    "shadowed_at_start": (_CAM, {"long_name": "class 2: unlit in frame 0"}),
    "always_shadowed": (_CAM, {"long_name": "unlit in every frame"}),
    "relit_after_arrival": (_CAM, {"long_name": "lit again after the first shadowed frame"}),
    "cause": (_CAM, {"long_name": "class 3: 1 cast shadow, 2 attached"}),
    "arrival_time_s": (_CAM, {"units": "s", "long_name": "first time the pixel-centre point is unlit"}),
    "arrival_frame": (_CAM, {"units": "frame", "long_name": "arrival_time_s as fractional frame index"}),
    "first_shadowed_frame": (_CAM, {"units": "frame", "long_name": "first frame whose pixel centre is unlit (-1 never)"}),
    "arrival_time_half_coverage_s": (_CAM, {"units": "s", "long_name": "median of 16 sub-pixel arrival times"}),
    "arrival_frame_half_coverage": (_CAM, {"units": "frame", "long_name": "arrival_time_half_coverage_s as frame"}),
    "subpixel_sky_fraction": (_CAM, {"units": "1", "long_name": "fraction of 16 sub-points that are sky"}),
    "sky_fraction": (_CAM, {"units": "1", "long_name": "rendered sky fraction of the pixel footprint"}),
    "depth_z": (_CAM, {"units": "m", "long_name": "camera z of the pixel-centre point"}),
    "reference_radiance": (_CAM + ("channel",), {"units": "radiance", "long_name": "noise-free radiance of frame 0"}),
    "times_s": (_TIME, {"units": "s", "long_name": "frame time since frame 0"}),
    "exposure_gain": (_TIME, {"units": "1", "long_name": "true total exposure gain"}),
    "shake_dx_px": (_TIME, {"units": "pixel", "long_name": "true shake along columns (content moves +dx)"}),
    "shake_dy_px": (_TIME, {"units": "pixel", "long_name": "true shake along rows (content moves +dy)"}),
    "pb_edge_y": (_TIME + ("col",), {"units": "pixel", "long_name": "GT shadow-edge row (pixel-edge coordinates)"}),
    "pb_n_transitions": (_TIME + ("col",), {"long_name": "lit-above / shadowed-below pairs in the column"}),
    "pb_front": (_TIME + ("col", "channel"), {"units": "radiance", "long_name": "GT ridge pushbroom (reference radiance at the edge)"}),
}


def _wrong_dims(dataset, required):
    """Names (with dims) of `required` variables missing from `dataset` or with other dims."""
    return [f"{name} {dims}" for name, dims in required.items()
            if name not in dataset or tuple(dataset[name].dims) != dims]


def _npz_data_vars(arrays, table):
    """``{key: (dims, array, attrs)}`` for the keys of `table` present in `arrays`, ndim checked."""
    data_vars = {}
    for key, (dims, attrs) in table.items():
        if key in arrays:
            value = np.asarray(arrays[key])
            if value.ndim != len(dims):
                raise ValueError(f"gt.npz key {key!r} has shape {value.shape}, expected dims {dims}")
            data_vars[key] = (dims, value, attrs)
    return data_vars


def _as_bool(dataset, names):
    """`dataset` with the variables `names` (those present) cast to bool."""
    for name in names:
        if name in dataset:
            dataset[name] = dataset[name].astype(bool)
    return dataset


_OUTDOOR_MASKS = ("sky_mask", "never_shadowed", "shadowed_at_start", "always_shadowed", "relit_after_arrival")


def check_outdoor_ground_truth(dataset):
    """Raise ValueError unless `dataset` has the standard outdoor variables with their dims."""
    problems = _wrong_dims(dataset, OUTDOOR_REQUIRED)
    if problems:
        raise ValueError(f"outdoor ground truth lacks (or has wrong dims for): {', '.join(problems)}")
    return dataset


def mitsuba_outdoor_npz_to_dataset(arrays):
    """Convert the arrays of an outdoor ``gt.npz`` into the standard outdoor GT Dataset.

    Parameters
    ----------
    arrays : mapping of str to ndarray
        E.g. ``numpy.load("gt.npz")`` of ``shared/data/outdoor-dev/dev_ridge``:
        camera arrays ``(H, W[, 3])`` indexed ``[row, col]``, per-frame arrays
        ``(T[, W[, 3]])``.

    Returns
    -------
    xarray.Dataset
        Every known key (see ``_OUTDOOR_NPZ_VARS``) with coords ``row``, ``col``,
        ``time`` (frame index), ``channel``; attr ``definitions`` (JSON) if present.
    """
    missing = [k for k in OUTDOOR_REQUIRED if k not in arrays]
    if missing:
        raise ValueError(f"outdoor gt.npz arrays lack required keys {missing}")
    data_vars = _npz_data_vars(arrays, _OUTDOOR_NPZ_VARS)
    height, width = np.shape(arrays["shadow_class"])
    coords = {
        "row": np.arange(height),
        "col": np.arange(width),
        "time": ("time", np.arange(np.size(arrays["times_s"])), {"units": "frame"}),
        "channel": np.array(["R", "G", "B"], dtype=object),
    }
    dataset = _as_bool(xr.Dataset(data_vars, coords=coords), _OUTDOOR_MASKS)
    if "definitions" in arrays:
        dataset.attrs["definitions"] = str(np.asarray(arrays["definitions"]))
    return check_outdoor_ground_truth(dataset)


def check_ground_truth(dataset):
    """Raise ValueError unless `dataset` has the standard variables with their dims."""
    problems = _wrong_dims(dataset, REQUIRED)
    if problems:
        raise ValueError(f"ground truth lacks (or has wrong dims for): {', '.join(problems)}")
    return dataset


def mitsuba_lab_npz_to_dataset(arrays):
    """Convert the arrays of a lab ``gt.npz`` into the standard GT Dataset.

    Parameters
    ----------
    arrays : mapping of str to ndarray
        E.g. ``numpy.load("gt.npz")``: camera arrays ``(H, W[, 3])`` indexed
        ``[row, col]``, dual arrays ``(N_v, N_u[, k])`` indexed ``[v, u]``.

    Returns
    -------
    xarray.Dataset
        Standard variables plus every known key (see ``_LAB_NPZ_VARS``), with
        integer coords ``row``, ``col``, ``u``, ``v``, ``channel`` (R, G, B),
        ``xyz`` and ``cam_axis`` (col, row).
    """
    missing = [k for k in REQUIRED if k not in arrays]
    if missing:
        raise ValueError(f"gt.npz arrays lack required keys {missing}")
    data_vars = _npz_data_vars(arrays, _LAB_NPZ_VARS)
    skipped = sorted(set(arrays) - set(_LAB_NPZ_VARS))
    if skipped:
        log.debug("gt.npz keys not converted: %s", skipped)
    height, width = np.shape(arrays["t_u"])
    n_v, n_u = np.shape(arrays["dual_cam_visible"])
    coords = {
        "row": np.arange(height),
        "col": np.arange(width),
        "v": ("v", np.arange(n_v), {"long_name": "dual row (pixel-centre index)"}),
        "u": ("u", np.arange(n_u), {"long_name": "dual column (pixel-centre index)"}),
        "channel": np.array(["R", "G", "B"], dtype=object),
        "xyz": np.array(["x", "y", "z"], dtype=object),
        "cam_axis": np.array(["col", "row"], dtype=object),
    }
    dataset = _as_bool(xr.Dataset(data_vars, coords=coords),
                       ("lit", "dual_cam_visible", "hit", "dual_hit", "valid_u", "valid_v"))
    return check_ground_truth(dataset)


def _per_pixel_frame(variable):
    """Whether a ground-truth variable holds a map per frame (dims time, row and col)."""
    return {"time", "row", "col"} <= set(variable.dims)


def _load_shadowcam_nc(path, *, frame_maps=True):
    with xr.open_dataset(path, engine="h5netcdf") as source:
        if not frame_maps:
            source = source.drop_vars([name for name, v in source.data_vars.items() if _per_pixel_frame(v)])
        dataset = source.load()
    return dataset


def _load_mitsuba_lab_npz(path):
    with np.load(path) as arrays:
        return mitsuba_lab_npz_to_dataset({k: arrays[k] for k in arrays.files})


def _load_mitsuba_outdoor_npz(path):
    with np.load(path) as arrays:
        return mitsuba_outdoor_npz_to_dataset({k: arrays[k] for k in arrays.files})


def _load_shadowcam_outdoor_nc(path, *, frame_maps=True):
    return _as_bool(_load_shadowcam_nc(path, frame_maps=frame_maps), _OUTDOOR_MASKS)


#: ground_truth.format -> loader(path) -> Dataset
GT_FORMATS = {
    "shadowcam_nc": _load_shadowcam_nc,
    "mitsuba_lab_npz": _load_mitsuba_lab_npz,
    "shadowcam_outdoor_nc": _load_shadowcam_outdoor_nc,
    "mitsuba_outdoor_npz": _load_mitsuba_outdoor_npz,
}
#: formats whose loader leaves the per-frame maps unread when asked (``frame_maps=False``)
_READS_SELECTIVELY = ("shadowcam_nc", "shadowcam_outdoor_nc")
#: formats whose standard form is the outdoor one
OUTDOOR_FORMATS = ("shadowcam_outdoor_nc", "mitsuba_outdoor_npz")


def load_ground_truth(manifest, *, frame_maps=True):
    """Return a manifest's ground truth as the standard GT Dataset.

    Parameters
    ----------
    manifest : dict or str or Path
        From :func:`shadowcam.io.manifest.load_manifest`, or a manifest path. Its
        ``ground_truth`` entry names the format and the file (relative to root).
    frame_maps : bool, keyword-only
        Keep the variables that hold a map per frame (dims ``time``, ``row``, ``col``,
        e.g. an outdoor render's ``lit_center``). False leaves them out, so that a step
        that does not read them needs memory independent of the number of frames (they
        are never read from a ``shadowcam_nc`` / ``shadowcam_outdoor_nc`` file; other
        formats drop them after conversion).

    Returns
    -------
    xarray.Dataset
        In memory, in the lab standard form, or the outdoor one for the
        formats of :data:`OUTDOOR_FORMATS`; attrs ``source_format``,
        ``source_file`` and ``source_sha256``.
    """
    from shadowcam.io.manifest import load_manifest, verify_checksums

    if isinstance(manifest, (str, Path)):
        manifest = load_manifest(manifest)
    spec = manifest.get("ground_truth")
    if not spec:
        raise ValueError(f"manifest {manifest.get('manifest_path')} has no ground_truth entry (real captures have none)")
    if spec["format"] not in GT_FORMATS:
        raise ValueError(f"ground_truth.format {spec['format']!r} is not one of {sorted(GT_FORMATS)}")
    root = Path(manifest.get("root") or Path(manifest["manifest_path"]).parent)
    path = root / spec["file"]
    if not path.is_file():
        raise ValueError(f"ground truth file {path} (manifest {manifest.get('manifest_path')}) does not exist")
    checksums = verify_checksums(manifest, ["ground_truth"]) if "ground_truth" in manifest.get("files", {}) else {}
    try:
        if spec["format"] in _READS_SELECTIVELY:
            dataset = GT_FORMATS[spec["format"]](path, frame_maps=frame_maps)
        else:
            dataset = GT_FORMATS[spec["format"]](path)
            if not frame_maps:
                dataset = dataset.drop_vars([n for n, v in dataset.data_vars.items() if _per_pixel_frame(v)])
        (check_outdoor_ground_truth if spec["format"] in OUTDOOR_FORMATS else check_ground_truth)(dataset)
    except ValueError as exc:
        raise ValueError(f"ground truth {path} (format {spec['format']}): {exc}") from None
    dataset.attrs.update(
        source_format=spec["format"],
        source_file=str(path),
        source_sha256=next(iter(checksums.values()), ""),
    )
    return dataset
