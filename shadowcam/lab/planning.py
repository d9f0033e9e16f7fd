"""Resolution planning of a shadow-camera capture (paper section II-B, Eq. 3).

A mask moving at speed ``u`` a distance ``h`` in front of the light moves ``x = u t``
per frame (``t`` the frame time: exposure = frame interval, no motion-blur gaps). Its
shadow moves ``S = D x / h`` on the most distant scene plane (depth ``D``, Eq. 1),
which a lens of focal length ``f`` images as ``S' = f D x / (h (D - f))`` (Eq. 2). With
pixels of width ``W`` the dual view has

    r = W h (D - f) / (f D u t)                                   (Eq. 3)

dual pixels per camera pixel in each dimension: the shadow takes ``r`` frames to cross
one camera pixel, so a sweep across ``N`` camera pixels takes ``r N`` frames and gives
``r N`` dual pixels. ``r > 1`` asks for more dual pixels than the camera resolves (the
dual view then has holes; paper: "bound by the actual resolution of the real camera").
All lengths in one unit (e.g. metres), speed in that unit per second, ``t`` in seconds.
``(D - f)/D`` is the thin-lens image distance of a lens focused at ``D``; an ideal pinhole
(image plane at ``f``) has 1 there, a difference of ``f / D``.

Offers
------
dual_resolution_ratio : Eq. 3, r from the capture geometry.
mask_speed_for_ratio : Eq. 3 inverted, the mask speed giving a wanted r.
plan_capture : r, dual pixels and frames per sweep, plus the recommended mask speed for a
    wanted dual resolution.
"""

from shadowcam._shared.validation import check_positive


def _geometry(pixel_width, mask_distance, depth, focal_length, frame_time):
    w = check_positive(float(pixel_width), "pixel_width", finite=True)
    h = check_positive(float(mask_distance), "mask_distance", finite=True)
    d = check_positive(float(depth), "depth", finite=True)
    f = check_positive(float(focal_length), "focal_length", finite=True)
    t = check_positive(float(frame_time), "frame_time", finite=True)
    if not d > f:
        raise ValueError(f"depth: must exceed focal_length ({d} <= {f}); give both in one unit")
    return w * h * (d - f) / (f * d * t)


def dual_resolution_ratio(*, pixel_width, mask_distance, depth, focal_length, mask_speed,
                          frame_time):
    """Dual pixels per camera pixel (each dimension), the paper's Eq. 3.

    Parameters
    ----------
    pixel_width : float
        Width W of a camera pixel on the sensor (length).
    mask_distance : float
        Distance h from the light to the mask (length).
    depth : float
        Greatest scene depth D from the camera (length).
    focal_length : float
        Camera focal length f (length).
    mask_speed : float
        Mask speed u (length per second).
    frame_time : float
        Time t per frame (s): the mask moves ``u t`` per frame.

    Returns
    -------
    float
        ``r = W h (D - f) / (f D u t)``; frames the shadow needs to cross one camera pixel.
    """
    u = check_positive(float(mask_speed), "mask_speed", finite=True)
    return _geometry(pixel_width, mask_distance, depth, focal_length, frame_time) / u


def mask_speed_for_ratio(ratio, *, pixel_width, mask_distance, depth, focal_length,
                         frame_time):
    """Mask speed giving `ratio` dual pixels per camera pixel (Eq. 3 solved for u).

    Parameters
    ----------
    ratio : float
        Wanted r (> 0; above 1 the dual view outresolves the camera).
    pixel_width, mask_distance, depth, focal_length, frame_time : float
        As in :func:`dual_resolution_ratio`.

    Returns
    -------
    float
        ``u = W h (D - f) / (f D r t)`` (length per second).
    """
    r = check_positive(float(ratio), "ratio", finite=True)
    return _geometry(pixel_width, mask_distance, depth, focal_length, frame_time) / r


def plan_capture(*, pixel_width, mask_distance, depth, focal_length, frame_time,
                 image_pixels, mask_speed=None, wanted_dual_pixels=None):
    """Plan a sweep: dual resolution of a mask speed, and the speed for a wanted resolution.

    Parameters
    ----------
    pixel_width, mask_distance, depth, focal_length, frame_time : float
        As in :func:`dual_resolution_ratio`.
    image_pixels : int
        Camera pixels across the swept direction.
    mask_speed : float, optional
        Planned mask speed: report its r, dual pixels and frames per sweep.
    wanted_dual_pixels : int, optional
        Wanted dual pixels across the sweep: report the mask speed that gives them.

    Returns
    -------
    dict
        ``ratio``, ``dual_pixels`` (``r N``), ``frames_per_sweep`` (frames for the
        shadow to cross the image, ``r N``), ``exceeds_camera`` (r > 1) for `mask_speed`;
        ``recommended_mask_speed``, ``recommended_ratio`` and ``mask_step_per_frame``
        for `wanted_dual_pixels`.
    """
    n = int(image_pixels)
    if n < 1:
        raise ValueError(f"image_pixels must be a positive integer; got {image_pixels!r}")
    if mask_speed is None and wanted_dual_pixels is None:
        raise ValueError("mask_speed, wanted_dual_pixels: give at least one")
    geometry = dict(pixel_width=pixel_width, mask_distance=mask_distance, depth=depth,
                    focal_length=focal_length, frame_time=frame_time)
    out = {"image_pixels": n}
    if mask_speed is not None:
        r = dual_resolution_ratio(mask_speed=mask_speed, **geometry)
        out.update(mask_speed=float(mask_speed), ratio=r, dual_pixels=r * n,
                   frames_per_sweep=r * n, exceeds_camera=bool(r > 1))
    if wanted_dual_pixels is not None:
        r = check_positive(float(wanted_dual_pixels), "wanted_dual_pixels", finite=True) / n
        speed = mask_speed_for_ratio(r, **geometry)
        out.update(wanted_dual_pixels=float(wanted_dual_pixels), recommended_ratio=r,
                   recommended_mask_speed=speed,
                   mask_step_per_frame=speed * float(frame_time),
                   recommended_exceeds_camera=bool(r > 1))
    return out
