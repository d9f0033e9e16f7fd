"""Shadow-camera models: per-pixel shadow events -> virtual-image coordinates ``u, v``.

Every camera of the paper built from wire sweeps under one set-up is an entry of
:data:`CAMERA_MODELS`; the capture description decides which one a dataset gets
(:func:`choose_camera_model`: the simplest model the scene needs).

* ``perspective`` / ``orthographic`` (paper II, IV, Fig. 7): two perpendicular sweeps at
  uniform speed under one light; the frame index is the dual coordinate (``u = t_u``). The
  light decides the projection: a point (or area) light gives a perspective dual view, a
  distant light an orthographic one. A telecentric (orthographic) primal camera does not
  change the dual projection (Fig. 8).
* ``linear`` (Fig. 12): two or more sweeps under one light, each declared by its wire angle
  theta_k (in the mask plane, 0 = wire along ``v``, moving along ``u``), speed sigma_k (dual
  pixels per frame, perpendicular to the wire) and frame count T_k. Each shadow time is the
  exact affine function of the dual coordinates (``synthetic.lab.sweeps.dual_affine``)

      ``t_k = (cos(theta_k) (u - c_u) + sin(theta_k) (v - c_v)) / sigma_k + (T_k - 1) / 2``,

  with ``(c_u, c_v) = ((N_u - 1)/2, (N_v - 1)/2)`` the centre of the dual grid; ``(u, v)`` is
  the per-pixel weighted least-squares solution over the sweeps that timed the pixel
  (weights ``1 / max(time_std, std_floor)^2``). Pixels where the timed sweeps are nearly
  parallel are ``ill_conditioned``; with three or more sweeps, pixels whose times disagree
  with every (u, v) (normalised residual above ``max_residual``) are ``inconsistent``.
* ``cross_slit`` (Fig. 10 II-III): two non-parallel sweeps, each under its own light; the
  virtual pixel is the pair of times ``(u, v) = (t_a, t_b)``, no fit.
* ``pushbroom`` (Fig. 10 IV-V): one sweep; ``u`` is the shadow time and ``v`` the camera
  position along the shadow line (the camera row for a wire whose shadow runs along the
  rows' direction, else the column). The image is assembled by
  :func:`shadowcam.cameras.pushbroom.pushbroom_from_shadow_time`.

A sweep declaration is a mapping with ``name`` and the optional keys of
:data:`SWEEP_KEYS` (those of the renderer's ``sweeps.make_sweeps``, which the product reads
from the same capture description).

Offers
------
SWEEP_KEYS : keys of a sweep declaration.
REASON_FLAGS : reason code -> meaning (those of ``dual_coords`` and ``inconsistent``).
CAMERA_MODELS : model name -> function ``(times, sweeps, **options) -> (u, v, valid, reason, info)``.
declared_sweeps : normalised sweep declarations of a capture description.
frames_to_cross : frames a sweep needs to cross the dual field at its speed.
choose_camera_model : the camera a capture description needs (``auto``) or a checked request.
sweep_rows : the rows ``(a, b, c)`` of ``t_k = a u + b v + c`` of declared sweeps.
estimate_sweep : a sweep's angle, speed and offset from its times and the u/v sweeps' times.
camera_perspective, camera_orthographic, camera_linear, camera_cross_slit, camera_pushbroom :
    the entries.
camera_coords_from_shadow_time : shadow-time dataset + description -> dual-coordinates dataset.
FRAME_INDEX_MODELS : cameras whose dual coordinates are the standard pair's frame indices.
capture_dual_coords : the dual coordinates of a capture by its camera model (the step's front).
"""

import inspect
import math

import numpy as np

from shadowcam._shared.coverage import MIN_COVERAGE, check_coverage
from shadowcam._shared.validation import check_array, check_in, check_positive
from shadowcam.cameras.dual_coords import REASON_FLAGS as DUAL_REASON_FLAGS
from shadowcam.cameras.dual_coords import (
    dual_coords_dataset, dual_coords_from_shadow_time, dual_coords_uniform,
)

#: keys of a sweep declaration (a subset of the renderer's sweep specification keys)
SWEEP_KEYS = ("name", "angle_deg", "motion_deg", "speed", "speed_scene", "frames",
              "plane_offset", "light", "light_offset", "light_direction")

#: light kinds of a capture description
LIGHT_KINDS = ("point", "area", "distant")

#: the standard pair of perpendicular sweeps (no declaration needed)
STANDARD_SWEEPS = ({"name": "u", "angle_deg": 0.0}, {"name": "v", "angle_deg": 90.0})

_NO_TIME, _ILL, _INCONSISTENT = 1, 3, 4

