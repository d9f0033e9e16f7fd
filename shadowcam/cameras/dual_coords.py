"""Shadow times -> dual (shadow-camera) coordinates ``u, v``.

Two ways (paper section II-A):

* **uniform motion**: the mask moves uniformly, so a shadow time is a dual
  coordinate up to scale and offset, ``u = a_u t_u + b_u``,
  ``v = a_v t_v + b_v``. Default: one dual pixel per frame (``u = t_u``).
* **calibration plane**: the sweeps are repeated over a bare plane whose
  camera->plane homography is known. Each plane pixel then gives a time pair
  ``(t_u, t_v)`` and a plane point ``(x, y)``; a map ``(t_u, t_v) -> (x, y)``
  is fitted with candidate models of increasing complexity (``affine`` 6
  parameters, ``homography`` 8, smoothing thin-plate spline ``tps``), the
  simplest one whose k-fold cross-validated residual is within a tolerance of
  the best is kept, and it is applied to the scene's times. Plane coordinates
  are mapped to the dual grid by a rectangular plane window (default: the
  bounding box of the calibration points) whose edges are the grid's edges.

Dual pixel convention (docs/contracts.md): the centre of dual column ``i``
is ``u = i`` (row ``j``: ``v = j``), so the grid edges are at ``-0.5`` and
``width - 0.5``.

Ill-conditioning is never silent: too few or collinear calibration points and
nearly parallel sweeps raise ``ValueError``; scene pixels where the local map
is near singular or lies outside the calibrated time range are marked invalid
with a reason code.

Offers
------
DUAL_COORD_MODELS : candidate calibration-plane models, name -> ``PlaneModel`` spec.
DUAL_COORD_METHODS : name -> function, ``uniform`` and ``calibration``.
PROJECTIVE_MODELS : calibration-plane models exact under uniform mask motion.
REASON_FLAGS : reason code -> meaning for the ``reason`` output.
dual_coords_uniform : times -> dual coordinates under uniform motion.
dual_coords_calibration : times -> dual coordinates through a calibration plane.
fit_time_to_plane : fit and select the ``(t_u, t_v) -> (x, y)`` model (cross-validated).
apply_homography : apply a 3x3 homography to points.
sweep_crossing_sine : per-point sine of the angle between the two sweep directions.
dual_coords_dataset : assemble the ``dual_coords`` xarray Dataset.
UNIFORM_OPTIONS, CALIBRATION_OPTIONS : options of the two methods accepted by the front function.
choose_dual_model : the dual-coordinate method that runs for a requested one (``auto`` decided once).
choose_dual_coords_method : the same, for what a shadow-time dataset holds.
dual_coords_from_shadow_time : shadow-time dataset -> dual-coordinates dataset (either method).
"""

import json
from dataclasses import dataclass, field

import numpy as np
import xarray as xr
from scipy.interpolate import RBFInterpolator
from scipy.optimize import least_squares

from shadowcam._shared.coverage import MIN_COVERAGE, check_coverage
from shadowcam._shared.validation import check_array, check_in_interval

#: reason codes of the ``reason`` output variable
REASON_FLAGS = {
    0: "ok",
    1: "no_time",
    2: "outside_calibration",
    3: "ill_conditioned",
}


# --------------------------------------------------------------------------
# small helpers
# --------------------------------------------------------------------------


