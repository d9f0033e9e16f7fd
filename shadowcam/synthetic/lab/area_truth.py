"""Exact entry and exit times of a wire's shadow under an area light (the renderer's model).

A disc, sphere or tube is rendered as the continuous source
(:mod:`shadowcam.synthetic.lab.area_occlusion`): the time at which a `fraction` of it is
blocked is solved on its exact blocked share (``fraction = 0``: first contact and last
release, the source's extreme points). A square is rendered as weighted point samples (:func:`shadowcam.synthetic.lab.scene.light_samples`);
the wire (a cylinder) blocks the segment from a scene point to each sample
during an analytic interval of frames
(:func:`shadowcam.synthetic.lab.raycast.wire_occlusion_interval`). When the
wire is wider than the source seen through it, the blocked weight rises from
0 (the leading edge reaches the source's first extreme point) to all of it
(an umbra) and falls again: the time at which a `fraction` of the weight is
blocked is the weighted quantile of the samples' interval starts, and the
time at which it falls back to that fraction is the same from their ends
taken backwards (the blocked weight's staircase interpolated linearly
between the middles of its steps). ``fraction = 0`` gives the extreme points' times (the
penumbra's outer edges), ``fraction = 0.5`` the half-depth crossings a
tracker measures.

Offers
------
sample_intervals : per point and light sample, the frames the wire blocks it.
area_light_times : entry and exit at a blocked fraction of the source, per point (exact for
    the continuous disc, sphere and tube; the samples' staircase for a square).
"""

import numpy as np

from shadowcam._shared.validation import check_array, check_in_interval
from shadowcam.synthetic.lab.area_occlusion import exact_occlusion, occlusion_times
from shadowcam.synthetic.lab.raycast import wire_occlusion_interval
from shadowcam.synthetic.lab.scene import light_samples


def sample_intervals(points, sweep, mask, light):
    """Blocked interval of each (point, light sample) pair.

    Parameters
    ----------
    points : (N, 3) array_like
        Scene points.
    sweep : WireSweep
    mask : MaskPlane
    light : PointLight or AreaLight

    Returns
    -------
    start, stop : (N, S) float64 ndarray
        Frames between which the wire blocks the segment to sample s (NaN where never).
    weight : (S,) float64 ndarray
        Each sample's share of the light (sums to 1).
    """
    points = np.asarray(points, np.float64)
    check_array(points, "points", shape=(None, 3))
    positions, _, weights = light_samples(light)
    if positions is None:
        raise ValueError("light: needs positions (a point or area light), not a distant light")
    n, s = len(points), len(positions)
    centre, half = wire_occlusion_interval(np.repeat(points, s, axis=0), np.tile(positions, (n, 1)),
                                           sweep, mask)
    centre, half = centre.reshape(n, s), half.reshape(n, s)
    weight = weights.sum(axis=1)
    return centre - half, centre + half, weight / weight.sum()


def _blocked_time(values, weight, q):
    """Per row of `values` (N, S), when the blocked weight reaches `q` (NaN if any is NaN).

    The blocked weight is a staircase (sample k blocked from ``values[k]``);
    its continuous version interpolates linearly between the middles of the
    steps, and runs from the first to the last value.
    """
    order = np.argsort(values, axis=1)
    sorted_values = np.take_along_axis(values, order, axis=1)
    cumulative = np.cumsum(weight[order], axis=1)
    middle = cumulative - 0.5 * weight[order]
    result = np.array([np.interp(q, m, v) for m, v in zip(middle, sorted_values)])
    return np.where(np.isnan(values).any(axis=1), np.nan, result)


def area_light_times(points, sweep, mask, light=None, *, fraction=0.5):
    """When the wire starts and stops blocking `fraction` of an area light, per point.

    Parameters
    ----------
    points : (N, 3) array_like
    sweep : WireSweep
    mask : MaskPlane
    light : PointLight or AreaLight, optional
        Default the sweep's own light.
    fraction : float, optional
        Blocked share of the light's weight, in ``[0, 1]``: 0 = the source's
        extreme points (first and last sample blocked at all), 0.5 = half
        depth, 1 = the umbra's edges.

    Returns
    -------
    entry, exit : (N,) float64 ndarray
        Fractional frames; NaN where the wire misses a sample (no full interval).
    """
    check_in_interval(fraction, "fraction", 0.0, 1.0, closed="both")
    light = sweep.light if light is None else light
    if light is None:
        raise ValueError("light: the sweep carries no light; pass one")
    if exact_occlusion(light):
        # a share just below the whole: the umbra's edges for fraction 1
        return occlusion_times(points, light, sweep, mask, share=min(float(fraction), 1.0 - 1e-12))
    start, stop, weight = sample_intervals(points, sweep, mask, light)
    # blocked weight rising through `fraction` (interval starts), falling back (ends, reversed)
    entry = _blocked_time(start, weight, fraction)
    exit_ = -_blocked_time(-stop, weight, fraction)
    return entry, exit_
