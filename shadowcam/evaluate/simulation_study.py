"""The paper's simulation study (section II-C, Fig. 5), reproduced and extended.

Each study *setting* renders a small synthetic lab capture in memory (the ``tabletop``
scene of :mod:`shadowcam.synthetic.lab.scene`, exact ground truth), runs the library pipeline
``shadow_time -> dual_coords (uniform) -> dual_view (mesh)`` on it and measures the
errors of :mod:`shadowcam.lab.accuracy`: the dual view against the ground-truth reciprocal
render after one gain fit, over the whole image (holes count as zero) and inside the
ground-truth valid mask (the paper's two curves), the dual-coordinate error (dual
pixels) and the shadow-time error (frames).

The study varies one factor at a time from a baseline (:data:`BASELINE`):

==============  =====================================================================
factor          meaning (unit)
==============  =====================================================================
``frames``      frames per sweep = dual resolution N x N (mask speed ~ 1/N)
``thickness``   wire radius in units of the thinnest wire, half a mask step
``time_noise``  std of Gaussian noise added to the estimated shadow times (frames)
``path_noise``  std of the wire's per-frame offset along the mask normal, i.e.
                non-planar mask motion (mask steps, one step = one dual pixel)
``exposure``    sensor exposure: fraction of the DN range reached by the bright end
                of the scene, with shot and read noise (0 = noise-free float frames)
``bit_depth``   ADC bits of a noise-free sensor (quantisation only; 0 = float)
``light_size``  diameter of a disc (area) light in mask steps (0 = point light)
==============  =====================================================================

Offers
------
FACTORS : factor name -> (unit, description).
BASELINE : the baseline setting.
StudySetting : one setting (a value for every factor).
simulate_setting : render one setting and compute its errors.
run_study : every factor at every level -> xarray Dataset over ``(factor, level)``.
"""

import time
from dataclasses import dataclass, fields, replace

import numpy as np
import xarray as xr

from shadowcam.lab.accuracy import dual_coord_errors, dual_image_errors, shadow_time_errors
from shadowcam.cameras.dual_coords import dual_coords_uniform
from shadowcam.cameras.dual_view import resample_dual_view
from shadowcam.synthetic.lab.render import SWEEP_INDEX, prepare_capture
from shadowcam.synthetic.lab.scene import AreaLight, make_wire_sweeps
from shadowcam.synthetic.lab.scenes import make_scene
from shadowcam.synthetic.sensor import SensorModel, electrons_per_unit_radiance, raw_to_linear, simulate_raw
from shadowcam.lab.shadow_time import sweep_shadow_times

#: factor -> (unit, description)
FACTORS = {
    "frames": ("frame", "frames per sweep = dual resolution (mask speed ~ 1/frames)"),
    "thickness": ("thinnest_wire", "wire radius in units of the thinnest wire (half a mask step)"),
    "time_noise": ("frame", "std of Gaussian noise added to the shadow times"),
    "path_noise": ("mask_step", "std of the wire's offset along the mask normal (non-planar motion)"),
    "exposure": ("1", "fraction of the DN range at the scene's bright end, shot + read noise; "
                      "0 = noise-free"),
    "bit_depth": ("bit", "ADC bits of a noise-free sensor (quantisation only); 0 = float"),
    "light_size": ("mask_step", "disc light diameter (0 = point light)"),
}

#: the metrics of every setting: name -> (units, long name)
METRICS = {
    "rel_rmse_whole": ("1", "dual view vs reciprocal render, relative RMSE, whole image "
                            "(holes count as zero), one gain"),
    "rel_rmse_masked": ("1", "dual view vs reciprocal render, relative RMSE inside the GT "
                             "valid mask, one gain"),
    "dual_coord_rmse": ("dual_pixel", "RMS Euclidean error of (u, v)"),
    "dual_coord_median": ("dual_pixel", "median Euclidean error of (u, v)"),
    "dual_coord_coverage": ("1", "fraction of pixels with GT (u, v) that got an estimate"),
    "shadow_time_p95": ("frame", "95th percentile of |shadow time error|, mean of sweeps u, v"),
    "dual_coverage": ("1", "fraction of camera-visible dual pixels covered"),
    "runtime": ("s", "wall time of rendering and processing the setting"),
}

#: thinnest wire radius, in mask steps (delta): a dip about one frame wide
THINNEST_RADIUS = 0.5
#: light samples per side of a disc light
AREA_SAMPLES = 5