def apply_homography(homography, points):
    """Apply a homography to 2-D points.

    Parameters
    ----------
    homography : (3, 3) array_like
    points : (N, 2) ndarray
        Input points ``(x, y)`` (for camera pixels: ``(col, row)``).

    Returns
    -------
    (N, 2) float64 ndarray
        Mapped points; NaN where the point maps to infinity.
    """
    h = np.asarray(homography, dtype=np.float64)
    if h.shape != (3, 3) or not np.all(np.isfinite(h)):
        raise ValueError(f"homography must be a finite 3x3 matrix; got shape {h.shape}")
    p = np.asarray(points, dtype=np.float64)
    check_array(p, "points", shape=(None, 2))
    w = p @ h[2, :2] + h[2, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        x = (p @ h[0, :2] + h[0, 2]) / w
        y = (p @ h[1, :2] + h[1, 2]) / w
    out = np.stack([x, y], axis=1)
    out[np.abs(w) < 1e-12] = np.nan
    return out


def _normalising_similarity(points):
    """Hartley normalisation: similarity taking points to mean 0, RMS radius sqrt(2)."""
    mean = points.mean(axis=0)
    rms = np.sqrt(np.mean(np.sum((points - mean) ** 2, axis=1)))
    s = np.sqrt(2.0) / rms if rms > 0 else 1.0
    return np.array([[s, 0.0, -s * mean[0]], [0.0, s, -s * mean[1]], [0.0, 0.0, 1.0]])


def _spread_ratio(points):
    """Smaller / larger singular value of the centred point cloud (0 = collinear)."""
    centred = points - points.mean(axis=0)
    sv = np.linalg.svd(centred, compute_uv=False)
    return float(sv[1] / sv[0]) if sv[0] > 0 else 0.0


# --------------------------------------------------------------------------
# candidate models (t_u, t_v) -> (x, y)
# --------------------------------------------------------------------------


def _fit_affine(src, dst, **_):
    design = np.column_stack([src, np.ones(len(src))])
    coef, *_ = np.linalg.lstsq(design, dst, rcond=None)  # (3, 2)

    def model(points):
        return np.column_stack([points, np.ones(len(points))]) @ coef

    model.matrix = np.vstack([coef.T, [0.0, 0.0, 1.0]])
    return model


def _fit_homography(src, dst, *, refine=True, **_):
    ts, td = _normalising_similarity(src), _normalising_similarity(dst)
    s = apply_homography(ts, src)
    d = apply_homography(td, dst)
    n = len(src)
    a = np.zeros((2 * n, 9))
    a[0::2, 0:2], a[0::2, 2] = s, 1.0
    a[0::2, 6:8], a[0::2, 8] = -d[:, :1] * s, -d[:, 0]
    a[1::2, 3:5], a[1::2, 5] = s, 1.0
    a[1::2, 6:8], a[1::2, 8] = -d[:, 1:] * s, -d[:, 1]
    hn = np.linalg.svd(a, full_matrices=False)[2][-1].reshape(3, 3)
    if refine and n >= 5:
        # geometric (transfer) error, Levenberg-Marquardt in normalised coordinates
        hn = hn / hn[2, 2] if abs(hn[2, 2]) > 1e-12 else hn

        def residual(p):
            return (apply_homography(np.append(p, 1.0).reshape(3, 3), s) - d).ravel()

        sol = least_squares(residual, hn.ravel()[:8], method="lm", xtol=1e-15, ftol=1e-15)
        if np.all(np.isfinite(sol.x)):
            hn = np.append(sol.x, 1.0).reshape(3, 3)
    h = np.linalg.inv(td) @ hn @ ts
    h = h / h[2, 2] if abs(h[2, 2]) > 1e-12 else h

    def model(points):
        return apply_homography(h, points)

    model.matrix = h
    return model


def _fit_tps(src, dst, *, smoothing=1e-3, max_points=1000, seed=0, **_):
    rng = np.random.default_rng(seed)
    if len(src) > max_points:
        keep = rng.choice(len(src), size=max_points, replace=False)
        src, dst = src[keep], dst[keep]
    t = _normalising_similarity(src)
    interpolator = RBFInterpolator(
        apply_homography(t, src), dst, kernel="thin_plate_spline", smoothing=smoothing, degree=1
    )

    def model(points):
        out = np.empty((len(points), 2))
        for start in range(0, len(points), 20000):  # bounded kernel-matrix memory
            block = points[start : start + 20000]
            out[start : start + 20000] = interpolator(apply_homography(t, block))
        return out

    model.matrix = None
    return model


@dataclass(frozen=True)
class PlaneModel:
    """A candidate calibration-plane model.

    Attributes
    ----------
    fit : callable
        ``fit(times (N, 2), plane_xy (N, 2), **options) -> model``; ``model(times)``
        returns ``(N, 2)`` plane points.
    n_params : int
        Number of free parameters (complexity order; at least ``n_params + 2``
        points are required).
    description : str
    """

    fit: callable
    n_params: int
    description: str = ""


#: candidate models of the (t_u, t_v) -> plane (x, y) map, simplest first
DUAL_COORD_MODELS = {
    "affine": PlaneModel(_fit_affine, 6, "affine map (uniform motion, any sweep directions)"),
    "homography": PlaneModel(
        _fit_homography, 8, "projective map (normalised DLT + Levenberg-Marquardt)"
    ),
    "tps": PlaneModel(
        _fit_tps,
        20,
        "smoothing thin-plate spline (scipy RBFInterpolator, degree 1) on <= max_points "
        "samples; n_params is a nominal minimum sample count",
    ),
}


def sweep_crossing_sine(model, times, *, step=0.5):
    """Sine of the angle between the two sweep directions on the plane.

    The sweep directions at a point are the gradients of ``t_u`` and ``t_v``
    with respect to plane ``(x, y)``, i.e. the rows of the inverse Jacobian of
    the fitted map ``(t_u, t_v) -> (x, y)`` (central differences, ``step``
    frames). 1 = perpendicular sweeps, 0 = parallel (singular map).

    Parameters
    ----------
    model : callable
        ``model(times (N, 2)) -> (N, 2)`` plane points.
    times : (N, 2) ndarray
    step : float, keyword-only

    Returns
    -------
    (N,) float64 ndarray
        ``|sin|`` of the crossing angle; 0 where the Jacobian is singular or not finite.
    """
    times = np.asarray(times, dtype=np.float64)
    du = np.array([step, 0.0])
    dv = np.array([0.0, step])
    jx = (model(times + du) - model(times - du)) / (2 * step)  # d(x,y)/dt_u
    jy = (model(times + dv) - model(times - dv)) / (2 * step)  # d(x,y)/dt_v
    det = jx[:, 0] * jy[:, 1] - jy[:, 0] * jx[:, 1]
    # inverse Jacobian rows: grad t_u = (jy_y, -jy_x)/det, grad t_v = (-jx_y, jx_x)/det
    with np.errstate(divide="ignore", invalid="ignore"):
        sine = np.abs(det) / (np.hypot(jy[:, 0], jy[:, 1]) * np.hypot(jx[:, 0], jx[:, 1]))
    return np.where(np.isfinite(sine), sine, 0.0)


@dataclass
class PlaneFit:
    """Result of `fit_time_to_plane`.

    Attributes
    ----------
    name : str
        Chosen model name (a key of `DUAL_COORD_MODELS`).
    model : callable
        Fitted on all points; ``model(times (N, 2)) -> (N, 2)`` plane points.
    residual_rms : float
        Cross-validated RMS residual of the chosen model (in `residual_units`).
    candidates : list of dict
        Per candidate: ``name``, ``n_params``, ``cv_rms``, ``cv_se`` (its
        standard error), ``fit_rms``, ``status`` (``ok`` or why it was
        skipped), ``within_noise`` (``cv_rms <= limit``), ``chosen``.
    limit : float
        Largest CV residual within the noise of the best candidate.
    residual_units : str
    time_range : (2, 2) ndarray
        ``[[t_u_min, t_u_max], [t_v_min, t_v_max]]`` of the calibration points.
    """

    name: str
    model: callable
    residual_rms: float
    candidates: list = field(default_factory=list)
    residual_units: str = "plane"
    time_range: np.ndarray = None
    limit: float = None


def _rms(a, b):
    return float(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=1))))


