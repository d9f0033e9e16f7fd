"""The virtual camera array of a capture's files (a user's manifest or a rendered ``capture.json``).

A camera-array capture (docs/contracts.md) holds two sweeps of frame files, ``horizontal``
(the light moving along ``e_u``) and ``vertical`` (along ``e_v``), and one image lit from
each wire crossing; its plan (:func:`shadowcam.io.capture_plan.capture_plan`) lists them.
Each experiment is streamed through the lab sweeps' decoder
(:func:`shadowcam.io.decode.frame_blocks`: camera RAW, TIFF, PNG, EXR to linear RGB), a
block of frames at a time, into the two passes of
:func:`shadowcam.cameras.array.assign_wires` (twice more when the spacing is estimated):
memory follows the frame size, not the number of frames. The crossing images are
decoded into one stack.

Offers
------
camera_array_of_plan : a camera-array capture plan -> the array dataset.
"""

import numpy as np

from shadowcam.cameras.array import array_views, assign_wires, estimate_spacing
from shadowcam.io.decode import frame_blocks, read_stack


def camera_array_of_plan(plan, *, tolerance=0.5, method="mesh"):
    """The virtual camera array of a captured (or rendered and written) camera-array capture.

    The experiments are streamed one after the other, then the crossing images decoded.

    Parameters
    ----------
    plan : shadowcam.io.capture_plan.CapturePlan
        Of a manifest with a top-level ``camera_array`` block (``plan.camera_array`` with
        ``crossings``) and sweeps ``horizontal``, ``vertical``.
    tolerance, method
        See :func:`shadowcam.cameras.array.camera_array`.

    Returns
    -------
    xarray.Dataset
        :func:`shadowcam.cameras.array.camera_array`'s dataset; attrs ``spacing_frames``
        (horizontal, vertical experiment) and ``spacing_source``: ``manifest``, or
        ``estimated`` when the manifest gives no spacing: each experiment's own
        (:func:`shadowcam.cameras.array.estimate_spacing`), or for a single wire the other
        family's.
    """
    array = plan.camera_array
    if array is None or "crossings" not in array:
        raise ValueError(f"plan: manifest {plan.manifest_path} is not a captured camera array (no top-level "
                         "camera_array block with crossings); render a synthetic one with render-array")
    rows, cols = int(array["rows"]), int(array["cols"])
    given = array["spacing_frames"]
    if given is None and max(rows, cols) < 2:
        raise ValueError(f"manifest {plan.manifest_path}: key 'camera_array.spacing_frames' is missing and "
                         "one wire per family gives no gap to estimate it from; give the spacing in frames")
    experiments = {"horizontal": cols, "vertical": rows}  # wires whose shadows pass
    order = sorted(experiments, key=lambda name: experiments[name] < 2)  # an estimable family first
    times, spacing = {}, {}
    for name in order:
        frames = frame_blocks(plan.sweep(name).files, plan.frame_shape)
        if given is not None:
            spacing[name] = float(given)
        elif experiments[name] >= 2:
            spacing[name] = estimate_spacing(frames, experiments[name], tolerance=tolerance, shape=plan.frame_shape)
        else:
            spacing[name] = next(iter(spacing.values()))
        wire_times, reason, minima = assign_wires(frames, experiments[name], spacing_frames=spacing[name],
                                                  tolerance=tolerance, shape=plan.frame_shape)
        times[name] = (wire_times, reason, minima.n_frames)
    crossings = read_stack(array["crossings"], shape=plan.frame_shape)
    (u, reason_u, t_u), (v, reason_v, t_v) = times["horizontal"], times["vertical"]
    out = array_views(crossings.reshape(rows, cols, *crossings.shape[1:]), u, v, reason_u=reason_u,
                      reason_v=reason_v, shape=(t_v, t_u), method=method)
    return out.assign_attrs(spacing_frames=[spacing["horizontal"], spacing["vertical"]],
                            spacing_source="manifest" if given is not None else "estimated",
                            tolerance=float(tolerance))
