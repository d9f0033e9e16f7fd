"""``shadowcam dual-coords``: shadow times -> dual coordinates ``u, v``.

Reads ``shadow_time.nc`` (and, for the calibration-plane method, the
manifest's ``calibration_plane`` homography and optional mask) and writes
``results/<ds>/dual_coords.nc``. ``--model auto`` uses the calibration plane
when the manifest has one and the calibration sweeps ``cal_u``, ``cal_v``
were timed, else uniform motion.

Offers
------
add_parser : register the step and its options.
run : compute and write the dataset.
"""

import json
import logging
from pathlib import Path

import numpy as np

from shadowcam.cli.options import parse_params
from shadowcam.io.capture_plan import choose_dual_model
from shadowcam.cameras.dual_coords import (
    DUAL_COORD_METHODS,
    dual_coords_calibration,
    dual_coords_dataset,
    dual_coords_uniform,
)

log = logging.getLogger(__name__)

#: --params keys understood besides the method's own options
_GRID_KEYS = ("dual_width", "dual_height", "min_confidence")
_UNIFORM_KEYS = ("scale", "offset", "min_spread")
_CALIBRATION_KEYS = ("models", "k_folds", "rel_tol", "abs_tol", "seed", "model_options", "min_spread",
                     "plane_window", "extrapolation_margin", "min_sweep_angle_deg")


def add_parser(subparsers, name):
    """Register ``dual-coords`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="shadow times -> dual coordinates",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--shadow-time", required=True, help="results/<ds>/shadow_time.nc")
    parser.add_argument("--manifest", required=True, help="data_manifest/<ds>.yaml or capture.json")
    parser.add_argument("--model", default="auto", choices=["auto", *DUAL_COORD_METHODS])
    parser.add_argument("--params", default="{}", help="JSON: dual_width, dual_height, min_confidence, "
                        f"uniform: {', '.join(_UNIFORM_KEYS)}; calibration: {', '.join(_CALIBRATION_KEYS)}")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/dual_coords.nc")
    return parser


def _sweep_times(shadow_time, sweep, min_confidence):
    t = shadow_time["shadow_time"].sel(sweep=sweep).transpose("row", "col").values.astype(np.float32)
    if min_confidence > 0 and "confidence" in shadow_time:
        conf = shadow_time["confidence"].sel(sweep=sweep).transpose("row", "col").values
        t = np.where(conf >= min_confidence, t, np.nan).astype(np.float32)
    return t


def run(args):
    """Compute dual coordinates from ``args.shadow_time`` and write ``args.out``."""
    import xarray as xr

    from shadowcam.io.images import read_image, write_netcdf
    from shadowcam.io.manifest import load_manifest, verify_checksums
    from shadowcam.io.provenance import attach_provenance, file_sha256

    params = parse_params(args.params,
                          allowed=set(_GRID_KEYS) | set(_UNIFORM_KEYS) | set(_CALIBRATION_KEYS))
    manifest = load_manifest(args.manifest)
    with xr.open_dataset(args.shadow_time, engine="h5netcdf") as ds:
        shadow_time = ds.load()
    sweeps = [str(s) for s in shadow_time["sweep"].values]
    for needed in ("u", "v"):
        if needed not in sweeps:
            raise ValueError(f"--shadow-time {args.shadow_time} has no sweep {needed!r} (has {sweeps})")
    plane = manifest.get("calibration_plane") or {}
    has_cal = "cal_u" in sweeps and "cal_v" in sweeps and "homography" in plane
    try:
        model = choose_dual_model(args.model, calibration_available=has_cal,
                                  missing=f"sweeps cal_u, cal_v in {args.shadow_time} (has {sweeps}) "
                                  f"and calibration_plane.homography in {args.manifest}")
    except ValueError as exc:
        raise ValueError(f"--{exc}") from None
    n_frames = tuple(int(shadow_time.attrs.get(f"n_frames_{s}", 0)) for s in ("u", "v"))
    if min(n_frames) < 1:
        raise ValueError(f"--shadow-time {args.shadow_time}: attrs n_frames_u / n_frames_v missing")
    grid = manifest.get("dual") or {}
    width = int(params.get("dual_width", grid.get("width", n_frames[0])))
    height = int(params.get("dual_height", grid.get("height", n_frames[1])))
    min_conf = float(params.get("min_confidence", 0.0))
    t_u, t_v = _sweep_times(shadow_time, "u", min_conf), _sweep_times(shadow_time, "v", min_conf)
    checksums = dict(json.loads(shadow_time.attrs.get("input_checksums", "{}")))
    checksums[str(args.shadow_time)] = file_sha256(args.shadow_time)
    if model == "uniform":
        opts = {k: params[k] for k in _UNIFORM_KEYS if k in params}
        u, v, valid, info = dual_coords_uniform(t_u, t_v, n_frames=n_frames, dual_shape=(height, width), **opts)
        reason = None
    else:
        mask = None
        if "mask" in plane:
            checksums.update(verify_checksums(manifest, ["calibration_plane"]))
            mask_path = Path(manifest["root"]) / manifest["files"]["calibration_plane"][0]
            mask = read_image(mask_path)[..., 0] > 0.5
        opts = {k: params[k] for k in _CALIBRATION_KEYS if k in params}
        u, v, valid, reason, info = dual_coords_calibration(
            t_u, t_v, cal_t_u=_sweep_times(shadow_time, "cal_u", min_conf),
            cal_t_v=_sweep_times(shadow_time, "cal_v", min_conf), homography=plane["homography"],
            dual_shape=(height, width), plane_mask=mask, **opts)
    log.info("dual coordinates: method %s, model %s, residual %.4g, %d of %d pixels valid",
             model, info["model"], info["model_residual_rms"], int(valid.sum()), valid.size)
    dataset = dual_coords_dataset(u, v, valid, info=info, method=model, reason=reason)
    dataset.attrs["dataset"] = manifest["name"]
    dataset = attach_provenance(dataset, config={"model": model, **params},
                                input_checksums=checksums, step="dual-coords")
    write_netcdf(dataset, args.out)
    log.info("wrote %s", args.out)