def fit_time_to_plane(
    times,
    plane_xy,
    *,
    models=("affine", "homography", "tps"),
    k_folds=5,
    rel_tol=0.0,
    abs_tol=0.1,
    unit_scale=1.0,
    min_sweep_angle_deg=15.0,
    min_spread=0.05,
    seed=0,
    model_options=None,
):
    """Fit the calibration map ``(t_u, t_v) -> (x, y)`` and choose its model.

    Every candidate is scored by k-fold cross-validation; the simplest model
    (fewest parameters) whose CV residual is within the noise of the best one
    is chosen: at most ``best + max(se, abs_tol) + rel_tol * best``, where
    ``se`` is the standard error of the best model's CV residual (the
    one-standard-error rule) and `abs_tol` a floor below which residual
    differences are shadow-time noise, not model misfit.

    Parameters
    ----------
    times : (N, 2) ndarray
        Shadow times ``(t_u, t_v)`` (frames) of calibration-plane pixels.
    plane_xy : (N, 2) ndarray
        Plane coordinates of the same pixels.
    models : sequence of str, keyword-only
        Candidate names (keys of `DUAL_COORD_MODELS`).
    k_folds : int
        Folds of the cross-validation (>= 2).
    rel_tol, abs_tol : float
        Selection tolerance (see above); `abs_tol` is in reporting units
        (``plane / unit_scale``, dual pixels in :func:`dual_coords_calibration`):
        default 0.1, the sub-frame precision of shadow times.
    unit_scale : float
        Plane units per reporting unit (e.g. plane units per dual pixel);
        residuals are reported divided by it.
    min_sweep_angle_deg : float
        Below this median crossing angle of the two sweeps the problem is
        ill-conditioned and ``ValueError`` is raised.
    min_spread : float
        Smallest accepted ratio of the singular values of the centred time
        and plane point clouds (0 = collinear).
    seed : int
        Seed of the fold assignment (and of the TPS subsample).
    model_options : mapping of str to mapping, optional
        Extra options per model, e.g. ``{"tps": {"smoothing": 1e-2}}``.

    Returns
    -------
    PlaneFit

    Raises
    ------
    ValueError
        Mismatched/non-finite input, too few points for any model, collinear
        points, or nearly parallel sweeps.
    """
    times = np.asarray(times, dtype=np.float64)
    plane_xy = np.asarray(plane_xy, dtype=np.float64)
    check_array(times, "times", shape=(None, 2))
    if plane_xy.shape != times.shape:
        raise ValueError(f"plane_xy: shape {plane_xy.shape} differs from times {times.shape}")
    if not (np.all(np.isfinite(times)) and np.all(np.isfinite(plane_xy))):
        raise ValueError("times/plane_xy: calibration points must be finite")
    unknown = [m for m in models if m not in DUAL_COORD_MODELS]
    if unknown or not models:
        raise ValueError(f"models: unknown {unknown}; choose from {sorted(DUAL_COORD_MODELS)}")
    if k_folds < 2:
        raise ValueError(f"k_folds must be >= 2; got {k_folds}")
    if unit_scale <= 0:
        raise ValueError(f"unit_scale must be > 0; got {unit_scale}")
    n = len(times)
    order = sorted(models, key=lambda m: DUAL_COORD_MODELS[m].n_params)
    fewest = DUAL_COORD_MODELS[order[0]].n_params + 2
    if n < fewest:
        raise ValueError(
            f"calibration points: {n} points are too few (model {order[0]!r} needs >= {fewest}); "
            "check the calibration sweeps and the plane mask"
        )
    for name, pts in (("times", times), ("plane_xy", plane_xy)):
        ratio = _spread_ratio(pts)
        if ratio < min_spread:
            raise ValueError(
                f"calibration {name}: points are (nearly) collinear (spread ratio {ratio:.3g} "
                f"< {min_spread}); the calibration plane must be swept in two directions "
                "(are the two sweeps parallel?)"
            )
    options = dict(model_options or {})
    folds = np.random.default_rng(seed).permutation(n) % k_folds
    candidates = []
    for name in order:
        spec = DUAL_COORD_MODELS[name]
        entry = {"name": name, "n_params": spec.n_params, "cv_rms": None, "cv_se": None, "fit_rms": None}
        if n < spec.n_params + 2:
            entry["status"] = f"skipped: {n} points < n_params + 2 = {spec.n_params + 2}"
            candidates.append(entry)
            continue
        opts = {"seed": seed, **options.get(name, {})}
        sq = np.empty(n)
        for k in range(k_folds):
            train, test = folds != k, folds == k
            model = spec.fit(times[train], plane_xy[train], **opts)
            pred = model(times[test])
            sq[test] = np.sum((pred - plane_xy[test]) ** 2, axis=1)
        sq = np.where(np.isfinite(sq), sq, np.inf)
        rms = float(np.sqrt(np.mean(sq)))
        entry["cv_rms"] = rms / unit_scale
        # standard error of the RMS from that of the mean square (delta method)
        entry["cv_se"] = (float(np.std(sq) / np.sqrt(n) / (2 * rms)) if 0 < rms < np.inf else 0.0) / unit_scale
        model = spec.fit(times, plane_xy, **opts)
        entry["fit_rms"] = _rms(model(times), plane_xy) / unit_scale
        entry["status"] = "ok" if np.isfinite(entry["cv_rms"]) else "failed: non-finite residual"
        entry["_model"] = model
        candidates.append(entry)
    scored = [c for c in candidates if c["status"] == "ok"]
    if not scored:
        raise ValueError(f"calibration points: no candidate model could be fitted: {candidates}")
    best = min(scored, key=lambda c: c["cv_rms"])
    limit = best["cv_rms"] * (1 + rel_tol) + max(best["cv_se"], abs_tol)
    chosen = next(c for c in scored if c["cv_rms"] <= limit)
    sine = sweep_crossing_sine(chosen["_model"], times)
    angle = float(np.degrees(np.arcsin(np.clip(np.median(sine), 0.0, 1.0))))
    if angle < min_sweep_angle_deg:
        raise ValueError(
            f"calibration sweeps: the two sweep directions cross at {angle:.1f} deg "
            f"(< min_sweep_angle_deg = {min_sweep_angle_deg}); nearly parallel sweeps "
            "make (t_u, t_v) -> plane ill-conditioned"
        )
    for c in candidates:
        c["chosen"] = c is chosen
    model = chosen.pop("_model")
    for c in candidates:
        c.pop("_model", None)
    for c in candidates:
        c["within_noise"] = c["status"] == "ok" and c["cv_rms"] <= limit
    return PlaneFit(
        name=chosen["name"],
        model=model,
        residual_rms=chosen["cv_rms"],
        candidates=candidates,
        time_range=np.stack([times.min(axis=0), times.max(axis=0)], axis=1),
        limit=float(limit),
    )


