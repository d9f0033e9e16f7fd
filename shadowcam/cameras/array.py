"""The virtual camera array of a static grid mask under a moving light (paper III, Fig. 6).

A mask of ``n`` horizontal and ``m`` vertical wires stays still while the light moves
along a line: along ``e_u`` in the *horizontal* experiment (the vertical wires' shadows
pass each pixel), along ``e_v`` in the *vertical* one. A pixel sees one dip per wire;
the dip of vertical wire j comes at the frame where the light, the wire and the pixel's
point are coplanar, which is the ``u`` coordinate of the point seen from the crossing
(i, j) through the light's line (see :mod:`shadowcam.synthetic.lab.light_motion`).
Crossing (i, j) is therefore a pinhole camera whose pixel of a point is (time of
horizontal wire i, time of vertical wire j), and whose colour is the camera's image lit
by a light at the crossing.

Assigning minima to wires: with the wires equally spaced by ``s`` frames of the light's
motion, neighbouring wires' dips at a point at depth ``d`` beyond the mask (``g`` the
light-mask distance) are ``s (1 + g / d)`` frames apart: all gaps of a pixel are equal
and at least ``s``; identical wires cast dips of like depth, so a dip less than half as
deep as the pixel's deepest is the lit level's own variation under the moving light (or a
scene shadow's edge), not a wire. Fewer evenly spaced dips than wires are placed when the missing wires
can only lie outside the sweep on one known side. A pixel whose minima number differs from
the wires otherwise (``minima_count``) or whose gaps are not equal within `tolerance` frames or shorter than
``s`` (``uneven_gaps``) gets no coordinate from that experiment.

Offers
------
ARRAY_REASONS : reason code -> meaning, per pixel and experiment.
assign_wires : minima of one experiment -> per-wire times and reasons.
estimate_spacing : the wire spacing in frames, from an experiment's evenly spaced dips.
camera_array : both experiments and the crossing images -> the array dataset over
    (camera_row, camera_col, v, u, channel) (of a capture's files:
    :func:`shadowcam.cameras.array_files.camera_array_of_plan`).
array_views : each family's wire times and the crossing images -> that dataset.
array_accuracy : coordinate RMSE per camera, rectification and disparity against the
    renderer's wire times, and the views against the reciprocal renders.
capture_accuracy : :func:`array_accuracy` against a capture's ``ground_truth.nc``.
"""

import warnings

import numpy as np
import xarray as xr

from shadowcam._shared.validation import check_array, check_positive
from shadowcam.cameras.dual_view import resample_dual_view
from shadowcam.lab import minima as _m

#: reason code -> meaning, per pixel and experiment (0 = every wire timed)
ARRAY_REASONS = {0: "ok", 1: "minima_count", 2: "uneven_gaps", 3: "minimum_flagged"}
OK, MINIMA_COUNT, UNEVEN_GAPS, MINIMUM_FLAGGED = range(4)


