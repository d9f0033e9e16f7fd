"""Exact ground truth of a synthetic outdoor time-lapse (definitions of dev_ridge's gt.npz).

Same variable names and definitions as the shared ``outdoor-dev/dev_ridge/gt.npz``
(``/work/shared/data/README.md`` 2.6), computed with the renderer's own sun-visibility test
(:func:`shadowcam.synthetic.outdoor.render.sun_lit`), so the frames show exactly this truth.

Offers
------
SHADOW_CLASSES : class code -> name (0 sky, 1 never shadowed, 2 shadowed at start, 3 arrives).
DEFINITIONS : variable -> definition (stored as the ``definitions`` attr, JSON).
state_gains : the true lit and sky gains of each frame.
arrival_times : per-sample first unlit time (frames scanned, then bisected in time).
classify : shadow classes and masks of pixel centres from their lit-per-frame table.
pushbroom_edge : ``pb_edge_y`` and ``pb_n_transitions`` from pixel-centre arrival times.
sample_rows : image sampled at fractional rows per (frame, column) (linear in the row).
pushbroom_bins : ``pb_bin`` / ``pb_bin_count``.
"""

import numpy as np

from shadowcam.synthetic.outdoor.render import sun_lit

SHADOW_CLASSES = {0: "sky", 1: "never_shadowed", 2: "shadowed_at_start", 3: "shadow_arrives"}

DEFINITIONS = {
    "conventions": "arrays are (row, col) in the UNSHAKEN reference camera; pixel (row v, col u) "
                   "centre at image point (u+0.5, v+0.5); times in seconds since the first frame",
    "lit": "a terrain point p is lit at time t iff n_shading(p) . l(t) > 0 and the sun elevation "
           "exceeds the terrain horizon H(p, azimuth(t)) (shadowcam.synthetic.outdoor.terrain.horizon_angles, "
           "0.5 m origin offset, interpolated linearly between azimuth nodes) - the test the "
           "renderer applies to every sample, so frames and ground truth agree by construction",
    "sun": "point sun (sun_diameter_deg 0) or a uniform disc of sun_diameter_deg: the frames "
           "use the visible disc fraction above the horizon's tangent line (the penumbra); "
           "'lit' and every arrival time below refer to the disc's centre, i.e. the middle of "
           "the penumbra (visible fraction 1/2)",
    "penumbra_start_time_s": "disc sun: first time the disc's centre is within one sun radius "
                             "of the horizon (light starts to fade), same scan and bisection; "
                             "NaN unless shadow_class==3 or when shadowed from the start",
    "penumbra_end_time_s": "disc sun: first time the whole disc is below the horizon (sun "
                           "fully hidden); NaN if it never happens in the sequence",
    "arrival_time_s": "pixel-centre point: first time it is not lit. Frames are scanned; for the "
                      "first unlit frame k (k>=1) the time is bisected (30 steps) in "
                      "(t[k-1], t[k]] with the continuous sun model; NaN unless shadow_class==3",
    "arrival_frame": "arrival_time_s as a fractional frame index (piecewise-linear in times_s)",
    "first_shadowed_frame": "first frame index at which the pixel-centre point is unlit (-1 never)"
                            "; = ceil(arrival_frame) for class 3",
    "shadow_class": "0 sky (centre ray misses terrain), 1 never shadowed (lit in every frame), "
                    "2 shadowed at start (unlit in frame 0), 3 shadow arrives during the sequence",
    "always_shadowed": "unlit in every frame",
    "relit_after_arrival": "lit again in some frame after first_shadowed_frame",
    "cause": "for class 3: 1 cast shadow (horizon above the sun), 2 attached (n_shading . l <= 0)",
    "subpixel_arrival_time_s": "(row, col, subpixel) same definition for the renderer's s x s "
                               "samples of each pixel (offsets subpixel_offsets, pixels from the "
                               "pixel corner); +inf never, -inf at start, NaN sky",
    "arrival_time_half_coverage_s": "median of the sub-pixel arrival times (~ time of 50% "
                                    "footprint coverage); NaN if any sub-sample is sky or the "
                                    "median is not finite",
    "sky_fraction": "fraction of the pixel's render samples whose view ray misses the terrain",
    "reference_radiance": "noise-free linear RGB radiance of frame 0 (no cloud, gain, shake or "
                          "noise)",
    "pb_edge_y": "(time, col) shadow-edge position in column u at frame k: lowest (largest v) "
                 "pair of vertically adjacent non-sky pixels with row v lit and row v+1 shadowed "
                 "at t_k (lit: T>t_k or never; shadowed: T<=t_k or at start); y = v + 0.5 + f "
                 "with f = (T[v]-t_k)/(T[v]-T[v+1]) (0.5 if either is infinite); NaN if no such "
                 "pair",
    "pb_n_transitions": "(time, col) number of lit-above/shadowed-below pairs in the column",
    "pb_front": "(time, col, channel) GROUND-TRUTH PUSHBROOM: reference_radiance sampled at "
                "(u, pb_edge_y) by linear interpolation between rows v and v+1 (row v only if "
                "v+1 is already shadowed at frame 0). Row k = time t_k, column = image column",
    "pb_front_live": "(time, col, channel) like pb_front but the noise-free radiance of frame k "
                     "itself (its sun and sky colour; no cloud/gain/shake/noise) at the lit-side "
                     "pixel row v",
    "pb_bin": "(time, col, channel) mean reference_radiance of the class-3 pixels of column u "
              "with t[k-1] < T <= t[k]; NaN where pb_bin_count == 0",
    "cloud_attenuation": "(time, row, col) mean over the pixel's samples of the cloud shadow's "
                         "transmittance of the sun term (1 = no cloud); cloud shadow is NOT "
                         "terrain shadow and does not enter lit / arrival times",
    "exposure_gain": "true total gain of frame k (auto-exposure steps x flicker); the frame's "
                     "ExposureTime metadata carries only the step part (ae_ev)",
    "lit_gain": "(time) the gain of sunlit pixels: exposure_gain x the median over non-sky pixels "
                "whose footprint sees the whole sun in frames 0 and k of their cloud-free luminance "
                "in frame k / in frame 0 (what the first outdoor pass's gain_lit estimates; NaN "
                "without such pixels)",
    "sky_gain": "(time) the gain of sky-lit pixels: the same over pixels that see none of the sun "
                "in frames 0 and k (a cloud shadow does not change it)",
}