# --------------------------------------------------------------------------
# the two methods
# --------------------------------------------------------------------------


def _check_time_maps(t_u, t_v):
    t_u = np.asarray(t_u)
    t_v = np.asarray(t_v)
    check_array(t_u, "t_u", ndim=2)
    if t_v.shape != t_u.shape:
        raise ValueError(f"t_v: shape {t_v.shape} differs from t_u {t_u.shape}")
    return t_u, t_v


def dual_coords_uniform(
    t_u, t_v, *, n_frames, dual_shape=None, scale=None, offset=None, min_spread=0.05
):
    """Dual coordinates under uniform mask motion: ``u = a_u t_u + b_u`` (same for v).

    Parameters
    ----------
    t_u, t_v : (rows, cols) ndarray
        Shadow times (frames) of the u and v sweeps; NaN = none.
    n_frames : (int, int), keyword-only
        Frames of the u and v sweeps.
    dual_shape : (int, int), optional
        ``(height, width)`` of the dual grid; default ``(n_frames_v, n_frames_u)``
        (one dual pixel per frame, ``u = t_u``). Otherwise the frame range
        ``[-0.5, N - 0.5]`` is stretched onto ``[-0.5, width - 0.5]``.
    scale, offset : (float, float), optional
        Explicit ``(a_u, a_v)`` and ``(b_u, b_v)``; override `dual_shape`'s stretch.
    min_spread : float
        If the valid ``(t_u, t_v)`` pairs are (nearly) collinear (singular-value
        ratio below this), the sweeps are (nearly) parallel and ``ValueError``
        is raised. 0 disables the check.

    Returns
    -------
    u, v : (rows, cols) float32 ndarray
        Dual coordinates (dual pixels), NaN where invalid.
    valid : (rows, cols) bool ndarray
    info : dict
        ``model``, ``scale``, ``offset``, ``dual_width``, ``dual_height``,
        ``model_residual_rms`` (0: exact by assumption), ``candidates``.
    """
    t_u, t_v = _check_time_maps(t_u, t_v)
    n_u, n_v = (int(x) for x in n_frames)
    if n_u < 1 or n_v < 1:
        raise ValueError(f"n_frames must be positive; got {n_frames}")
    height, width = (n_v, n_u) if dual_shape is None else (int(x) for x in dual_shape)
    if height < 1 or width < 1:
        raise ValueError(f"dual_shape must be positive; got {dual_shape}")
    if scale is None:
        scale = (width / n_u, height / n_v)
    if offset is None:
        offset = (0.5 * scale[0] - 0.5, 0.5 * scale[1] - 0.5)
    valid = np.isfinite(t_u) & np.isfinite(t_v)
    if min_spread > 0 and valid.sum() >= 3:
        points = np.column_stack([t_u[valid], t_v[valid]]).astype(np.float64)
        for name, times, n in (("u", points[:, 0], n_u), ("v", points[:, 1], n_v)):
            if np.all(times == times[0]):
                raise ValueError(
                    f"shadow_time: all {len(times)} pixels timed in both sweeps have t_{name} = {times[0]:g}; "
                    f"sweep {name} ({n} frames) is too short, or its shadow did not move across the image"
                )
        ratio = _spread_ratio(points)
        if ratio < min_spread:
            raise ValueError(
                f"shadow_time: the u and v times are (nearly) collinear (spread ratio "
                f"{ratio:.3g} < min_spread = {min_spread}); nearly parallel sweeps do not "
                "define dual coordinates"
            )
    u = np.where(valid, scale[0] * t_u + offset[0], np.nan).astype(np.float32)
    v = np.where(valid, scale[1] * t_v + offset[1], np.nan).astype(np.float32)
    info = {
        "model": "uniform",
        "scale": [float(s) for s in scale],
        "offset": [float(o) for o in offset],
        "dual_width": width,
        "dual_height": height,
        "model_residual_rms": 0.0,
        "candidates": [{"name": "uniform", "n_params": 4, "status": "assumed", "chosen": True}],
    }
    return u, v, valid, info


