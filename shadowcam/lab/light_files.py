"""One shadow camera per light from a several-lights capture's files (a user's manifest or a rendered ``capture.json``).

A several-lights capture (docs/contracts.md) is a standard lab capture, sweeps ``u`` and
``v`` of frame files and a reference frame, shot under several lights at once, with a
top-level ``lights`` block (``kinds``, optional ``light_along_u``, ``light_along_v``); its
plan (:func:`shadowcam.io.capture_plan.capture_plan`) lists them. Each sweep is streamed
twice through the lab sweeps' decoder (:func:`shadowcam.io.decode.iter_frames`: camera RAW,
TIFF, PNG, EXR to linear RGB), a block of frames at a time (:func:`shadowcam.io.decode.frame_blocks`), into
the two passes of :func:`shadowcam.lab.minima.find_minima` (per-pixel work in row bands),
whose minima :func:`shadowcam.lab.light_views.sweep_light_times` assigns to the lights
(camera RAW: timed from each pixel's own mosaic site where its noise allows): memory
follows the frame size, not the sweep's length.

Offers
------
light_set_views_of_plan : a several-lights capture plan -> the per-light views dataset.
light_set_capture_of_plan : the capture's frames, reference and ground truth as one dataset
    (what :func:`shadowcam.lab.light_views.light_set_views` and the methods comparison read).
"""

import numpy as np
import xarray as xr

from shadowcam.io.decode import frame_blocks, frame_info, read_stack
from shadowcam.lab.light_views import SWEEPS, light_views_dataset, pair_sweep_lights, sweep_light_times, view_attrs


def _captured(plan):
    block = plan.light_set
    if block is None or plan.rendered:
        raise ValueError(f"plan: manifest {plan.manifest_path} is not a captured several-lights capture (no "
                         "top-level lights block over sweeps u, v); render a synthetic one with render-lights "
                         "and pass its capture.json")
    return block


def _cfa_pattern(plan):
    """The CFA pattern of the sweeps' camera RAW files (the first file of each, which must agree),
    or None for other frames."""
    patterns = {name: frame_info(plan.sweep(name).files[0])["cfa_pattern"] for name in SWEEPS}
    if len(set(patterns.values())) > 1:
        raise ValueError(f"plan: manifest {plan.manifest_path}: the sweeps' first files have CFA patterns "
                         f"{patterns}; both sweeps must come from one camera")
    return patterns[SWEEPS[0]] or None


def _reference(plan):
    """The mean of the capture's reference frames, (H, W, 3) float32."""
    return read_stack(plan.reference, shape=plan.frame_shape).mean(axis=0)


def light_set_views_of_plan(plan, *, half_window=4, method="edge_fit", radius=2, tolerance=2.0, check_order=True):
    """Per-light shadow times and dual views of a captured (or rendered and written) several-lights capture.

    The sweeps are streamed one after the other, each twice (the minima's two passes), a
    block of frames at a time. Camera RAW sweeps are timed from each pixel's own mosaic site where its noise allows
    (the CFA pattern of the sweep's first file, :func:`shadowcam.io.decode.frame_info`).

    Parameters
    ----------
    plan : shadowcam.io.capture_plan.CapturePlan
        Of a manifest with a top-level ``lights`` block (``plan.light_set`` with ``kinds``,
        ``light_along_u``, ``light_along_v``), sweeps ``u``, ``v`` and a reference.
    half_window, method, radius, tolerance, check_order
        See :func:`shadowcam.lab.light_views.light_set_views`; without described positions
        light k is the k-th shadow to pass in the u sweep, paired with the v sweep's by
        their contrast maps (:func:`shadowcam.lab.light_views.pair_sweep_lights`).

    Returns
    -------
    xarray.Dataset
        :func:`shadowcam.lab.light_views.light_set_views`'s dataset over the dual grid
        (frames of v, frames of u); attrs also ``kinds`` (per light) and ``light_order``:
        ``described`` (by ``light_along_*``) or ``shadows`` (in the order they pass), and
        the sweeps' pairing (``pairing``, ``pairing_z``, ``pairing_decided``,
        :func:`shadowcam.lab.light_views.pair_sweep_lights`).

    Raises
    ------
    ValueError
        A plan without a captured ``lights`` block, a frame of another size than the
        capture's, or measured positions against the described ones (naming
        ``light_along_<sweep>``).
    """
    block = _captured(plan)
    described = block["light_along_u"] is not None
    pattern = _cfa_pattern(plan)
    per_sweep, positions = {}, {}
    for name in SWEEPS:
        per_sweep[name], positions[name] = sweep_light_times(
            frame_blocks(plan.sweep(name).files, plan.frame_shape), block["count"], sweep=name,
            light_along=block[f"light_along_{name}"], half_window=half_window, method=method, radius=radius,
            tolerance=tolerance, check_order=check_order, cfa_pattern=pattern, shape=plan.frame_shape)
    per_sweep, positions, pairing = pair_sweep_lights(per_sweep, positions, described=described, check=check_order)
    attrs = view_attrs(half_window=half_window, method=method, radius=radius, tolerance=tolerance,
                       check_order=check_order and described)
    attrs.update(kinds=list(block["kinds"]), light_order="described" if described else "shadows", **pairing)
    return light_views_dataset(per_sweep, positions, _reference(plan),
                               shape=(plan.n_frames("v"), plan.n_frames("u")), lights=np.arange(block["count"]),
                               channels=["R", "G", "B"], attrs=attrs)


def light_set_capture_of_plan(plan):
    """A captured several-lights capture in memory: both sweeps' frames, the reference and its truth.

    Holds both sweeps at once (:func:`light_set_views_of_plan` does not): for comparisons
    that rerun the stage.

    Parameters
    ----------
    plan : shadowcam.io.capture_plan.CapturePlan
        As for :func:`light_set_views_of_plan`.

    Returns
    -------
    xarray.Dataset
        ``frames_u``, ``frames_v`` (t, y, x, channel) and ``reference`` (y, x, channel)
        decoded (white 1), ``light_along_u``, ``light_along_v`` (light,) when described,
        and the ground truth's per-light times (``t_center_<s>``, ``t_first_<s>``,
        ``t_last_<s>``, ``share``) when the manifest names ``ground_truth``; attr
        ``cfa_pattern`` for camera RAW files, so that
        :func:`shadowcam.lab.light_views.light_set_views` times them as
        :func:`light_set_views_of_plan` does.
    """
    block = _captured(plan)
    data = {f"frames_{name}": ((f"t_{name}", "y", "x", "channel"),
                               read_stack(plan.sweep(name).files, shape=plan.frame_shape)) for name in SWEEPS}
    data["reference"] = (("y", "x", "channel"), _reference(plan))
    if block["light_along_u"] is not None:
        data.update({f"light_along_{name}": (("light",), np.asarray(block[f"light_along_{name}"]))
                     for name in SWEEPS})
    pattern = _cfa_pattern(plan)
    capture = xr.Dataset(data, coords={"channel": ["R", "G", "B"], "light": np.arange(block["count"])},
                         attrs={"cfa_pattern": pattern} if pattern else {})
    if block["ground_truth"] is not None:
        with xr.open_dataset(block["ground_truth"]) as opened:
            truth = opened.load()
        keep = [v for v in truth.data_vars if v.startswith(("t_center_", "t_first_", "t_last_")) or v == "share"]
        capture = capture.assign({v: truth[v] for v in keep})
    return capture