def state_gains(clear, sun_seen, sky, *, exposure_gain):
    """The true lit and sky gains of each frame (:data:`DEFINITIONS` ``lit_gain``, ``sky_gain``).

    Parameters
    ----------
    clear : (K, H, W, 3) ndarray
        Cloud-free radiance of every frame (before exposure, shake and noise).
    sun_seen : (K, H, W) ndarray
        Visible fraction of the sun over each pixel's footprint.
    sky : (H, W) bool ndarray
    exposure_gain : (K,) ndarray

    Returns
    -------
    lit_gain, sky_gain : (K,) float64 ndarray
    """
    luma = np.asarray(clear, dtype=np.float64).mean(axis=-1)
    seen = np.asarray(sun_seen, dtype=np.float64)
    terrain = ~np.asarray(sky, dtype=bool) & (luma[0] > 0)
    out = np.full((2, len(luma)), np.nan)
    for k in range(len(luma)):
        for row, keep in enumerate(((seen[0] == 1) & (seen[k] == 1), (seen[0] == 0) & (seen[k] == 0))):
            keep &= terrain
            if keep.any():
                out[row, k] = exposure_gain[k] * np.median(luma[k][keep] / luma[0][keep])
    return out[0], out[1]


def arrival_times(geometry, sun, frame_times, *, bisect_steps=30, offset_rad=0.0):
    """First unlit time of every sample.

    Parameters
    ----------
    geometry : shadowcam.synthetic.outdoor.render.SampleGeometry
    sun : shadowcam.synthetic.outdoor.sun.SunPath
    frame_times : (K,) ndarray
        Frame times (s), increasing.
    bisect_steps : int, keyword-only
    offset_rad : float, keyword-only
        Unlit means the sun's centre is at most this far above the horizon
        (:func:`shadowcam.synthetic.outdoor.render.sun_lit`): 0 the penumbra's centre (and
        the point sun), ``+radius`` the penumbra's start, ``-radius`` its end.

    Returns
    -------
    arrival : (N,) ndarray
        Seconds; ``-inf`` unlit in frame 0, ``+inf`` lit in every frame, NaN sky.
    lit : (K, N) bool ndarray
        Sun visibility per frame.
    first : (N,) ndarray of int
        First unlit frame (-1 never).
    """
    frame_times = np.asarray(frame_times, dtype=np.float64)
    if frame_times.ndim != 1 or np.any(np.diff(frame_times) <= 0):
        raise ValueError("frame_times: expected increasing 1-D times")
    lit = np.stack([sun_lit(geometry, sun, t, offset_rad=offset_rad) for t in frame_times])
    unlit = ~lit
    any_unlit = unlit.any(axis=0)
    first = np.where(any_unlit, np.argmax(unlit, axis=0), -1)
    arrival = np.where(any_unlit, -np.inf, np.inf)
    arrival[geometry.sky] = np.nan
    todo = np.flatnonzero((first >= 1) & ~geometry.sky)
    if todo.size:
        lo = frame_times[first[todo] - 1].copy()
        hi = frame_times[first[todo]].copy()
        sub = _subset(geometry, todo)
        for _ in range(bisect_steps):
            mid = 0.5 * (lo + hi)
            lit_mid = sun_lit(sub, sun, mid, offset_rad=offset_rad)
            lo = np.where(lit_mid, mid, lo)
            hi = np.where(lit_mid, hi, mid)
        arrival[todo] = 0.5 * (lo + hi)
    return arrival, lit, first