def dual_coords_calibration(
    t_u,
    t_v,
    *,
    cal_t_u,
    cal_t_v,
    homography,
    dual_shape,
    plane_mask=None,
    plane_window=None,
    extrapolation_margin=1.0,
    min_sweep_angle_deg=15.0,
    **fit_options,
):
    """Dual coordinates through a calibration plane (paper II-A, second method).

    Parameters
    ----------
    t_u, t_v : (rows, cols) ndarray
        Scene shadow times (frames).
    cal_t_u, cal_t_v : (rows, cols) ndarray, keyword-only
        Shadow times of the calibration sweeps over the bare plane.
    homography : (3, 3) array_like
        Camera ``(col, row)`` pixel-centre index -> plane ``(x, y)``.
    dual_shape : (int, int)
        ``(height, width)`` of the dual grid.
    plane_mask : (rows, cols) bool ndarray, optional
        Camera pixels that see the plane in the calibration sweeps (default: all
        pixels with both calibration times).
    plane_window : (x_min, y_min, x_max, y_max), optional
        Plane rectangle covered by the dual grid (its edges are the grid's
        edges); default: bounding box of the calibration points.
    extrapolation_margin : float
        Scene times more than this many frames outside the calibration time
        range are marked ``outside_calibration``.
    min_sweep_angle_deg : float
        Global check (raises) and per-pixel check (marks ``ill_conditioned``).
    **fit_options
        Passed to `fit_time_to_plane` (``models``, ``k_folds``, ``rel_tol``,
        ``abs_tol`` (dual pixels), ``seed``, ``model_options``, ``min_spread``).

    Returns
    -------
    u, v : (rows, cols) float32 ndarray
    valid : (rows, cols) bool ndarray
    reason : (rows, cols) uint8 ndarray
        Codes of `REASON_FLAGS`.
    info : dict
        ``model``, ``model_residual_rms`` (CV, dual pixels), ``candidates``,
        ``plane_window``, ``dual_width``, ``dual_height``.
    """
    t_u, t_v = _check_time_maps(t_u, t_v)
    cal_t_u, cal_t_v = _check_time_maps(cal_t_u, cal_t_v)
    if cal_t_u.shape != t_u.shape:
        raise ValueError(f"cal_t_u: shape {cal_t_u.shape} differs from t_u {t_u.shape}")
    height, width = (int(x) for x in dual_shape)
    if height < 1 or width < 1:
        raise ValueError(f"dual_shape must be positive; got {dual_shape}")
    on_plane = np.isfinite(cal_t_u) & np.isfinite(cal_t_v)
    if plane_mask is not None:
        plane_mask = np.asarray(plane_mask, dtype=bool)
        if plane_mask.shape != t_u.shape:
            raise ValueError(f"plane_mask: shape {plane_mask.shape} differs from t_u {t_u.shape}")
        on_plane &= plane_mask
    rows, cols = np.nonzero(on_plane)
    plane_xy = apply_homography(homography, np.column_stack([cols, rows]).astype(np.float64))
    cal_times = np.column_stack([cal_t_u[on_plane], cal_t_v[on_plane]]).astype(np.float64)
    finite = np.all(np.isfinite(plane_xy), axis=1)
    plane_xy, cal_times = plane_xy[finite], cal_times[finite]
    if plane_window is None:
        if len(plane_xy) == 0:
            raise ValueError("cal_t_u/cal_t_v: no calibration-plane pixel has both times")
        lo, hi = plane_xy.min(axis=0), plane_xy.max(axis=0)
        if not np.all(hi > lo):
            raise ValueError(
                f"cal_t_u/cal_t_v: the {len(plane_xy)} calibration-plane pixels are collinear "
                "in the plane (degenerate bounding box); the calibration plane must be seen "
                "over an area (check plane_mask)"
            )
        plane_window = (lo[0], lo[1], hi[0], hi[1])
    x0, y0, x1, y1 = (float(w) for w in plane_window)
    if not (x1 > x0 and y1 > y0):
        raise ValueError(f"plane_window: needs x_max > x_min and y_max > y_min, got {plane_window}")
    pixel = np.array([(x1 - x0) / width, (y1 - y0) / height])
    fit = fit_time_to_plane(
        cal_times,
        plane_xy,
        unit_scale=float(np.sqrt(pixel[0] * pixel[1])),
        min_sweep_angle_deg=min_sweep_angle_deg,
        **fit_options,
    )
    has_time = np.isfinite(t_u) & np.isfinite(t_v)
    scene_times = np.column_stack([t_u[has_time], t_v[has_time]]).astype(np.float64)
    xy = fit.model(scene_times)
    reason = np.where(has_time, 0, 1).astype(np.uint8)
    lo = fit.time_range[:, 0] - extrapolation_margin
    hi = fit.time_range[:, 1] + extrapolation_margin
    outside = np.any((scene_times < lo) | (scene_times > hi), axis=1)
    sine = sweep_crossing_sine(fit.model, scene_times)
    bad = (sine < np.sin(np.radians(min_sweep_angle_deg))) | ~np.all(np.isfinite(xy), axis=1)
    codes = np.where(bad, 3, np.where(outside, 2, 0)).astype(np.uint8)
    reason[has_time] = codes
    valid = reason == 0
    u = np.full(t_u.shape, np.nan, dtype=np.float32)
    v = np.full(t_u.shape, np.nan, dtype=np.float32)
    ok = codes == 0
    # orient each dual axis along its sweep (u grows with t_u, v with t_v), as
    # the uniform model and the reciprocal camera do, whatever the plane's axes
    grows_x = np.cov(plane_xy[:, 0], cal_times[:, 0])[0, 1] >= 0
    grows_y = np.cov(plane_xy[:, 1], cal_times[:, 1])[0, 1] >= 0
    u_vals = ((xy[:, 0] - x0) if grows_x else (x1 - xy[:, 0])) / pixel[0] - 0.5
    v_vals = ((xy[:, 1] - y0) if grows_y else (y1 - xy[:, 1])) / pixel[1] - 0.5
    u[has_time] = np.where(ok, u_vals, np.nan)
    v[has_time] = np.where(ok, v_vals, np.nan)
    info = {
        "model": fit.name,
        "model_residual_rms": fit.residual_rms,
        "candidates": fit.candidates,
        "selection_limit": fit.limit,
        "plane_window": [x0, y0, x1, y1],
        "axes_flipped": [bool(not grows_x), bool(not grows_y)],
        "dual_width": width,
        "dual_height": height,
        "n_calibration_points": int(len(cal_times)),
    }
    return u, v, valid, reason, info


