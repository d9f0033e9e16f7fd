"""The virtual camera array of a capture's files (a user's manifest or a rendered ``capture.json``).

A camera-array capture (docs/contracts.md) holds two sweeps of frame files, ``horizontal``
(the light moving along ``e_u``) and ``vertical`` (along ``e_v``), and one image lit from
each wire crossing; its plan (:func:`shadowcam.io.capture_plan.capture_plan`) lists them.
The frames and images are decoded one at a time by the lab sweeps' decoder
(:func:`shadowcam.io.decode.iter_frames`: camera RAW, TIFF, PNG, EXR to linear RGB) into
one float32 stack per experiment, which :func:`shadowcam.cameras.array.camera_array`
reads whole (every pixel's minima span the sweep).

Offers
------
read_stack : decode frame files into one (N, H, W, 3) float32 stack.
camera_array_of_plan : a camera-array capture plan -> the array dataset.
"""

import numpy as np

from shadowcam.cameras.array import camera_array, estimate_spacing
from shadowcam.io.decode import iter_frames


def read_stack(paths, *, shape=None):
    """Decode frame files into one stack, one file at a time.

    Parameters
    ----------
    paths : sequence of str or Path
        Files in order.
    shape : (2,) tuple of int, optional
        ``(rows, cols)`` every file must have (default: the first file's).

    Returns
    -------
    (N, H, W, 3) float32 ndarray
        Linear RGB (black 0, white level 1).

    Raises
    ------
    ValueError
        No paths, or a file of another size than `shape` or the first file (naming both).
    """
    paths = list(paths)
    if not paths:
        raise ValueError("paths: no frame files to read")
    stack = None
    for k, (path, image, _) in enumerate(iter_frames(paths)):
        if stack is None:
            if shape is not None and tuple(image.shape[:2]) != tuple(shape):
                raise ValueError(f"frame {path} has size {image.shape[0]}x{image.shape[1]} (rows x cols) but the "
                                 f"capture's frames are {shape[0]}x{shape[1]}; every frame and crossing image "
                                 "must come from one camera at one size (remove or crop the odd file)")
            stack = np.empty((len(paths), *image.shape), np.float32)
        stack[k] = image
    return stack


def camera_array_of_plan(plan, *, tolerance=0.5, method="mesh"):
    """The virtual camera array of a captured (or rendered and written) camera-array capture.

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
        :func:`shadowcam.cameras.array.camera_array`'s dataset; attr ``spacing_source``:
        ``manifest``, or ``estimated`` (:func:`shadowcam.cameras.array.estimate_spacing`,
        the smaller of the two experiments' estimates) when the manifest gives no spacing.
    """
    array = plan.camera_array
    if array is None or "crossings" not in array:
        raise ValueError(f"plan: manifest {plan.manifest_path} is not a captured camera array (no top-level "
                         "camera_array block with crossings); render a synthetic one with render-array")
    shape = plan.frame_shape
    horizontal = read_stack(plan.sweep("horizontal").files, shape=shape)
    vertical = read_stack(plan.sweep("vertical").files, shape=shape)
    crossings = read_stack(array["crossings"], shape=shape)
    rows, cols = int(array["rows"]), int(array["cols"])
    spacing, source = array["spacing_frames"], "manifest"
    if spacing is None:
        if max(rows, cols) < 2:
            raise ValueError(f"manifest {plan.manifest_path}: key 'camera_array.spacing_frames' is missing and "
                             "one wire per family gives no gap to estimate it from; give the spacing in frames")
        spacing = min(estimate_spacing(frames, n, tolerance=tolerance)
                      for frames, n in ((horizontal, cols), (vertical, rows)) if n >= 2)
        source = "estimated"
    out = camera_array(horizontal, vertical, crossings.reshape(rows, cols, *crossings.shape[1:]),
                       spacing_frames=float(spacing), tolerance=tolerance, method=method)
    return out.assign_attrs(spacing_source=source)