@dataclass(frozen=True)
class StudySetting:
    """One setting of the study: a value for every factor of :data:`FACTORS`."""

    frames: int = 48
    thickness: float = 1.0
    time_noise: float = 0.0
    path_noise: float = 0.0
    exposure: float = 0.0
    bit_depth: int = 0
    light_size: float = 0.0

    def __post_init__(self):
        if int(self.frames) < 3:
            raise ValueError(f"frames: must be >= 3, got {self.frames}")
        if not self.thickness > 0:
            raise ValueError(f"thickness: must be positive, got {self.thickness}")
        for name in ("time_noise", "path_noise", "light_size"):
            if not getattr(self, name) >= 0:
                raise ValueError(f"{name}: must be >= 0, got {getattr(self, name)}")
        if not 0 <= self.exposure <= 1:
            raise ValueError(f"exposure: must be in [0, 1] (0 = noise-free), got {self.exposure}")
        if self.bit_depth and not 8 <= int(self.bit_depth) <= 16:
            raise ValueError(f"bit_depth: must be 0 (float) or 8..16, got {self.bit_depth}")


#: the baseline: 48 x 48 dual view, thinnest wire, point light, noise-free float frames
BASELINE = StudySetting()


def _sensor_for(setting):
    """(SensorModel, noise flag) of a setting, or None for noise-free float frames."""
    if setting.bit_depth:
        bits = int(setting.bit_depth)  # same electrons per DN step ratio as the 12-bit model
        return SensorModel(bit_depth=bits, black_level=2 ** (bits - 4), gain=2.0 ** (bits - 12),
                           read_noise=6.0 * 2.0 ** (bits - 12)), False
    if setting.exposure:
        return SensorModel(), True
    return None


def _to_linear(radiance, *, setting, reference, seed):
    """Frames (T, rows, cols, 3) or an image (rows, cols, 3) through the setting's sensor.

    The exposure places the 99.5th percentile of `reference` at the setting's fraction
    of the DN range (0.8 unless ``exposure`` is set). Returns float32 with black = 0 and
    white level = 1, as the decode stage delivers.
    """
    sensor = _sensor_for(setting)
    target = setting.exposure or 0.8
    model = SensorModel() if sensor is None else sensor[0]
    electrons = electrons_per_unit_radiance(reference, sensor=model, target_fraction=target)
    if sensor is None:  # the mean DN without rounding, normalised
        span = model.white_level - model.black_level
        return (radiance * np.float32(electrons * model.gain / span)).astype(np.float32)
    stack = radiance if radiance.ndim == 4 else radiance[None]
    out = np.stack([raw_to_linear(simulate_raw(frame, sensor=model, scale=electrons,
                                               seed=[*seed, k], noise=sensor[1], mosaic=False),
                                  sensor=model) for k, frame in enumerate(stack)])
    return out if radiance.ndim == 4 else out[0]


def _scene_for(setting, *, scene, size, seed):
    base = make_scene(scene, seed=seed, height=size, width=size, frames=int(setting.frames))
    mask = base.mask
    sweeps = make_wire_sweeps(mask, radius=setting.thickness * THINNEST_RADIUS * mask.delta)
    light = base.light
    if setting.light_size > 0:
        light = AreaLight(light.position, mask.normal, setting.light_size * mask.delta,
                          "disc", light.intensity, AREA_SAMPLES)
    return replace(base, sweeps=sweeps, light=light)