#: dual-coordinate methods, name -> function
DUAL_COORD_METHODS = {
    "uniform": dual_coords_uniform,
    "calibration": dual_coords_calibration,
}


def dual_coords_dataset(u, v, valid, *, info, method, reason=None):
    """Assemble the ``dual_coords`` Dataset of docs/contracts.md.

    Parameters
    ----------
    u, v : (rows, cols) ndarray
        Dual coordinates (dual pixels).
    valid : (rows, cols) bool ndarray
    info : mapping, keyword-only
        As returned by the methods (``model``, ``model_residual_rms``,
        ``candidates``, ``dual_width``, ``dual_height``, ...).
    method : str
        ``uniform`` or ``calibration``.
    reason : (rows, cols) uint8 ndarray, optional
        Reason codes (`REASON_FLAGS`); derived from `valid` if omitted.

    Returns
    -------
    xarray.Dataset
        Over ``(row, col)``: ``u``, ``v`` (float32), ``valid``, ``reason``;
        attrs ``method``, ``model``, ``model_residual_rms``, ``candidates``
        (JSON), ``dual_width``, ``dual_height`` and any further scalar/list info.
    """
    valid = np.asarray(valid, dtype=bool)
    if reason is None:
        reason = np.where(valid, 0, 1).astype(np.uint8)
    dims = ("row", "col")
    rows, cols = valid.shape
    ds = xr.Dataset(
        {
            "u": (dims, np.asarray(u, dtype=np.float32),
                  {"units": "dual_pixel", "long_name": "dual column coordinate (centre of column i is u = i)"}),
            "v": (dims, np.asarray(v, dtype=np.float32),
                  {"units": "dual_pixel", "long_name": "dual row coordinate (centre of row j is v = j)"}),
            "valid": (dims, valid, {"long_name": "pixel has reliable dual coordinates"}),
            "reason": (dims, np.asarray(reason, dtype=np.uint8), {
                "long_name": "why the dual coordinates are missing",
                "flag_values": np.array(sorted(REASON_FLAGS), dtype=np.uint8),
                "flag_meanings": " ".join(REASON_FLAGS[k] for k in sorted(REASON_FLAGS)),
            }),
        },
        coords={"row": np.arange(rows), "col": np.arange(cols)},
    )
    attrs = {"method": method}
    for key, value in info.items():
        if key == "candidates":
            attrs[key] = json.dumps(value)
        elif isinstance(value, (list, tuple)):
            attrs[key] = np.asarray(value, dtype=np.float64)
        else:
            attrs[key] = value
    ds.attrs.update(attrs)
    return ds