#: reason codes of the camera models: those of ``dual_coords`` plus ``inconsistent``
REASON_FLAGS = {**DUAL_REASON_FLAGS, _INCONSISTENT: "inconsistent"}


def _cos_sin(angle_deg):
    """(cos, sin) of an angle in degrees, exact at multiples of 90."""
    a = float(angle_deg) % 360.0
    exact = {0.0: (1.0, 0.0), 90.0: (0.0, 1.0), 180.0: (-1.0, 0.0), 270.0: (0.0, -1.0)}
    if a in exact:
        return exact[a]
    return math.cos(math.radians(a)), math.sin(math.radians(a))


def _light_key(sweep):
    """What distinguishes a sweep's own light (None = the scene's light)."""
    for key in ("light_offset", "light_direction"):
        if sweep.get(key) is not None:
            value = tuple(float(x) for x in sweep[key])
            return None if key == "light_offset" and not any(value) else (key, value)
    return ("light", id(sweep["light"])) if sweep.get("light") is not None else None


def frames_to_cross(dual_shape, angle_deg, speed):
    """Frames a sweep needs for its wire to cross the whole dual field.

    Parameters
    ----------
    dual_shape : (int, int)
        ``(N_v, N_u)`` of the dual grid.
    angle_deg : float
        Wire angle theta (motion ``cos(theta) e_u + sin(theta) e_v``, perpendicular to the wire).
    speed : float
        Perpendicular step per frame, dual pixels (> 0).

    Returns
    -------
    int
        ``max(2, ceil((N_u |cos theta| + N_v |sin theta|) / speed))``.
    """
    check_positive(speed, "speed", finite=True)
    n_v, n_u = (int(n) for n in dual_shape)
    cos_a, sin_a = _cos_sin(angle_deg)
    extent = n_u * abs(cos_a) + n_v * abs(sin_a)
    return max(2, math.ceil(extent / float(speed) - 1e-9))


def declared_sweeps(description, *, n_frames=None):
    """Normalised sweep declarations of a capture description.

    Parameters
    ----------
    description : mapping
        ``sweeps`` (list of declarations, default the standard u/v pair), ``light``
        (one of :data:`LIGHT_KINDS`, default ``point``).
    n_frames : mapping of str to int, optional
        Frames per sweep measured in the data (``shadow_time`` attrs ``n_frames_<name>``);
        fills declarations without ``frames`` and must agree with those that have it.

    Returns
    -------
    list of dict
        ``name``, ``angle_deg`` (float), ``speed`` (float), ``frames`` (int or None),
        ``light`` (the light key: None for the scene's light) per sweep.

    Raises
    ------
    ValueError
        Unknown keys, duplicate names, non-positive speed, an oblique motion, frames that
        disagree with the data.
    """
    if not hasattr(description, "get"):
        raise ValueError(f"description must be a mapping; got {type(description).__name__}")
    check_in(description.get("light", "point"), "description.light", LIGHT_KINDS)
    specs = description.get("sweeps") or STANDARD_SWEEPS
    if isinstance(specs, dict) or not hasattr(specs, "__iter__"):
        raise ValueError("description.sweeps must be a list of sweep declarations; got "
                         f"{type(specs).__name__}")
    n_frames = dict(n_frames or {})
    out, names = [], set()
    for index, spec in enumerate(specs):
        key = f"description.sweeps[{index}]"
        if not hasattr(spec, "get"):
            raise ValueError(f"{key} must be a mapping; got {type(spec).__name__}")
        unknown = sorted(set(spec) - set(SWEEP_KEYS))
        if unknown:
            raise ValueError(f"{key} has unknown keys {unknown}; allowed {list(SWEEP_KEYS)}")
        name = spec.get("name")
        if not isinstance(name, str) or not name or name in names:
            raise ValueError(f"{key}.name must be a unique non-empty name; got {name!r}")
        names.add(name)
        angle = float(spec.get("angle_deg", 0.0))
        if spec.get("motion_deg") is not None and not math.isclose(
                float(spec["motion_deg"]) % 180.0, angle % 180.0, abs_tol=1e-9):
            raise ValueError(f"{key}.motion_deg must equal angle_deg (motion perpendicular to "
                             f"the wire; declare the perpendicular speed); got "
                             f"{spec['motion_deg']} for angle_deg {angle}")
        if spec.get("speed_scene") is not None:
            raise ValueError(f"{key}.speed_scene: declare the speed in dual pixels per frame "
                             "(speed) for the camera model")
        speed = float(spec.get("speed", 1.0))
        check_positive(speed, f"{key}.speed", finite=True)
        frames = spec.get("frames", n_frames.get(name))
        if frames is not None:
            frames = int(frames)
            if frames < 2:
                raise ValueError(f"{key}.frames must be >= 2; got {frames}")
            if name in n_frames and int(n_frames[name]) != frames:
                raise ValueError(f"{key}.frames must match the {n_frames[name]} frames of sweep "
                                 f"{name!r} in the data; got {frames}")
        out.append({"name": name, "angle_deg": angle, "speed": speed, "frames": frames,
                    "light": _light_key(spec)})
    return out


