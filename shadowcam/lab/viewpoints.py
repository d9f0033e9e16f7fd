"""Dual views from points across the dip interval (paper Fig. 13: several viewpoints from one capture).

Under an extended source or a thick mask, a pixel's shadow lasts an interval
of frames: its entry is when the mask's leading edge cuts the pixel's line to
the source's leading point, its exit when the trailing edge frees the line to
the trailing point, and a fraction across the interval when the line to a
point between them is cut. Each fraction, used as the pixel's shadow time,
gives a dual view from a different point of the source or mask. The half-depth
interval's entry and exit are the wire's edges passing the source's centre; the
penumbra's outer edges (first contact, last release; :mod:`shadowcam.lab.penumbra_law`)
are the edges passing the source's extreme points: the views from those points.

Offers
------
VIEWPOINTS : named viewpoints -> fraction across the half-depth interval.
OUTER_VIEWPOINTS : named viewpoints -> fraction across the penumbra's outer edges.
viewpoint_fraction : a viewpoint name or number -> its fraction.
shadow_time_at : a ``shadow_time`` dataset whose times are those of one viewpoint.
"""

import numpy as np

from shadowcam._shared.validation import check_in_interval

#: named viewpoints: fraction across the dip's half-depth interval (0 = entry, 1 = exit)
VIEWPOINTS = {"entry": 0.0, "centre": 0.5, "exit": 1.0}
#: named viewpoints: fraction across the penumbra's outer edges (0 = first contact, 1 = last
#: release: the views from the source's extreme points)
OUTER_VIEWPOINTS = {"penumbra_first": 0.0, "penumbra_last": 1.0}


def viewpoint_fraction(viewpoint):
    """Fraction across its interval of `viewpoint` (a key of :data:`VIEWPOINTS` or
    :data:`OUTER_VIEWPOINTS`, or a number in [0, 1] across the half-depth interval)."""
    named = {**VIEWPOINTS, **OUTER_VIEWPOINTS}
    if isinstance(viewpoint, str) and viewpoint in named:
        return named[viewpoint]
    try:
        fraction = float(viewpoint)
    except (TypeError, ValueError):
        raise ValueError(f"viewpoint must be one of {sorted(named)} or a fraction in [0, 1]; "
                         f"got {viewpoint!r}") from None
    return check_in_interval(fraction, "viewpoint", 0.0, 1.0, closed="both")


def shadow_time_at(shadow_time, viewpoint):
    """The ``shadow_time`` dataset with each timed pixel's time at `viewpoint` across its interval.

    Parameters
    ----------
    shadow_time : xarray.Dataset
        With ``interval_entry``, ``interval_exit`` and their ``*_std`` over
        ``(sweep, row, col)`` (:func:`shadowcam.lab.shadow_time.shadow_time_of_stores`).
    viewpoint : str or float
        See :func:`viewpoint_fraction`; :data:`OUTER_VIEWPOINTS` need ``penumbra_first``,
        ``penumbra_last`` and their ``*_std`` (the penumbra law's, wide dips only).

    Returns
    -------
    xarray.Dataset
        A copy whose ``shadow_time`` is ``entry + f (exit - entry)`` (the outer
        edges' for :data:`OUTER_VIEWPOINTS`) and
        ``time_std`` the propagated crossing noise; pixels without an interval
        lose their time (NaN, confidence 0). Attrs ``viewpoint`` and
        ``viewpoint_fraction``.
    """
    fraction = viewpoint_fraction(viewpoint)
    start, stop = ("penumbra_first", "penumbra_last") if viewpoint in OUTER_VIEWPOINTS else \
        ("interval_entry", "interval_exit")
    missing = {start, stop, f"{start}_std", f"{stop}_std"} - set(shadow_time)
    if missing:
        why = ("the penumbra law measures the outer edges of wide dips only" if start == "penumbra_first"
               else "it was computed without the dip-interval pass")
        raise ValueError(f"shadow_time has no {sorted(missing)}: {why}; recompute it with the current "
                         "shadow-time step")
    entry, exit_ = shadow_time[start], shadow_time[stop]
    time = entry + fraction * (exit_ - entry)
    std = np.hypot((1 - fraction) * shadow_time[f"{start}_std"], fraction * shadow_time[f"{stop}_std"])
    out = shadow_time.copy()
    out["shadow_time"] = time.astype(np.float32).assign_attrs(shadow_time["shadow_time"].attrs)
    out["time_std"] = std.astype(np.float32).assign_attrs(shadow_time["time_std"].attrs)
    timed = np.isfinite(time)
    out["confidence"] = shadow_time["confidence"].where(timed, 0.0).astype(np.float32)
    out.attrs.update(viewpoint=str(viewpoint), viewpoint_fraction=fraction)
    return out
