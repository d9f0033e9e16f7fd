"""``shadowcam dual-coords``: shadow times -> dual coordinates ``u, v``.

Reads ``shadow_time.nc`` (and, for the calibration-plane method, the
manifest's ``calibration_plane`` homography and optional mask) and writes
``results/<ds>/dual_coords.nc`` (:func:`shadowcam.cameras.models.capture_dual_coords`: the
capture plan's camera model; the standard pair runs the dual-coordinate model).
``--model auto`` tests uniform motion against the calibration plane when the manifest
has one and the calibration sweeps ``cal_u``, ``cal_v`` were timed, else assumes it.

Example::

    shadowcam dual-coords --shadow-time results/dev_spheres/shadow_time.nc \\
        --manifest data_manifest/dev_spheres.yaml --model auto --out results/dev_spheres/dual_coords.nc

Offers
------
add_parser : register the step and its options.
run : compute and write the dataset.
"""

import logging
from pathlib import Path

from shadowcam._shared.coverage import MIN_COVERAGE
from shadowcam.cameras.dual_coords import (
    CALIBRATION_OPTIONS, DUAL_COORD_METHODS, UNIFORM_OPTIONS, choose_dual_coords_method,
)
from shadowcam.cameras.models import capture_dual_coords
from shadowcam.cli.options import parse_params
from shadowcam.io.capture_plan import capture_plan
from shadowcam.io.datasets import open_dataset, write_dataset
from shadowcam.io.images import read_image
from shadowcam.io.manifest import load_manifest, verify_checksums
from shadowcam.io.provenance import file_sha256

log = logging.getLogger(__name__)

_GRID_KEYS = ("dual_width", "dual_height", "min_confidence", "min_coverage")


def add_parser(subparsers, name):
    """Register ``dual-coords`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="shadow times -> dual coordinates")
    parser.add_argument("--shadow-time", required=True, help="results/<ds>/shadow_time.nc")
    parser.add_argument("--manifest", required=True, help="data_manifest/<ds>.yaml or capture.json")
    parser.add_argument("--model", default="auto", choices=["auto", *DUAL_COORD_METHODS],
                        help="mapping from shadow times to u, v (default auto: the simplest the data support)")
    parser.add_argument("--params", default="{}", help="JSON: dual_width, dual_height, min_confidence, min_coverage, "
                        f"uniform: {', '.join(UNIFORM_OPTIONS)}; calibration: {', '.join(CALIBRATION_OPTIONS)}")
    parser.add_argument("--out", required=True, help="output netCDF, e.g. results/<ds>/dual_coords.nc")
    return parser


def run(args):
    """Compute dual coordinates from ``args.shadow_time`` and write ``args.out``."""
    params = parse_params(args.params, allowed={*_GRID_KEYS, *UNIFORM_OPTIONS, *CALIBRATION_OPTIONS})
    manifest = load_manifest(args.manifest)
    shadow_time = open_dataset(args.shadow_time)
    plane, grid = manifest.get("calibration_plane") or {}, manifest.get("dual") or {}
    model = choose_dual_coords_method(shadow_time, args.model, homography=plane.get("homography"))
    checksums = {str(args.shadow_time): file_sha256(args.shadow_time)}
    mask = None
    if model == "calibration" and "mask" in plane:
        checksums.update(verify_checksums(manifest, ["calibration_plane"]))
        mask = read_image(Path(manifest["root"]) / manifest["files"]["calibration_plane"][0])[..., 0] > 0.5
    plan = capture_plan(args.manifest, dual_model=model)
    dataset = capture_dual_coords(
        shadow_time, plan.camera, camera_model=plan.camera_model, dual_model=model, dual_width=params.get("dual_width", grid.get("width")),
        dual_height=params.get("dual_height", grid.get("height")),
        min_confidence=params.get("min_confidence", 0.0), min_coverage=params.get("min_coverage", MIN_COVERAGE),
        homography=plane.get("homography"), plane_mask=mask,
        **{k: v for k, v in params.items() if k not in _GRID_KEYS})
    log.info("dual coordinates: method %s, model %s, residual %.4g, %d of %d pixels valid", dataset.attrs["method"],
             dataset.attrs["model"], dataset.attrs["model_residual_rms"], int(dataset["valid"].sum()),
             dataset["valid"].size)
    dataset.attrs["dataset"] = manifest["name"]
    write_dataset(dataset, args.out, config={"model": model, **params}, inputs=(shadow_time,), checksums=checksums,
                  step="dual-coords")