def simulate_setting(setting, *, scene="tabletop", size=64, supersample=2, seed=0,
                     method="edge_fit", half_window=4, dual_view_method="mesh"):
    """Render one setting in memory, run the dual pipeline and measure its errors.

    Parameters
    ----------
    setting : StudySetting
    scene : str, keyword-only
        Preset of :data:`shadowcam.synthetic.lab.scenes.SCENES`.
    size : int
        Camera rows = cols (even).
    supersample : int
        Sub-samples per pixel side of the renders.
    seed : int
        Scene, sensor-noise, path-noise and time-noise seed.
    method : str
        Shadow-time method (key of ``SHADOW_TIME_METHODS``).
    half_window : int
        Frames kept each side of a dip by the tracker; lowered for short sweeps to
        ``max(1, (frames - 4) // 2)`` so that at least 3 frames measure the lit level.
    dual_view_method : str
        Resampler of ``shadowcam.cameras.dual_view.DUAL_VIEW_METHODS``.

    Returns
    -------
    dict of str to float
        The keys of :data:`METRICS`.
    """
    if not isinstance(setting, StudySetting):
        raise ValueError(f"setting: expected a StudySetting, got {type(setting).__name__}")
    started = time.perf_counter()
    sc = _scene_for(setting, scene=scene, size=size, seed=seed)
    capture = prepare_capture(sc, supersample=supersample, calibration=False)
    gt = capture.ground_truth
    n = int(setting.frames)
    half_window = max(1, min(int(half_window), (n - 4) // 2))
    rng = np.random.default_rng([seed, 17])
    times = {}
    errors = []
    for name in ("u", "v"):
        offsets = (rng.normal(0.0, setting.path_noise * sc.mask.delta, n)
                   if setting.path_noise > 0 else None)
        frames = _to_linear(capture.frames(name, path_offsets=offsets), setting=setting,
                            reference=capture.reference, seed=(seed, SWEEP_INDEX[name]))
        result = sweep_shadow_times([frames], (size, size), method=method,
                                    half_window=half_window)
        t = result["shadow_time"].astype(np.float64)
        if setting.time_noise > 0:
            t = t + rng.normal(0.0, setting.time_noise, t.shape)
        times[name] = t
        errors.append(shadow_time_errors(t, gt[f"t_{name}"].values, lit=gt["lit"].values))
    u, v, valid, _ = dual_coords_uniform(times["u"], times["v"], n_frames=(n, n))
    colours = _to_linear(capture.reference, setting=setting, reference=capture.reference,
                         seed=(seed, SWEEP_INDEX["reference"]))
    image, coverage = resample_dual_view(colours, u, v, shape=(n, n), valid=valid,
                                         method=dual_view_method)
    img = dual_image_errors(image, coverage, gt["reciprocal"].values,
                            dual_cam_visible=gt["dual_cam_visible"].values)
    coords = dual_coord_errors(u, v, gt["t_u"].values, gt["t_v"].values, valid=valid)
    return {
        "rel_rmse_whole": img["rel_rmse_whole"],
        "rel_rmse_masked": img["rel_rmse_masked"],
        "dual_coord_rmse": coords["rmse"],
        "dual_coord_median": coords["median"],
        "dual_coord_coverage": coords["coverage"],
        "shadow_time_p95": float(np.mean([e["p95"] for e in errors])),
        "dual_coverage": img["coverage_of_visible"],
        "runtime": time.perf_counter() - started,
    }


def run_study(levels, *, baseline=BASELINE, progress=None, **options):
    """Vary each factor over its levels, the others held at the baseline.

    Parameters
    ----------
    levels : mapping of str to sequence of float
        Factor name (key of :data:`FACTORS`) -> the values to try.
    baseline : StudySetting, keyword-only
    progress : callable, optional
        Called as ``progress(factor, value, metrics)`` after each setting.
    **options
        Passed to :func:`simulate_setting` (``scene``, ``size``, ``supersample``,
        ``seed``, ``method``, ``half_window``, ``dual_view_method``).

    Returns
    -------
    xarray.Dataset
        Dims ``factor`` (the factors given, in order) and ``level`` (0..L-1, L the
        longest list); coordinate ``value (factor, level)`` (NaN where a factor has
        fewer levels), ``status (factor, level)`` ("ok" or "failed: <why>", when a
        step raised ``ValueError``; its metrics are then NaN) and every metric of
        :data:`METRICS` over ``(factor, level)``.
    """
    if not levels:
        raise ValueError("levels: give at least one factor and its values")
    unknown = set(levels) - set(FACTORS)
    if unknown:
        raise ValueError(f"levels: unknown factors {sorted(unknown)}; choose from {list(FACTORS)}")
    names = [f.name for f in fields(StudySetting)]
    factors = [f for f in names if f in levels]
    width = max(len(levels[f]) for f in factors)
    if width < 1:
        raise ValueError("levels: every factor needs at least one value")
    value = np.full((len(factors), width), np.nan)
    data = {m: np.full((len(factors), width), np.nan) for m in METRICS}
    status = np.full((len(factors), width), "", dtype=object)
    for i, factor in enumerate(factors):
        for j, level in enumerate(levels[factor]):
            setting = replace(baseline, **{factor: type(getattr(baseline, factor))(level)})
            value[i, j] = float(level)
            try:
                metrics = simulate_setting(setting, **options)
            except ValueError as exc:  # the pipeline refused the data: record why
                status[i, j] = f"failed: {exc}"
                metrics = {m: float("nan") for m in METRICS}
            else:
                status[i, j] = "ok"
            for key, val in metrics.items():
                data[key][i, j] = val
            if progress is not None:
                progress(factor, level, metrics)
    dims = ("factor", "level")
    ds = xr.Dataset(
        {m: (dims, data[m], {"units": METRICS[m][0], "long_name": METRICS[m][1]})
         for m in METRICS},
        coords={"factor": factors, "level": np.arange(width),
                "value": (dims, value, {"long_name": "the factor's value at this level"}),
                "factor_units": ("factor", [FACTORS[f][0] for f in factors]),
                "status": (dims, status.astype(str), {"long_name": "ok, or why the pipeline "
                                                      "refused the setting"})},
        attrs={"baseline": repr(baseline), "description": "one-factor-at-a-time simulation "
               "study (paper II-C, Fig. 5); see shadowcam.evaluate.simulation_study",
               **{f"option_{k}": v for k, v in options.items()}},
    )
    return ds