UNIFORM_OPTIONS = ("scale", "offset", "min_spread")
CALIBRATION_OPTIONS = ("models", "k_folds", "rel_tol", "abs_tol", "seed", "model_options", "min_spread",
                       "plane_window", "extrapolation_margin", "min_sweep_angle_deg", "test_uniform")

#: calibration-plane models that are exact under uniform mask motion (time -> plane projective)
PROJECTIVE_MODELS = ("affine", "homography")


def _rms_text(candidate):
    return f"{candidate['cv_rms']:.3g}" if candidate.get("cv_rms") is not None else "n/a"


def _uniform_if_projective(info, uniform_info):
    """Info of the calibration fit turned into the uniform model's, or None if it is not projective.

    With a point light and a wire moving uniformly in a plane, frame indices are
    perspective dual coordinates (paper II-A) and the map time -> calibration plane is
    exactly projective; a projective model within the noise of the best thus confirms
    uniform motion, the simplest model, on the frame-index grid.
    """
    candidates = info["candidates"]
    best = min((c for c in candidates if c["status"] == "ok"), key=lambda c: c["cv_rms"])
    projective = [c for c in candidates if c["name"] in PROJECTIVE_MODELS and c["status"] == "ok"]
    limit = info["selection_limit"]
    fits = (f"CV residuals {', '.join(c['name'] + ' ' + _rms_text(c) for c in candidates)} dual px; "
            f"within noise of the best ({best['name']}): <= {limit:.3g}")
    if info["model"] not in PROJECTIVE_MODELS:
        tried = " and ".join(c["name"] for c in projective) or "no projective model"
        info["model_choice"] = (
            f"calibration ({info['model']}): the sweeps do not move uniformly -- the projective time->plane "
            f"map ({tried}) misfits beyond noise ({fits})")
        return None
    chosen = next(c for c in candidates if c["chosen"])
    entry = {"name": "uniform", "n_params": uniform_info["candidates"][0]["n_params"],
             "cv_rms": chosen["cv_rms"], "cv_se": chosen["cv_se"], "fit_rms": chosen["fit_rms"],
             "status": f"ok: time->plane is {chosen['name']} within noise", "within_noise": True, "chosen": True}
    for c in candidates:
        c["chosen"] = False
    return {**uniform_info, "method": "uniform", "model_residual_rms": chosen["cv_rms"],
            "candidates": [entry, *candidates], "selection_limit": limit,
            "model_choice": (f"uniform (frame index = dual coordinate): the calibration sweeps' time->plane map is "
                             f"{chosen['name']} (projective) within noise ({fits})")}


def _sweeps_of(shadow_time):
    return [str(s) for s in shadow_time["sweep"].values]


def choose_dual_model(model, *, calibration_available, missing="the calibration sweeps and plane"):
    """Return the dual-coordinate model that runs for a requested `model`.

    Parameters
    ----------
    model : {"auto", "uniform", "calibration"}
        Requested model; ``auto`` is the simplest model the data support: with
        calibration data, ``calibration``, whose sweeps are timed and test uniform
        motion first (:func:`dual_coords_from_shadow_time` keeps the frame-index
        model when the time->plane map is projective within noise), else ``uniform``.
    calibration_available : bool
        The calibration sweeps ``cal_u``, ``cal_v`` and the plane's homography exist.
    missing : str, optional
        What the calibration model lacks, for the error message.

    Returns
    -------
    str
        ``"uniform"`` or ``"calibration"``.

    Raises
    ------
    ValueError
        If `model` is unknown, or ``calibration`` without calibration data.
    """
    if model not in ("auto", *DUAL_COORD_METHODS):
        raise ValueError(f"model must be 'auto' or one of {', '.join(DUAL_COORD_METHODS)}; got {model!r}")
    if model == "auto":
        return "calibration" if calibration_available else "uniform"
    if model == "calibration" and not calibration_available:
        raise ValueError(f"model 'calibration' needs {missing}; use model 'auto' or 'uniform'")
    return model


def choose_dual_coords_method(shadow_time, method="auto", *, homography=None):
    """The method that runs on `shadow_time` (:func:`choose_dual_model` on what it holds).

    Calibration is available when `shadow_time` has sweeps ``cal_u`` and ``cal_v``
    and the calibration plane's `homography` is known.
    """
    sweeps = _sweeps_of(shadow_time)
    return choose_dual_model(
        method, calibration_available="cal_u" in sweeps and "cal_v" in sweeps and homography is not None,
        missing=f"sweeps cal_u, cal_v in the shadow times (has {sweeps}) and the calibration plane's "
        "homography (manifest calibration_plane.homography)")


def _sweep_times(shadow_time, sweep, min_confidence):
    t = shadow_time["shadow_time"].sel(sweep=sweep).transpose("row", "col").values.astype(np.float32)
    if min_confidence > 0 and "confidence" in shadow_time:
        conf = shadow_time["confidence"].sel(sweep=sweep).transpose("row", "col").values
        t = np.where(conf >= min_confidence, t, np.nan).astype(np.float32)
    return t