def _pair_sine(a, b):
    ca, sa = _cos_sin(a["angle_deg"])
    cb, sb = _cos_sin(b["angle_deg"])
    return abs(ca * sb - sa * cb)


def _is_standard_pair(sweeps):
    return (len(sweeps) == 2 and [s["angle_deg"] % 360.0 for s in sweeps] == [0.0, 90.0]
            and all(s["speed"] == 1.0 for s in sweeps))


def choose_camera_model(description, model="auto", *, min_sweep_angle_deg=15.0):
    """The camera model a capture description needs (model only what the scene needs).

    One sweep -> ``pushbroom``; two sweeps, each under its own light -> ``cross_slit``;
    sweeps under one light: the standard perpendicular pair at unit speed ->
    ``perspective`` (point or area light) or ``orthographic`` (distant light), any other
    set of two or more -> ``linear``.

    Parameters
    ----------
    description : mapping
        See :func:`declared_sweeps`.
    model : str
        ``auto`` or a key of :data:`CAMERA_MODELS`; a request is checked against the
        description.
    min_sweep_angle_deg : float
        Smallest angle between two sweeps' wires that defines a camera.

    Returns
    -------
    str
        A key of :data:`CAMERA_MODELS`.

    Raises
    ------
    ValueError
        Inconsistent descriptions: all sweeps (nearly) parallel, a cross-slit camera without
        a light per sweep, lights that differ between more than two sweeps, a model the
        sweeps cannot give.
    """
    check_in(model, "model", ("auto", *CAMERA_MODELS))
    sweeps = declared_sweeps(description)
    light = description.get("light", "point")
    names = [s["name"] for s in sweeps]
    lights = {s["light"] for s in sweeps}
    if len(sweeps) == 1:
        chosen = "pushbroom"
    else:
        limit = math.sin(math.radians(min_sweep_angle_deg))
        best = max(_pair_sine(a, b) for i, a in enumerate(sweeps) for b in sweeps[i + 1:])
        if best < limit:
            raise ValueError(f"description.sweeps {names} are all (nearly) parallel (largest "
                             f"angle {math.degrees(math.asin(min(best, 1.0))):.3g} deg < "
                             f"min_sweep_angle_deg = {min_sweep_angle_deg}); two crossing "
                             "sweeps are needed for a 2-D camera (or keep one for a pushbroom)")
        if len(lights) > 1:
            if len(sweeps) != 2:
                raise ValueError(f"description.sweeps {names} have {len(lights)} different "
                                 "lights; a cross-slit camera takes exactly two sweeps, each "
                                 "under its own light")
            chosen = "cross_slit"
        elif _is_standard_pair(sweeps):
            chosen = "orthographic" if light == "distant" else "perspective"
        else:
            chosen = "linear"
    if model == "auto" or model == chosen:
        return chosen
    if model == "cross_slit":
        raise ValueError(f"model 'cross_slit' needs two sweeps, each with its own light "
                         f"(light_offset or light_direction) in description.sweeps; got "
                         f"{names} under {'one light' if len(lights) == 1 else 'lights ' + str(len(lights))}")
    if model == "linear" and chosen in ("perspective", "orthographic"):
        return "linear"  # the standard pair is a special case of the linear camera
    if model in ("perspective", "orthographic") and chosen in ("perspective", "orthographic"):
        raise ValueError(f"model {model!r} contradicts description.light = {light!r}; "
                         f"the light decides the projection: use {chosen!r} or 'auto'")
    raise ValueError(f"model {model!r} does not fit description.sweeps {names} (the sweeps "
                     f"give a {chosen!r} camera); use model 'auto' or {chosen!r}")


def sweep_rows(sweeps, *, dual_shape):
    """Rows ``(a, b, c)`` of the exact relation ``t_k = a_k u + b_k v + c_k``.

    Parameters
    ----------
    sweeps : list of dict
        From :func:`declared_sweeps`, with ``frames``.
    dual_shape : (int, int)
        ``(N_v, N_u)`` of the dual grid.

    Returns
    -------
    (K, 3) float64 ndarray
    """
    n_v, n_u = (int(n) for n in dual_shape)
    rows = []
    for s in sweeps:
        if s["frames"] is None:
            raise ValueError(f"sweeps: sweep {s['name']!r} has no frame count; declare frames")
        cos_t, sin_t = _cos_sin(s["angle_deg"])
        a, b = cos_t / s["speed"], sin_t / s["speed"]
        rows.append((a, b, (s["frames"] - 1) / 2 - a * (n_u - 1) / 2 - b * (n_v - 1) / 2))
    return np.array(rows, dtype=np.float64)