def assign_wires(frames, n_wires, *, spacing_frames, tolerance=0.5, half_window=None, shape=None):
    """Times of each wire's shadow at each pixel of one experiment.

    Parameters
    ----------
    frames : (T, H, W[, C]) array_like, or callable
        The experiment's frames (light moving, wires of one family in place), or a
        callable streaming them in consecutive blocks, called twice
        (:func:`shadowcam.io.decode.frame_blocks`).
    n_wires : int
    spacing_frames : float
        Distance between neighbouring wires in frames of the light's motion.
    tolerance : float
        Frames by which a pixel's gaps may differ from each other.
    half_window : int, optional
        Of :func:`shadowcam.lab.minima.find_minima`; default ``floor(spacing / 2)``
        (neighbouring dips are at least `spacing_frames` apart).
    shape : (int, int), optional
        ``(H, W)``; needed when `frames` is a callable.

    Returns
    -------
    times : (n_wires, H, W) float64
        Wire j's time (wires in the order of their offsets); NaN where the reason is not ok.
    reason : (H, W) int8
        :data:`ARRAY_REASONS`.
    minima : Minima
    """
    check_positive(spacing_frames, "spacing_frames", finite=True)
    check_positive(tolerance, "tolerance", finite=True)
    if int(n_wires) != n_wires or n_wires < 1:
        raise ValueError(f"n_wires must be an integer >= 1; got {n_wires!r}")
    if callable(frames):
        if shape is None:
            raise ValueError("shape: the (H, W) of the frames is needed when they are streamed (frames a callable)")
    else:
        frames = np.asarray(frames)
        check_array(frames, "frames")
        if frames.ndim not in (3, 4):
            raise ValueError(f"frames must be (T, H, W[, C]); got shape {frames.shape}")
        shape = frames.shape[1:3]
    h = max(1, int(spacing_frames // 2)) if half_window is None else int(half_window)
    minima = _m.find_minima(frames, tuple(shape), count=int(n_wires), half_window=h,
                            steady_level=False)  # the light moves: its level varies
    reason = np.full(minima.count.shape, OK, np.int8)
    # identical wires cast dips of like depth: a minimum less than half as deep as the
    # pixel's deepest (the lit level's own variation under the moving light) is no wire's
    significant = (minima.reason != _m.MISSING) & (minima.reason != _m.LOW_CONTRAST)
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # pixels without minima
        deepest = np.nanmax(np.where(significant, minima.contrast, np.nan), axis=0)
        wire_like = significant & (minima.contrast >= 0.5 * deepest)
        extra = minima.extra_contrast >= 0.5 * deepest
    # the wires' minima first, in order along the sweep
    rank = np.argsort(~wire_like, axis=0, kind="stable")
    estimate = np.take_along_axis(np.where(wire_like, minima.estimate, np.nan), rank, 0)
    found = wire_like.sum(axis=0)
    reason[np.any(wire_like & (minima.reason != _m.OK), axis=0)] = MINIMUM_FLAGGED
    reason[(found != n_wires) | extra] = MINIMA_COUNT
    if n_wires > 1:
        gaps = np.diff(estimate, axis=0)
        with np.errstate(invalid="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # pixels without minima
            uneven = ((np.nanmax(gaps, axis=0) - np.nanmin(gaps, axis=0) > tolerance)
                      | (np.nanmin(gaps, axis=0) < spacing_frames - tolerance))
        reason[(reason == OK) & uneven] = UNEVEN_GAPS
    times = np.where(reason[None] == OK, estimate, np.nan)
    _place_partial(times, reason, estimate, found, minima.n_frames, int(n_wires), spacing_frames,
                   tolerance, extra)
    return times, reason, minima


def estimate_spacing(frames, n_wires, *, tolerance=0.5, shape=None):
    """The wires' spacing in frames of the light's motion, from one experiment's dips.

    The dips of neighbouring wires at a point at depth ``d`` beyond the mask are
    ``s (1 + g / d)`` frames apart, at least the spacing ``s`` and nearest it for the
    farthest points. The dips are found at the finest resolution (half window 1: dips at
    least two frames apart) and the spacing is the smallest mean gap of a pixel whose
    `n_wires` dips are evenly spaced. It bounds ``s`` from above by the ``g / d`` of the
    farthest point; :func:`assign_wires` uses it as the shortest gap a pixel may have and
    for its minima's half window.

    Parameters
    ----------
    frames : (T, H, W[, C]) array_like, or callable
        One experiment's frames, or a callable streaming them (see :func:`assign_wires`).
    n_wires : int
        Wires of the family whose shadows pass (>= 2).
    tolerance : float
        Frames by which a pixel's gaps may differ from each other.
    shape : (int, int), optional
        ``(H, W)``; needed when `frames` is a callable.

    Returns
    -------
    float
    """
    if int(n_wires) != n_wires or n_wires < 2:
        raise ValueError(f"n_wires: the spacing is estimated from the gaps between two or more wires' dips; "
                         f"got {n_wires!r}: give the spacing (camera_array.spacing_frames) instead")
    times, reason, _ = assign_wires(frames, n_wires, spacing_frames=2.0, tolerance=tolerance, half_window=1,
                                    shape=shape)
    every = (reason == OK) & np.all(np.isfinite(times), axis=0)  # all wires' dips inside the sweep
    gaps = np.diff(times, axis=0).mean(axis=0)[every]
    if not gaps.size:
        raise ValueError(f"frames: no pixel shows {n_wires} evenly spaced dips, so the wire spacing cannot be "
                         "estimated; give it (camera_array.spacing_frames)")
    return float(gaps.min())


def _place_partial(times, reason, est, found, n_frames, n_wires, spacing_frames, tolerance, extra):
    """Pixels with 2 <= c < n_wires reliable, evenly spaced minima: the missing wires' dips
    fall outside the sweep (one gap before the first or after the last dip would be inside
    it otherwise); where exactly one split into wires before and after fits, the minima
    take their wires' places (in place on `times` and `reason`)."""
    candidates = (found >= 2) & (found < n_wires) & ~extra & (reason == MINIMA_COUNT)
    if not candidates.any():
        return
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # pixels without minima
        gaps = np.diff(est, axis=0)
        even = ((np.nanmax(gaps, axis=0) - np.nanmin(gaps, axis=0) <= tolerance)
                & (np.nanmin(gaps, axis=0) >= spacing_frames - tolerance))
        gap = np.nanmean(gaps, axis=0)
    first = est[0]
    last = np.take_along_axis(est, np.maximum(found - 1, 0)[None], 0)[0]
    before_fits = first - gap < 0
    after_fits = last + gap > n_frames - 1
    missing = n_wires - found
    n_fits = np.zeros(found.shape, np.int64)
    split = np.zeros(found.shape, np.int64)
    for b in range(n_wires):
        a = missing - b
        fits = (b <= missing) & ((b == 0) | before_fits) & ((a == 0) | after_fits)
        n_fits += fits
        split = np.where(fits, b, split)
    place = candidates & even & (n_fits == 1)
    rows, cols = np.nonzero(place)
    for r, c in zip(rows, cols):
        b, k = split[r, c], found[r, c]
        times[:, r, c] = np.nan
        times[b:b + k, r, c] = est[:k, r, c]
        reason[r, c] = OK


def camera_array(frames_horizontal, frames_vertical, crossing_images, *, spacing_frames,
                 tolerance=0.5, method="mesh"):
    """The virtual camera array: one view per wire crossing.

    Parameters
    ----------
    frames_horizontal : (T_u, H, W[, C]) array_like
        Light moving along ``e_u``; the m vertical wires in place.
    frames_vertical : (T_v, H, W[, C]) array_like
        Light moving along ``e_v``; the n horizontal wires in place.
    crossing_images : (n, m, H, W, C) array_like
        The camera's image lit from each crossing (its colours).
    spacing_frames : float
        Wire spacing in frames of the light's motion (both families).
    tolerance : float
        See :func:`assign_wires`.
    method : str
        Resampler of :func:`shadowcam.cameras.dual_view.resample_dual_view`.

    Returns
    -------
    xarray.Dataset
        ``view`` (camera_row, camera_col, v, u, channel) float32 (NaN = hole), ``coverage``
        (camera_row, camera_col, v, u), the dual coordinates ``u`` (camera_col, y, x) and
        ``v`` (camera_row, y, x) of every camera pixel, and ``reason_u``, ``reason_v``
        (y, x) (:data:`ARRAY_REASONS`). The grid is ``T_v x T_u`` (dual pixel = frame).
    """
    crossing = np.asarray(crossing_images, dtype=np.float32)
    check_array(crossing, "crossing_images", ndim=5)
    n, m = crossing.shape[:2]
    u, reason_u, _ = assign_wires(frames_horizontal, m, spacing_frames=spacing_frames, tolerance=tolerance)
    v, reason_v, _ = assign_wires(frames_vertical, n, spacing_frames=spacing_frames, tolerance=tolerance)
    shape = (np.shape(frames_vertical)[0], np.shape(frames_horizontal)[0])
    out = array_views(crossing, u, v, reason_u=reason_u, reason_v=reason_v, shape=shape, method=method)
    return out.assign_attrs(spacing_frames=float(spacing_frames), tolerance=float(tolerance))


def array_views(crossing_images, u, v, *, reason_u, reason_v, shape, method="mesh"):
    """The array dataset from each family's wire times and the crossing images.

    Parameters
    ----------
    crossing_images : (n, m, H, W, C) array_like
        The camera's image lit from each crossing.
    u : (m, H, W) array_like
        Time of each vertical wire (:func:`assign_wires` of the horizontal experiment).
    v : (n, H, W) array_like
        Time of each horizontal wire (of the vertical experiment).
    reason_u, reason_v : (H, W) array_like of int8
        :data:`ARRAY_REASONS` of each experiment.
    shape : (2,) tuple of int
        ``(T_v, T_u)``: the dual grid, the vertical and horizontal experiments' frames.
    method : str
        Resampler of :func:`shadowcam.cameras.dual_view.resample_dual_view`.

    Returns
    -------
    xarray.Dataset
        As :func:`camera_array` (without its ``spacing_frames`` and ``tolerance`` attrs).
    """
    crossing = np.asarray(crossing_images, dtype=np.float32)
    check_array(crossing, "crossing_images", ndim=5)
    u, v = np.asarray(u), np.asarray(v)
    n, m = crossing.shape[:2]
    if u.shape[0] != m or v.shape[0] != n:
        raise ValueError(f"crossing_images: {n} x {m} crossings but times of {v.shape[0]} horizontal and "
                         f"{u.shape[0]} vertical wires")
    if u.shape[1:] != crossing.shape[2:4] or v.shape[1:] != crossing.shape[2:4]:
        raise ValueError(f"crossing_images: image size {crossing.shape[2:4]} differs from the frames' "
                         f"{u.shape[1:]}")
    shape = tuple(int(k) for k in shape)
    views = np.full((n, m, *shape, crossing.shape[4]), np.nan, np.float32)
    coverage = np.zeros((n, m, *shape), bool)
    for i in range(n):
        for j in range(m):
            views[i, j], coverage[i, j] = resample_dual_view(crossing[i, j], u[j], v[i], shape=shape,
                                                             method=method)
    channels = ["R", "G", "B"][:crossing.shape[4]] if crossing.shape[4] <= 3 else np.arange(crossing.shape[4])
    return xr.Dataset(
        {"view": (("camera_row", "camera_col", "v", "u", "channel"), views),
         "coverage": (("camera_row", "camera_col", "v", "u"), coverage),
         "u": (("camera_col", "y", "x"), u.astype(np.float32)),
         "v": (("camera_row", "y", "x"), v.astype(np.float32)),
         "reason_u": (("y", "x"), np.asarray(reason_u, np.int8)),
         "reason_v": (("y", "x"), np.asarray(reason_v, np.int8))},
        coords={"camera_row": np.arange(n), "camera_col": np.arange(m), "channel": channels},
        attrs={"method": method, "reasons": str(ARRAY_REASONS),
               "definitions": "view[i, j] at (v, u): the colour of crossing (i, j)'s image at the camera "
                              "pixel whose times of horizontal wire i and vertical wire j are (v, u)"})


def _rms(x):
    x = x[np.isfinite(x)]
    return float(np.sqrt(np.mean(x**2))) if x.size else float("nan")


def array_accuracy(array, t_vertical_wire, t_horizontal_wire, *, reciprocal=None, depth=None,
                   disparity_per_inverse_depth=None):
    """Checks of a camera array against exact wire times.

    Parameters
    ----------
    array : xarray.Dataset
        From :func:`camera_array`.
    t_vertical_wire : (m, H, W) array_like
        Exact time of each vertical wire at each pixel (NaN = unknown).
    t_horizontal_wire : (n, H, W) array_like
    reciprocal : (n, m, T_v, T_u, C) array_like, optional
        Ground-truth views; each estimated view is compared after one gain (least squares
        over the pixels both have).
    depth : (H, W) array_like, optional
        Depth of each pixel's point beyond the mask plane (scene units).
    disparity_per_inverse_depth : (float, float), optional
        ``(s, s g)``: the disparity between neighbouring cameras is ``s + s g / d`` frames.

    Returns
    -------
    dict
        ``coordinate_rmse`` (n, m) list: RMS over pixels of the distance between the
        estimated and exact (u, v) of camera (i, j); ``coverage`` (n, m) list: fraction of
        pixels with exact times that got both coordinates; ``v_rmse_per_row`` (n): RMS error
        of the v shared by the cameras of array row i (a point's row is the same across
        them by construction, so the array is rectified to this error); ``u_rmse_per_column``
        (m): the same for the u of array column j; ``disparity_rmse``: RMS of the
        estimated neighbouring-camera gaps against the depth law (when `depth` given);
        ``view_rmse`` (n, m): RMS of the view after the gain over the reciprocal's RMS,
        ``view_coverage`` and ``reciprocal_coverage`` (n, m): fractions of the dual grid
        each covers (when `reciprocal` given).
    """
    u, v = array["u"].values.astype(np.float64), array["v"].values.astype(np.float64)
    tu, tv = np.asarray(t_vertical_wire, np.float64), np.asarray(t_horizontal_wire, np.float64)
    n, m = v.shape[0], u.shape[0]
    du, dv = u - tu, v - tv
    rmse = [[_rms(np.hypot(du[j], dv[i])) for j in range(m)] for i in range(n)]
    known = [[np.isfinite(tu[j]) & np.isfinite(tv[i]) for j in range(m)] for i in range(n)]
    cover = [[float(np.mean((np.isfinite(u[j]) & np.isfinite(v[i]))[known[i][j]]))
              if known[i][j].any() else 0.0 for j in range(m)] for i in range(n)]
    out = {"coordinate_rmse": rmse, "coverage": cover,
           "u_rmse_per_column": [_rms(du[j]) for j in range(m)],
           "v_rmse_per_row": [_rms(dv[i]) for i in range(n)]}
    if depth is not None and disparity_per_inverse_depth is not None and m > 1:
        s, sg = disparity_per_inverse_depth
        expected = s + sg / np.asarray(depth, np.float64)
        out["disparity_rmse"] = _rms(np.diff(u, axis=0) - expected[None])
    if reciprocal is not None:
        truth = np.asarray(reciprocal, np.float64)
        views = array["view"].values.astype(np.float64)
        rel = []
        for i in range(n):
            row = []
            for j in range(m):
                a, b = views[i, j], truth[i, j]
                ok = np.all(np.isfinite(a), axis=-1) & np.all(np.isfinite(b), axis=-1) & (b.sum(-1) > 0)
                if not ok.any():
                    row.append(float("nan"))
                    continue
                gain = float(np.sum(a[ok] * b[ok]) / np.sum(a[ok] ** 2))
                row.append(float(np.sqrt(np.mean((gain * a[ok] - b[ok]) ** 2)) / np.sqrt(np.mean(b[ok] ** 2))))
            rel.append(row)
        out["view_rmse"] = rel
        out["view_coverage"] = array["coverage"].values.mean(axis=(2, 3)).tolist()
        out["reciprocal_coverage"] = (truth.sum(-1) > 0).mean(axis=(2, 3)).tolist()
    return out


def capture_accuracy(array, capture):
    """:func:`array_accuracy` against a rendered capture's ground truth.

    Parameters
    ----------
    array : xarray.Dataset
        From :func:`camera_array`.
    capture : xarray.Dataset
        The capture's ``ground_truth.nc`` (exact wire times ``t_vertical_wire``,
        ``t_horizontal_wire``, ``reciprocal``, ``depth``, attrs ``spacing_frames`` and
        ``light_mask_distance``; :func:`shadowcam.synthetic.lab.array_capture.write_array_capture`).

    Returns
    -------
    dict
        :func:`array_accuracy`'s figures.
    """
    s = float(capture.attrs["spacing_frames"])
    return array_accuracy(array, capture["t_vertical_wire"].values, capture["t_horizontal_wire"].values,
                          reciprocal=capture["reciprocal"].values, depth=capture["depth"].values,
                          disparity_per_inverse_depth=(s, s * float(capture.attrs["light_mask_distance"])))