def dual_coords_from_shadow_time(shadow_time, *, method="uniform", dual_width=None, dual_height=None,
                                 min_confidence=0.0, homography=None, plane_mask=None, min_coverage=MIN_COVERAGE,
                                 **options):
    """Dual coordinates of every camera pixel from its shadow times.

    Parameters
    ----------
    shadow_time : xarray.Dataset
        ``shadow_time (sweep, row, col)`` with sweeps ``u``, ``v`` (and ``cal_u``,
        ``cal_v`` for the calibration method), optional ``confidence``; attrs
        ``n_frames_u``, ``n_frames_v``.
    method : {"uniform", "calibration"}
    dual_width, dual_height : int, optional
        Dual grid size; default the frames per sweep (``n_frames_u``, ``n_frames_v``).
    min_confidence : float
        Shadow times of lower confidence count as missing.
    homography : (3, 3) array_like, optional
        Camera -> calibration plane (calibration method).
    plane_mask : (rows, cols) bool ndarray, optional
        Camera pixels on the calibration plane (calibration method).
    min_coverage : float
        Smallest fraction of the camera pixels that must get dual coordinates.
    **options
        :data:`UNIFORM_OPTIONS` or :data:`CALIBRATION_OPTIONS` of the method. The
        calibration method's ``test_uniform`` (default True) first tests uniform
        motion against the calibration data: if the chosen plane model is one of
        :data:`PROJECTIVE_MODELS`, the frame indices are the dual coordinates
        (paper II-A) and the uniform model runs on the frame-index grid.

    Returns
    -------
    xarray.Dataset
        :func:`dual_coords_dataset`; attrs ``method`` (the model family that ran),
        ``model``, ``candidates`` (with CV residuals) and ``model_choice`` (which
        model and why, one sentence).

    Raises
    ------
    ValueError
        If fewer than `min_coverage` of the camera pixels get dual coordinates (with the counts).
    """
    check_in_interval(min_coverage, "min_coverage", 0.0, 1.0, closed="both")
    if method not in DUAL_COORD_METHODS:
        raise ValueError(f"method: must be one of {sorted(DUAL_COORD_METHODS)}; got {method!r}")
    allowed = UNIFORM_OPTIONS if method == "uniform" else CALIBRATION_OPTIONS
    sweeps = _sweeps_of(shadow_time)
    for needed in ("u", "v") if method == "uniform" else ("u", "v", "cal_u", "cal_v"):
        if needed not in sweeps:
            raise ValueError(f"shadow_time: has no sweep {needed!r} (has {sweeps})")
    n_frames = tuple(int(shadow_time.attrs.get(f"n_frames_{s}", 0)) for s in ("u", "v"))
    if min(n_frames) < 1:
        raise ValueError("shadow_time: attrs n_frames_u / n_frames_v missing")
    shape = (int(n_frames[1] if dual_height is None else dual_height),
             int(n_frames[0] if dual_width is None else dual_width))
    min_confidence = float(min_confidence)
    t_u, t_v = _sweep_times(shadow_time, "u", min_confidence), _sweep_times(shadow_time, "v", min_confidence)
    opts = {k: options[k] for k in allowed if k in options}
    if method == "uniform":
        u, v, valid, info = dual_coords_uniform(t_u, t_v, n_frames=n_frames, dual_shape=shape, **opts)
        info["model_choice"] = ("uniform (frame index = dual coordinate): assumed (no calibration sweeps "
                                "tested it)")
        reason = None
    else:
        if homography is None:
            raise ValueError("homography: the calibration method needs the camera -> plane homography")
        test_uniform = bool(opts.pop("test_uniform", True))
        u, v, valid, reason, info = dual_coords_calibration(
            t_u, t_v, cal_t_u=_sweep_times(shadow_time, "cal_u", min_confidence),
            cal_t_v=_sweep_times(shadow_time, "cal_v", min_confidence), homography=homography,
            dual_shape=shape, plane_mask=plane_mask, **opts)
        uniform = dual_coords_uniform(t_u, t_v, n_frames=n_frames, dual_shape=shape,
                                      **{k: opts[k] for k in UNIFORM_OPTIONS if k in opts})
        uniform_info = _uniform_if_projective(info, uniform[3]) if test_uniform else None
        if uniform_info is not None:
            (u, v, valid, _), info, reason = uniform, uniform_info, None
        info.setdefault("model_choice", f"calibration ({info['model']}): requested without the uniform test")
        method = info.pop("method", method)
    _check_dual_coverage(valid, t_u, t_v, min_confidence=min_confidence, min_coverage=min_coverage)
    return dual_coords_dataset(u, v, valid, info=info, method=method, reason=reason)


def _check_dual_coverage(valid, t_u, t_v, *, min_confidence, min_coverage):
    """Fail with the counts of missing shadow times when (almost) no camera pixel has dual coordinates."""
    reasons = {"without a shadow time in sweep u": np.count_nonzero(~np.isfinite(t_u)),
               "without a shadow time in sweep v": np.count_nonzero(~np.isfinite(t_v))}
    hint = (f"min_confidence is {min_confidence:g} (shadow-time confidence lies in [0, 1])" if min_confidence > 0
            else "the shadow times leave these pixels out (see shadow_time's reason counts)")
    check_coverage(np.count_nonzero(valid), np.size(valid), what="camera pixels with dual coordinates",
                   reasons=reasons, hint=hint, min_coverage=min_coverage)