def _default_dual_shape(sweeps):
    """``(N_v, N_u)``: frames x speed of the sweeps moving exactly along u and along v."""
    along_u = [s for s in sweeps if s["angle_deg"] % 180.0 == 0.0]
    along_v = [s for s in sweeps if s["angle_deg"] % 180.0 == 90.0]
    if not (along_u and along_v):
        raise ValueError(f"dual_shape: the sweeps {[s['name'] for s in sweeps]} do not include "
                         "one moving along u (angle_deg 0) and one along v (angle_deg 90); give "
                         "the dual grid size (N_v, N_u) (description key frames or dual_shape)")
    return (int(round(along_v[0]["frames"] * along_v[0]["speed"])),
            int(round(along_u[0]["frames"] * along_u[0]["speed"])))


def _time_stack(times, sweeps):
    missing = [s["name"] for s in sweeps if s["name"] not in times]
    if missing:
        raise ValueError(f"times has no shadow-time map for sweeps {missing} (has {list(times)})")
    maps = [np.asarray(times[s["name"]], dtype=np.float64) for s in sweeps]
    check_array(maps[0], f"times[{sweeps[0]['name']!r}]", ndim=2)
    for s, m in zip(sweeps, maps):
        if m.shape != maps[0].shape:
            raise ValueError(f"times[{s['name']!r}] must have shape {maps[0].shape}; got {m.shape}")
    return np.stack(maps)


def _info(model, projection, dual_shape, **extra):
    return {"model": model, "projection": projection, "dual_height": int(dual_shape[0]),
            "dual_width": int(dual_shape[1]), "model_residual_rms": 0.0, **extra}


def _projection(light):
    return "orthographic" if light == "distant" else "perspective"


def _uniform(times, sweeps, light, dual_shape, model):
    if len(sweeps) != 2:
        raise ValueError(f"sweeps: the {model} camera takes the two perpendicular sweeps; got "
                         f"{[s['name'] for s in sweeps]}")
    t_u, t_v = _time_stack(times, sweeps)
    n_frames = tuple(int(s["frames"]) for s in sweeps)
    u, v, valid, info = dual_coords_uniform(t_u, t_v, n_frames=n_frames, dual_shape=dual_shape)
    reason = np.where(valid, 0, _NO_TIME).astype(np.uint8)
    shape = (info["dual_height"], info["dual_width"])
    return u, v, valid, reason, _info(model, _projection(light), shape, scale=info["scale"],
                                      offset=info["offset"], sweeps=[s["name"] for s in sweeps])


def camera_perspective(times, sweeps, *, light="point", dual_shape=None):
    """Perspective shadow camera: the standard pair under a point (or area) light.

    Parameters
    ----------
    times : mapping of str to (rows, cols) ndarray
        Shadow times (frames, NaN = none) per sweep name.
    sweeps : list of dict
        Two declarations (:func:`declared_sweeps`): the u and v sweeps, in that order.
    light : {"point", "area"}
    dual_shape : (int, int), optional
        ``(N_v, N_u)``; default one dual pixel per frame.

    Returns
    -------
    u, v : (rows, cols) float32 ndarray
    valid : (rows, cols) bool ndarray
    reason : (rows, cols) uint8 ndarray
        Codes of :data:`REASON_FLAGS`.
    info : dict
        ``model``, ``projection``, ``dual_width``, ``dual_height``, ...
    """
    if light == "distant":
        raise ValueError("light must be 'point' or 'area' for a perspective shadow camera; got "
                         "'distant' (a distant light gives the orthographic camera)")
    return _uniform(times, sweeps, light, dual_shape, "perspective")


def camera_orthographic(times, sweeps, *, light="distant", dual_shape=None):
    """Orthographic shadow camera (paper IV, Fig. 7): the standard pair under a distant light.

    Parameters and returns as :func:`camera_perspective`; `light` must be ``distant``.
    """
    check_in(light, "light", ("distant",))
    return _uniform(times, sweeps, light, dual_shape, "orthographic")