def _subset(geometry, index):
    from dataclasses import replace

    return replace(geometry, sky=geometry.sky[index], position=geometry.position[index],
                   normal=geometry.normal[index], albedo=geometry.albedo[index],
                   view_dir=geometry.view_dir[index], depth_z=geometry.depth_z[index],
                   horizon=geometry.horizon[index])


def classify(lit, first, sky):
    """Shadow classes and masks of pixel centres.

    Parameters
    ----------
    lit : (K, N) bool ndarray
    first : (N,) int ndarray
        First unlit frame (-1 never).
    sky : (N,) bool ndarray

    Returns
    -------
    dict of (N,) arrays
        ``shadow_class`` (uint8), ``never_shadowed``, ``shadowed_at_start``,
        ``always_shadowed``, ``relit_after_arrival`` (bool).
    """
    k = np.arange(lit.shape[0])[:, None]
    cls = np.where(sky, 0, np.where(first < 0, 1, np.where(first == 0, 2, 3))).astype(np.uint8)
    relit = (lit & (k > first[None, :])).any(axis=0) & (first >= 0)
    return {
        "shadow_class": cls,
        "never_shadowed": cls == 1,
        "shadowed_at_start": cls == 2,
        "always_shadowed": ~lit.any(axis=0) & ~sky,
        "relit_after_arrival": relit,
    }


def pushbroom_edge(arrival, sky, frame_times):
    """Shadow-edge row per frame and column from pixel-centre arrival times.

    Parameters
    ----------
    arrival : (rows, cols) ndarray
        ``T``: seconds, ``+inf`` never shadowed, ``-inf`` shadowed at start, NaN sky.
    sky : (rows, cols) bool ndarray
    frame_times : (K,) ndarray

    Returns
    -------
    edge_y : (K, cols) float32 ndarray
        Image row coordinate (pixel-edge) of the edge (NaN: no lit-above/shadowed-below pair).
    n_transitions : (K, cols) int16 ndarray
    row : (K, cols) int ndarray
        The lit-side row v of the chosen pair (-1 none).
    """
    T = np.asarray(arrival, dtype=np.float64)
    upper, lower = T[:-1], T[1:]
    valid = ~sky[:-1] & ~sky[1:]
    K, cols = len(frame_times), T.shape[1]
    edge = np.full((K, cols), np.nan, dtype=np.float32)
    count = np.zeros((K, cols), dtype=np.int16)
    row = np.full((K, cols), -1, dtype=np.int64)
    v = np.arange(T.shape[0] - 1)[:, None]
    with np.errstate(invalid="ignore"):
        for k, t in enumerate(frame_times):
            pair = valid & (upper > t) & (lower <= t)
            count[k] = pair.sum(axis=0)
            last = np.where(pair, v, -1).max(axis=0)
            has = last >= 0
            c = np.flatnonzero(has)
            r = last[has]
            tu, tl = T[r, c], T[r + 1, c]
            finite = np.isfinite(tu) & np.isfinite(tl)
            f = np.where(finite, (tu - t) / np.where(finite, tu - tl, 1.0), 0.5)
            edge[k, c] = r + 0.5 + f
            row[k, c] = r
    return edge, count, row


def sample_rows(image, row, frac, use_lower):
    """Per (frame, column): ``image`` at rows ``row`` and ``row + 1`` mixed by ``frac``.

    Parameters
    ----------
    image : (rows, cols, 3) ndarray
    row : (K, cols) int ndarray
        Upper row (-1: none -> NaN).
    frac : (K, cols) ndarray
        Weight of ``row + 1``.
    use_lower : (K, cols) bool ndarray
        False: take ``row`` alone.

    Returns
    -------
    (K, cols, 3) float32 ndarray
    """
    K, cols = row.shape
    out = np.full((K, cols, 3), np.nan, dtype=np.float32)
    has = row >= 0
    k, c = np.nonzero(has)
    r = row[has]
    f = np.where(use_lower[has], frac[has], 0.0)[:, None]
    lower = image[np.minimum(r + 1, image.shape[0] - 1), c]
    out[k, c] = (1.0 - f) * image[r, c] + f * lower
    return out


def pushbroom_bins(arrival, shadow_class, reference, frame_times):
    """Mean reference radiance of the class-3 pixels swept between frames k-1 and k.

    Returns
    -------
    pb_bin : (K, cols, 3) float32 ndarray (NaN where empty)
    pb_bin_count : (K, cols) int16 ndarray
    """
    K, cols = len(frame_times), arrival.shape[1]
    total = np.zeros((K, cols, 3))
    count = np.zeros((K, cols), dtype=np.int64)
    r, c = np.nonzero(shadow_class == 3)
    k = np.searchsorted(frame_times, arrival[r, c], side="left")  # t[k-1] < T <= t[k]
    ok = (k >= 1) & (k < K)
    np.add.at(total, (k[ok], c[ok]), reference[r[ok], c[ok]])
    np.add.at(count, (k[ok], c[ok]), 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = total / count[..., None]
    mean[count == 0] = np.nan
    return mean.astype(np.float32), count.astype(np.int16)