def camera_linear(times, sweeps, *, light="point", dual_shape=None, time_std=None,
                  std_floor=0.25, min_sweep_angle_deg=15.0, max_residual=4.0):
    """Dual coordinates from two or more declared sweeps by per-pixel least squares (Fig. 12).

    Parameters
    ----------
    times : mapping of str to (rows, cols) ndarray
        Shadow times (frames, NaN = none) per sweep name.
    sweeps : list of dict
        Declarations with ``angle_deg``, ``speed``, ``frames`` (:func:`declared_sweeps`).
    light : {"point", "area", "distant"}
        Decides the ``projection`` attr.
    dual_shape : (int, int), optional
        ``(N_v, N_u)`` of the dual grid; default frames x speed of the sweeps moving along
        u (``angle_deg`` 0) and along v (90); required without them.
    time_std : mapping of str to (rows, cols) ndarray, optional
        Per-pixel time uncertainty (frames) per sweep; without it every time has the
        uncertainty `std_floor`.
    std_floor : float
        Smallest time uncertainty used in a weight (frames).
    min_sweep_angle_deg : float
        Pixels whose timed sweeps cross at a smaller angle are ``ill_conditioned``.
    max_residual : float
        With more equations than unknowns, pixels whose residual RMS per degree of freedom,
        in units of the time uncertainty, exceeds this are ``inconsistent``.

    Returns
    -------
    u, v : (rows, cols) float32 ndarray
    valid : (rows, cols) bool ndarray
    reason : (rows, cols) uint8 ndarray
    info : dict
        Also ``sweep_rows`` (K x 3 ``a, b, c``) and ``model_residual_rms`` (frames).
    """
    check_positive(std_floor, "std_floor", finite=True)
    check_positive(max_residual, "max_residual")
    if len(sweeps) < 2:
        raise ValueError(f"sweeps: the linear camera needs two or more sweeps; got "
                         f"{[s['name'] for s in sweeps]}")
    stack = _time_stack(times, sweeps)
    if dual_shape is None:
        dual_shape = _default_dual_shape(sweeps)
    rows = sweep_rows(sweeps, dual_shape=dual_shape)
    limit = math.sin(math.radians(min_sweep_angle_deg))
    if max(_pair_sine(a, b) for i, a in enumerate(sweeps) for b in sweeps[i + 1:]) < limit:
        raise ValueError(f"sweeps {[s['name'] for s in sweeps]} are all (nearly) parallel "
                         f"(< min_sweep_angle_deg = {min_sweep_angle_deg}); they do not define "
                         "dual coordinates")
    have = np.isfinite(stack)
    if time_std is None:
        weight = np.where(have, 1.0 / std_floor**2, 0.0)
    else:
        std = _time_stack(time_std, sweeps)
        std = np.where(np.isfinite(std), np.maximum(std, std_floor), np.inf)
        weight = np.where(have, 1.0 / std**2, 0.0)
    rhs = np.where(have, stack - rows[:, 2, None, None], 0.0)
    a, b = rows[:, 0, None, None], rows[:, 1, None, None]
    m_aa, m_ab, m_bb = (weight * a * a).sum(0), (weight * a * b).sum(0), (weight * b * b).sum(0)
    r_a, r_b = (weight * a * rhs).sum(0), (weight * b * rhs).sum(0)
    det = m_aa * m_bb - m_ab**2
    # crossing sine of the best pair of timed sweeps (the same sines as the refusal above)
    sine = np.zeros(stack.shape[1:])
    for i in range(len(sweeps)):
        for j in range(i + 1, len(sweeps)):
            s_ij = _pair_sine(sweeps[i], sweeps[j])
            sine = np.where(have[i] & have[j], np.maximum(sine, s_ij), sine)
    timed = have.sum(0) >= 2
    ok = timed & (sine >= limit) & (det > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.where(ok, (m_bb * r_a - m_ab * r_b) / det, np.nan)
        v = np.where(ok, (m_aa * r_b - m_ab * r_a) / det, np.nan)
    residual = np.where(have, a * u + b * v - rhs, 0.0)
    dof = have.sum(0) - 2
    with np.errstate(divide="ignore", invalid="ignore"):
        norm_rms = np.sqrt((weight * residual**2).sum(0) / np.maximum(dof, 1))
        frame_rms = np.sqrt((residual**2).sum(0) / np.maximum(dof, 1))
    inconsistent = ok & (dof > 0) & (norm_rms > max_residual)
    reason = np.where(~timed, _NO_TIME, np.where(~ok, _ILL, np.where(inconsistent, _INCONSISTENT, 0)))
    valid = reason == 0
    fit_rms = frame_rms[valid & (dof > 0)]
    info = _info("linear", _projection(light), dual_shape,
                 sweeps=[s["name"] for s in sweeps], sweep_rows=rows.ravel().tolist(),
                 model_residual_rms=float(np.sqrt(np.mean(fit_rms**2))) if fit_rms.size else 0.0)
    nan = np.float32(np.nan)
    return (np.where(valid, u, nan).astype(np.float32), np.where(valid, v, nan).astype(np.float32),
            valid, reason.astype(np.uint8), info)


def camera_cross_slit(times, sweeps, *, light="point", dual_shape=None, min_sweep_angle_deg=15.0):
    """Cross-slit shadow camera (Fig. 10 II-III): two sweeps, each under its own light.

    The virtual pixel is the pair of shadow times, ``(u, v) = (t_a, t_b)`` (no fit): its
    viewing ray meets both slits (each sweep's wire direction through its light).

    Parameters
    ----------
    times : mapping of str to (rows, cols) ndarray
    sweeps : list of dict
        Two declarations with different ``light`` (:func:`declared_sweeps`).
    light : {"point", "area", "distant"}
        The lights' kind (recorded).
    dual_shape : (int, int), optional
        ``(N_v, N_u)``; default the frames of sweeps b and a.
    min_sweep_angle_deg : float
        Wires crossing at a smaller angle give parallel slits: no cross-slit camera.

    Returns
    -------
    As :func:`camera_perspective`; ``projection`` is ``cross-slit``.
    """
    names = [s["name"] for s in sweeps]
    if len(sweeps) != 2:
        raise ValueError(f"sweeps: a cross-slit camera takes exactly two sweeps; got {names}")
    if sweeps[0]["light"] is None and sweeps[1]["light"] is None or \
            sweeps[0]["light"] == sweeps[1]["light"]:
        raise ValueError(f"sweeps {names} share one light; a cross-slit camera needs a light "
                         "per sweep (light_offset or light_direction); under one light use "
                         "the perspective/orthographic or linear camera")
    if _pair_sine(*sweeps) < math.sin(math.radians(min_sweep_angle_deg)):
        raise ValueError(f"sweeps {names}: the wires are (nearly) parallel (angles "
                         f"{sweeps[0]['angle_deg']} and {sweeps[1]['angle_deg']} deg): the two "
                         "slits do not cross; no cross-slit camera")
    t_a, t_b = _time_stack(times, sweeps)
    valid = np.isfinite(t_a) & np.isfinite(t_b)
    if dual_shape is None:
        dual_shape = (int(sweeps[1]["frames"]), int(sweeps[0]["frames"]))
    nan = np.float32(np.nan)
    reason = np.where(valid, 0, _NO_TIME).astype(np.uint8)
    return (np.where(valid, t_a, nan).astype(np.float32), np.where(valid, t_b, nan).astype(np.float32),
            valid, reason, _info("cross_slit", "cross-slit", dual_shape, sweeps=names,
                                 light_kind=light))


def camera_pushbroom(times, sweeps, *, light="point", dual_shape=None):
    """Shadow pushbroom coordinates (Fig. 10 IV-V): one sweep.

    ``u`` is the shadow time; ``v`` the camera position along the shadow line: the row
    when the shadow edge runs along the columns' direction (the time changes mostly along
    the rows, as for a vertical wire), else the column (attr ``along``).

    Parameters
    ----------
    times : mapping of str to (rows, cols) ndarray
    sweeps : list of dict
        One declaration.
    light : {"point", "area", "distant"}
    dual_shape : (int, int), optional
        Default ``(rows or cols, frames)``.

    Returns
    -------
    As :func:`camera_perspective`; ``projection`` is ``pushbroom``.
    """
    if len(sweeps) != 1:
        raise ValueError(f"sweeps: a pushbroom takes one sweep; got {[s['name'] for s in sweeps]}")
    (t,) = _time_stack(times, sweeps)
    with np.errstate(invalid="ignore"):
        d_col = np.nanmedian(np.abs(np.diff(t, axis=1))) if t.shape[1] > 1 else 0.0
        d_row = np.nanmedian(np.abs(np.diff(t, axis=0))) if t.shape[0] > 1 else 0.0
    along = "row" if not (d_row > d_col) else "col"
    rows, cols = np.indices(t.shape)
    valid = np.isfinite(t)
    position = rows if along == "row" else cols
    if dual_shape is None:
        dual_shape = (t.shape[0] if along == "row" else t.shape[1], int(sweeps[0]["frames"]))
    nan = np.float32(np.nan)
    reason = np.where(valid, 0, _NO_TIME).astype(np.uint8)
    return (np.where(valid, t, nan).astype(np.float32),
            np.where(valid, position, nan).astype(np.float32), valid, reason,
            _info("pushbroom", "pushbroom", dual_shape, sweeps=[sweeps[0]["name"]], along=along,
                  light_kind=light))


#: camera models, name -> function ``(times, sweeps, **options) -> (u, v, valid, reason, info)``
CAMERA_MODELS = {
    "perspective": camera_perspective,
    "orthographic": camera_orthographic,
    "linear": camera_linear,
    "cross_slit": camera_cross_slit,
    "pushbroom": camera_pushbroom,
}


def estimate_sweep(t, t_u, t_v, *, min_points=10):
    """A sweep's declaration from its times and the standard u/v sweeps' times.

    Under one light the times are exactly affine in each other, ``t = a t_u + b t_v + c``
    (calibration sweeps over a bare plane give the cleanest points); the fit gives
    ``angle_deg = atan2(b, a)`` and ``speed = 1 / hypot(a, b)`` (dual pixels per frame when
    the u/v sweeps move one dual pixel per frame).

    Parameters
    ----------
    t, t_u, t_v : (rows, cols) ndarray
        Shadow times (frames, NaN = none).
    min_points : int
        Pixels with all three times needed.

    Returns
    -------
    dict
        ``angle_deg``, ``speed``, ``offset`` (c), ``residual_rms`` (frames), ``n_points``.
    """
    t, t_u, t_v = (np.asarray(x, dtype=np.float64) for x in (t, t_u, t_v))
    check_array(t, "t", ndim=2)
    if not (t.shape == t_u.shape == t_v.shape):
        raise ValueError(f"t, t_u, t_v must have one shape; got {t.shape}, {t_u.shape}, {t_v.shape}")
    ok = np.isfinite(t) & np.isfinite(t_u) & np.isfinite(t_v)
    if ok.sum() < int(min_points):
        raise ValueError(f"t: only {int(ok.sum())} pixels are timed in all three sweeps; "
                         f"at least min_points = {min_points} are needed")
    design = np.column_stack([t_u[ok], t_v[ok], np.ones(int(ok.sum()))])
    coef, *_ = np.linalg.lstsq(design, t[ok], rcond=None)
    residual = design @ coef - t[ok]
    a, b, c = (float(x) for x in coef)
    if math.hypot(a, b) == 0:
        raise ValueError("t: the sweep's times do not change with t_u or t_v (no motion)")
    return {"angle_deg": math.degrees(math.atan2(b, a)), "speed": 1.0 / math.hypot(a, b),
            "offset": c, "residual_rms": float(np.sqrt(np.mean(residual**2))),
            "n_points": int(ok.sum())}


def camera_coords_from_shadow_time(shadow_time, description, *, model="auto", dual_shape=None,
                                   min_confidence=0.0, **options):
    """Virtual-image coordinates of every camera pixel: the front function of the cameras.

    Parameters
    ----------
    shadow_time : xarray.Dataset
        ``shadow_time (sweep, row, col)``, optional ``time_std`` and ``confidence``; attrs
        ``n_frames_<sweep>``.
    description : mapping
        The capture description (``light``, ``sweeps``; :func:`declared_sweeps`).
    model : str
        ``auto`` or a key of :data:`CAMERA_MODELS` (:func:`choose_camera_model`).
    dual_shape : (int, int), optional
        ``(N_v, N_u)`` of the output grid; default the description's ``dual_shape``, or for
        the linear camera ``(frames, frames)`` of the description's ``frames`` (the dual
        grid of the renderer's standard pair), else the model's default.
    min_confidence : float
        Shadow times of lower confidence count as missing.
    **options
        Options of the model's function (e.g. ``min_sweep_angle_deg``, ``max_residual``).

    Returns
    -------
    xarray.Dataset
        ``dual_coords.dual_coords_dataset`` with attrs ``method`` (the camera model),
        ``projection`` and the model's info.
    """
    chosen = choose_camera_model(description, model)
    if dual_shape is None and description.get("dual_shape") is not None:
        dual_shape = tuple(int(n) for n in description["dual_shape"])
    elif dual_shape is None and description.get("frames") is not None and chosen == "linear":
        dual_shape = (int(description["frames"]),) * 2
    available = [str(s) for s in shadow_time["sweep"].values]
    n_frames = {n: int(shadow_time.attrs[f"n_frames_{n}"]) for n in available
                if f"n_frames_{n}" in shadow_time.attrs}
    sweeps = declared_sweeps(description, n_frames=n_frames)
    missing = [s["name"] for s in sweeps if s["name"] not in available]
    if missing:
        raise ValueError(f"shadow_time has no sweep {missing} declared in description.sweeps "
                         f"(has {available})")

    def maps(variable):
        out = {}
        for s in sweeps:
            m = shadow_time[variable].sel(sweep=s["name"]).transpose("row", "col").values
            if variable == "shadow_time" and min_confidence > 0 and "confidence" in shadow_time:
                conf = shadow_time["confidence"].sel(sweep=s["name"]).transpose("row", "col").values
                m = np.where(conf >= min_confidence, m, np.nan)
            out[s["name"]] = m
        return out

    if chosen == "linear" and "time_std" in shadow_time and "time_std" not in options:
        options["time_std"] = maps("time_std")
    u, v, valid, reason, info = CAMERA_MODELS[chosen](
        maps("shadow_time"), sweeps, light=description.get("light", "point"),
        dual_shape=dual_shape, **options)
    info = {k: val for k, val in info.items() if k != "sweeps"} | {"sweeps": " ".join(info["sweeps"])}
    ds = dual_coords_dataset(u, v, valid, info=info, method=chosen, reason=reason)
    ds["reason"].attrs.update(flag_values=np.array(sorted(REASON_FLAGS), dtype=np.uint8),
                              flag_meanings=" ".join(REASON_FLAGS[k] for k in sorted(REASON_FLAGS)))
    return ds



#: camera models whose dual coordinates are the frame indices of the standard pair
#: (``dual_coords.dual_coords_uniform``, or the calibration plane when it is measured)
FRAME_INDEX_MODELS = ("perspective", "orthographic")


def capture_dual_coords(shadow_time, description, *, camera_model, dual_model="uniform",
                        dual_width=None, dual_height=None, min_confidence=0.0,
                        min_coverage=MIN_COVERAGE, **options):
    """Dual coordinates of a capture by its camera model: the dual-coords step's front function.

    The standard pair (``perspective`` / ``orthographic``) runs the dual-coordinate model
    `dual_model` (:func:`shadowcam.cameras.dual_coords.dual_coords_from_shadow_time`:
    frame index = dual coordinate, or the calibration plane); every other camera of
    :data:`CAMERA_MODELS` (``linear``, ``cross_slit``, ``pushbroom``) runs its own model
    (:func:`camera_coords_from_shadow_time`) on the camera's dual grid.

    Parameters
    ----------
    shadow_time : xarray.Dataset
        ``shadow_time (sweep, row, col)``; attrs ``n_frames_<sweep>``.
    description : mapping
        The capture description (``CapturePlan.camera``: ``light``, ``sweeps``).
    camera_model : str
        A key of :data:`CAMERA_MODELS` (``CapturePlan.camera_model``).
    dual_model : {"uniform", "calibration"}
        Model of the standard pair (``CapturePlan.dual_model``).
    dual_width, dual_height : int, optional
        Dual grid size; default the camera's grid.
    min_confidence : float
        Shadow times of lower confidence count as missing.
    min_coverage : float
        Smallest fraction of the camera pixels that must get dual coordinates.
    **options
        Options of the model (those of the standard pair's model, e.g. ``scale``, are not
        used by the other cameras).

    Returns
    -------
    xarray.Dataset
        ``dual_coords.dual_coords_dataset``; attrs ``method`` (``uniform``, ``calibration``
        or the camera model), ``model_choice``, and ``optics`` (``mirror``, ``glass``) when
        the description's primal path has optics.

    Raises
    ------
    ValueError
        Unknown `camera_model`, or fewer than `min_coverage` of the pixels covered.
    """
    check_in(camera_model, "camera_model", tuple(CAMERA_MODELS))
    optics = str(description.get("optics", "none"))
    if camera_model in FRAME_INDEX_MODELS:
        ds = dual_coords_from_shadow_time(
            shadow_time, method=dual_model, dual_width=dual_width, dual_height=dual_height,
            min_confidence=min_confidence, min_coverage=min_coverage, **options)
        if optics != "none":  # the dual view carries the camera-pixel density then
            ds.attrs["optics"] = optics
        return ds
    shape = None if dual_width is None or dual_height is None else (int(dual_height), int(dual_width))
    taken = inspect.signature(CAMERA_MODELS[camera_model]).parameters
    ds = camera_coords_from_shadow_time(shadow_time, description, model=camera_model,
                                        dual_shape=shape, min_confidence=min_confidence,
                                        **{k: v for k, v in options.items() if k in taken})
    check_coverage(int(ds["valid"].sum()), ds["valid"].size,
                   what="camera pixels with dual coordinates",
                   reasons={REASON_FLAGS[k]: int((ds["reason"].values == k).sum())
                            for k in sorted(REASON_FLAGS) if k},
                   hint="the shadow times leave these pixels out (see shadow_time's reason counts)",
                   min_coverage=min_coverage)
    ds.attrs["model_choice"] = (f"{camera_model} camera: chosen by the capture plan from the "
                                f"sweep geometry (sweeps {ds.attrs['sweeps']})")
    if optics != "none":
        ds.attrs["optics"] = optics
    return ds
